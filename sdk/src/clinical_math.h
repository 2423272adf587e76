/* SPDX-License-Identifier: Apache-2.0 */
/* Clinical angles <-> local rotations (pose.h, pose_joint_clinical):
 *
 *   local = R(a0, deg[0]) * R(a1, deg[1]) * R(a2, deg[2]) * neutral
 *
 * With B = [a0 a1 a2] a rotation (the axes as columns), R(ai, t) = B Ri(t) B^T,
 * so local * neutral^-1 = B Rx(deg[0]) Ry(deg[1]) Rz(deg[2]) B^T: clinical
 * angles are intrinsic XYZ Euler angles in the frame of the axes, and the one
 * Euler implementation (rt_euler.c) decomposes them. Double precision
 * throughout; no allocation (these run in per-frame setters). */
#ifndef POSE_CLINICAL_MATH_H
#define POSE_CLINICAL_MATH_H

#include "rig_internal.h"

/** A joint's clinical frame, ready for conversions. */
typedef struct pose__clinical_frame {
    double neutral[4]; /**< unit */
    double basis[4];   /**< rotation taking x, y, z to the orthonormalized flexion,
                            abduction and (right-handed) rotation axes */
    double handed;     /**< +1; -1 when the stored axes are left-handed: the rotation
                            axis is then -basis z, so its angle changes sign */
} pose__clinical_frame;

/** A range of motion over the three clinical angles: the rig's (from its
 *  record) or a state's own (pose_set_joint_range). */
typedef struct pose__clinical_range {
    uint32_t limit_flags;    /**< POSE_LIMIT_X/_Y/_Z: deg[0]/[1]/[2] limited */
    float min_deg[3];        /**< unlimited angles: -180 */
    float max_deg[3];        /**< unlimited angles: 180 */
} pose__clinical_range;

/** How pose__clinical_from_local picks one of the two angle triples. */
typedef enum pose__clinical_pick {
    POSE__PICK_HINT,          /**< nearest the hint (angle-wise, wrapping) */
    POSE__PICK_INSIDE,        /**< inside the limits if one is, else abduction in [-90, 90] */
    POSE__PICK_NEAREST_LIMITS /**< the one least outside the limits (for clamping) */
} pose__clinical_pick;

/** Frame of a (validated) record: the axes are orthonormalized from the
 *  flexion axis on, so conversions both ways use exactly the same frame. */
void pose__clinical_frame_of(const pose__clinical_record *r, pose__clinical_frame *f);
/** The range a (validated) record stores. */
void pose__clinical_range_of(const pose__clinical_record *r, pose__clinical_range *out);
/** Clinical angles (degrees) -> local rotation, no limits. */
void pose__clinical_to_local(const pose__clinical_frame *f, const double deg[3], double q[4]);
/**
 * Local rotation -> clinical angles, `r` giving the limits. Every rotation has two triples, (f, a, r)
 * and (f + 180, 180 - a, r + 180); `pick` chooses (hint: {f, a, r} or NULL
 * unless POSE__PICK_HINT). Limited angles are moved by whole turns into, or
 * nearest to, their range (flexion 180 stays 180 with a range [-60, 180]);
 * with a hint every angle lies within 180 degrees of the hint's. At gimbal
 * lock (abduction +-90) only f +- r is defined: r is taken from the hint,
 * else 0 (moved into r's range when limited), and f carries the rest.
 */
void pose__clinical_from_local(const pose__clinical_frame *f, const pose__clinical_range *r,
                               const double q[4], pose__clinical_pick pick, const double hint[3],
                               double deg[3]);
/**
 * Move limited angles by whole turns into or nearest their range (a value
 * in range is unchanged); returns the degrees by which they still lie
 * outside, summed.
 */
double pose__clinical_fit(const pose__clinical_range *r, double deg[3]);

#endif /* POSE_CLINICAL_MATH_H */
