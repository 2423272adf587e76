/* SPDX-License-Identifier: Apache-2.0 */
/* Quiet clusters: what a cluster's last full pass of the contact response
 * proved, so that later passes skip it while nothing has moved enough to
 * change the answer (contact_push.c, contact_dyn.c).
 *
 * A full pass of a cluster (of skin vertices or of soft nodes) ends with a
 * lower bound on the distance from each of its points to each joint's
 * bones, which its tests found on the way (spheres apart, the grids'
 * gaps, the queries' distances). Until the next full pass, a point's
 * distance to a bone can shrink by no more than the point's move since
 * then plus the bone's: so while, for every joint,
 *
 *     bound - (the joint's bones' move since) - (the farthest point's move) > margin,
 *
 * no point of the cluster is within the margin of a bone, and the full
 * pass would change nothing (no push, no constraint). A joint's move is a
 * running sum over the bones' frames (pose__state_push_frames) of how far
 * any point of its bones' rest spheres moved between consecutive frames,
 * so the test is one subtraction a joint and one distance a point. A
 * posture held still costs almost nothing after its first step; what
 * moves is searched as before. */
#ifndef POSE_CONTACT_QUIET_H
#define POSE_CONTACT_QUIET_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "alloc.h"
#include "pose/pose.h"

typedef struct pose__quiet {
    size_t clusters, joints;
    float *points;  /**< per cluster, POSE__PUSH_CLUSTER x 3: its points at its last full pass */
    double *clear;  /**< per cluster, per joint: the bound then plus the joint's running move
                         then (-INFINITY: no full pass yet) */
    uint8_t *held;  /**< per cluster: the last pass left it as it was (quiet) */
} pose__quiet;

/** Room for `clusters` clusters of the rig's `joints` joints, none quiet. */
pose_status pose__quiet_build(pose__quiet *q, size_t clusters, size_t joints, const pose_allocator *a);
void pose__quiet_release(pose__quiet *q, const pose_allocator *a);
/** Forget every cluster's last pass (the next pass of each is full). */
void pose__quiet_forget(pose__quiet *q);
/** Whether cluster c, whose points are now pos[3 idx[i]] (pos[3 i] when
 *  idx is NULL), i < count, is still farther than the margin from every
 *  bone, given the joints' running moves `motion` (recorded in held). */
int pose__quiet_holds(pose__quiet *q, const double *motion, float margin, size_t c, const float *pos,
                      const uint32_t *idx, size_t count);
/** A full pass of cluster c starts: its points as the pass finds them. */
void pose__quiet_begin(pose__quiet *q, size_t c, const float *pos, const uint32_t *idx, size_t count);
/** ... and ends: `bound` per joint (what the pass proved; INFINITY for a
 *  joint whose bones it had no reason to test). */
void pose__quiet_end(pose__quiet *q, const double *motion, size_t c, const float *bound);

/** The clusters the last pass held, of all. */
size_t pose__quiet_held(const pose__quiet *q);

/** bound[joint] = min(bound[joint], d). */
static inline void pose__quiet_bound(float *bound, int joint, float d)
{
    if (bound && d < bound[joint])
        bound[joint] = d;
}

/** The same with d = sqrt(d2) - s, the root taken only where d may be
 *  less than the bound so far (most tests are of bones far from it). */
static inline void pose__quiet_bound_root(float *bound, int joint, float d2, float s)
{
    if (!bound)
        return;
    const float tie = bound[joint] + s;
    if (tie > 0.0f && d2 >= tie * tie)
        return;
    const float d = sqrtf(d2) - s;
    if (d < bound[joint])
        bound[joint] = d;
}

#endif /* POSE_CONTACT_QUIET_H */
