/* SPDX-License-Identifier: Apache-2.0 */
/* The baked body of tests/contact (the tests' shared coarse bake) and the
 * issue's deep poses, shared by the contact tests and bench/contact. */
#ifndef POSE_TEST_CONTACT_BODY_H
#define POSE_TEST_CONTACT_BODY_H

#include <stddef.h>
#include <stdlib.h>

#include "pose/pose.h"

typedef struct contact_pose {
    const char *label;
    const char *joints[2]; /* both sides; none: the neutral posture alone */
    float deg;             /* clinical flexion */
} contact_pose;

/* Issue 13's acceptance poses, each from the neutral posture (arms at the
 * sides, so the arms lie against the trunk in all of them). */
static const contact_pose contact_poses[] = {
    {"arms at the sides", {NULL, NULL}, 0.0f},
    {"knee flexion 140", {"knee_r", "knee_l"}, 140.0f},
    {"elbow flexion 145", {"elbow_r", "elbow_l"}, 145.0f},
    {"hip flexion 120", {"hip_r", "hip_l"}, 120.0f},
};
#define CONTACT_POSE_COUNT (sizeof contact_poses / sizeof contact_poses[0])

/* How many of the poses a test takes: all, or the first $POSE_CONTACT_POSES
 * (the TSan stage takes one: the threads run the same code at every pose,
 * and each pose costs minutes there). */
static inline size_t contact_pose_count(void)
{
    const char *e = getenv("POSE_CONTACT_POSES");
    const long n = e ? strtol(e, NULL, 10) : 0;
    return n > 0 && (size_t)n < CONTACT_POSE_COUNT ? (size_t)n : CONTACT_POSE_COUNT;
}

/* $POSE_CONTACT_THREADS_ONLY set (the TSan stage): a test keeps to what
 * the threads do, 1 thread against 2, and leaves out its single-threaded
 * brute-force references and sweeps, which take minutes under TSan and
 * check values the other stages check. */
static inline int contact_threads_only(void)
{
    const char *e = getenv("POSE_CONTACT_THREADS_ONLY");
    return e && *e && *e != '0';
}

/* Set pose `p` on `st` (from a reset). 0, or -1 naming nothing: a joint is
 * missing or the state refused the angles. */
static inline int contact_pose_set(const pose_rig *rig, pose_state *st, const contact_pose *p)
{
    if (pose_reset(st) != POSE_OK || pose_set_neutral(st) < 0)
        return -1;
    for (int s = 0; s < 2 && p->joints[s]; s++) {
        const float deg[3] = {p->deg, 0.0f, 0.0f};
        const int j = pose_rig_find_joint(rig, p->joints[s]);
        if (j < 0 || pose_set_joint_clinical(st, j, deg) < 0)
            return -1;
    }
    return 0;
}

#endif /* POSE_TEST_CONTACT_BODY_H */
