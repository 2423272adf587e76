/* SPDX-License-Identifier: Apache-2.0 */
/* Quiet clusters: what a cluster's last full pass of the contact response
 * proved, so that later passes skip it while nothing has moved enough to
 * change the answer (contact_push.c, contact_dyn.c).
 *
 * A full pass of a cluster (of skin vertices or of soft nodes) ends with a
 * lower bound on the distance from each of its points to each joint's
 * bones, which its tests found on the way (spheres apart, the grids'
 * gaps, the queries' distances). Distances do not depend on the frame they
 * are measured in, so moves are measured in the frame of one joint R (the
 * one whose bones were nearest; the cluster keeps its points and R's frame
 * as they were): until the next full pass, a point's distance to joint J's
 * bones can shrink by no more than the point's move in R's frame plus J's
 * bones' move in R's frame. So while, for every joint J,
 *
 *     bound_J - (J's bones' move in R's frame since) - (the farthest point's move in R's frame) > margin,
 *
 * no point of the cluster is within the margin of a bone (nor inside one:
 * it was outside, and nothing came nearer than the margin on the way), and
 * the full pass would change nothing (no push, no constraint). A joint's
 * move in another's frame is a running sum over the frames
 * (pose__quiet_joints_update) of how far any point of its bones' sphere
 * moved in that frame between consecutive frames, so the test is one
 * subtraction a joint and one transform a point. Skin riding on a moving
 * limb is quiet in the limb's frame; a posture held still costs almost
 * nothing after its first step; what moves near bone is searched as
 * before, and records no bounds while it keeps moving (pose__quiet_pass). */
#ifndef POSE_CONTACT_QUIET_H
#define POSE_CONTACT_QUIET_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "alloc.h"
#include "pose/pose.h"
#include "rt_quat.h"

/** The joints' frames and their running moves in each other's frames. */
typedef struct pose__quiet_joints {
    size_t count;
    int set;         /**< the frames hold a pose (the next one's move is measured from it) */
    float *frames;   /**< per joint: rotation (9, row-major) and translation (3), posed */
    float *pairs;    /**< per joint pair (R, J): J's rotation in R's frame (quaternion) and its
                          bones' sphere's centre there, at the last frames (7) */
    double *motion;  /**< per pair (R, J), R * count + J: J's bones' running move in R's frame */
} pose__quiet_joints;

typedef struct pose__quiet {
    size_t clusters, joints;
    float *points;   /**< per cluster, POSE__PUSH_CLUSTER x 3: its points at its last full pass */
    int32_t *frame;  /**< per cluster: the joint R whose bones were nearest then; -1: no full
                          pass yet, or one that found a point within the margin */
    float *frame_then; /**< per cluster: R's frame then (rotation, row-major, and translation) */
    double *clear;   /**< per cluster, per joint J: the bound then plus J's running move in R's
                          frame then */
    uint8_t *held;   /**< per cluster: the last pass left it as it was (quiet) */
    uint8_t *wait;   /**< per cluster: passes left before its next snapshot (backoff) */
    uint8_t *misses; /**< per cluster: tests failed in a row (the backoff's exponent, capped) */
} pose__quiet;

/** What a pass does with a cluster (pose__quiet_holds). */
typedef enum pose__quiet_pass {
    POSE__QUIET_HOLDS,  /**< leave it as it is */
    POSE__QUIET_RECORD, /**< search it, recording what the search proves (begin, bounds, end) */
    POSE__QUIET_SEARCH, /**< search it and record nothing: it moved too much of late for a
                             snapshot to last (a cluster that fails its test k times in a row
                             records only every 2^k-th pass, k <= QUIET_BACKOFF) */
} pose__quiet_pass;

pose_status pose__quiet_joints_build(pose__quiet_joints *qj, size_t joints, const pose_allocator *a);
void pose__quiet_joints_release(pose__quiet_joints *qj, const pose_allocator *a);
/** New frames (skin: rest -> posed per joint); each joint's bones lie in
 *  the sphere spheres[8 j .. 8 j + 3] at rest (centre, radius; radius
 *  -INFINITY: no bones). */
void pose__quiet_joints_update(pose__quiet_joints *qj, const pose__xform *skin, const float *spheres);

/** Room for `clusters` clusters of the rig's `joints` joints, none quiet. */
pose_status pose__quiet_build(pose__quiet *q, size_t clusters, size_t joints, const pose_allocator *a);
void pose__quiet_release(pose__quiet *q, const pose_allocator *a);
/** Whether cluster c, whose points are now pos[3 idx[i]] (pos[3 i] when
 *  idx is NULL), i < count, is still farther than the margin from every
 *  bone (recorded in held), and if not, whether the pass records it. */
pose__quiet_pass pose__quiet_holds(pose__quiet *q, const pose__quiet_joints *qj, float margin, size_t c, const float *pos,
                      const uint32_t *idx, size_t count);
/** A full pass of cluster c starts: its points as the pass finds them. */
void pose__quiet_begin(pose__quiet *q, size_t c, const float *pos, const uint32_t *idx, size_t count);
/** ... and ends: `bound` per joint (what the pass proved; INFINITY for a
 *  joint whose bones it had no reason to test; a bound within the margin:
 *  not quiet before the next full pass). */
void pose__quiet_end(pose__quiet *q, const pose__quiet_joints *qj, float margin, size_t c, const float *bound);
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
