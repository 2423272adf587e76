/* SPDX-License-Identifier: Apache-2.0
 * Tests that pose a rig from a recording and compare its joints with the
 * recording's truth in the clinical convention (pose.h): the angles are
 * measured back from the posed joint's world rotation, not taken from what
 * was requested. Public API only. */
#ifndef POSE_TEST_CLINICAL_CHECK_H
#define POSE_TEST_CLINICAL_CHECK_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>

#include <cmocka.h>

#include "pose/pose.h"

/* o = a * b for quaternions {x, y, z, w} */
static inline void tc_quat_mul(const double a[4], const double b[4], double o[4])
{
    o[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    o[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    o[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    o[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
}

/* Joint j's clinical angles after the last pose_apply, from its world rotation:
 * R_j = (W_parent * rest_local_j)^-1 * W_j; of the two angle triples, the one
 * nearest hint. */
static inline void tc_clinical_back(const pose_rig *rig, const pose_state *st, int j, const float hint[3],
                                    float deg[3])
{
    pose_joint_info info;
    pose_transform w, wp = {{0, 0, 0, 1}, {0, 0, 0}};
    assert_int_equal(pose_rig_joint_info(rig, j, &info), POSE_OK);
    assert_int_equal(pose_joint_world(st, j, &w), POSE_OK);
    if (info.parent >= 0)
        assert_int_equal(pose_joint_world(st, info.parent, &wp), POSE_OK);
    double a[4], b[4], c[4], wj[4], r[4];
    for (int k = 0; k < 4; k++) {
        a[k] = wp.rotation[k];
        b[k] = info.rest_local.rotation[k];
        wj[k] = w.rotation[k];
    }
    tc_quat_mul(a, b, c);
    c[0] = -c[0], c[1] = -c[1], c[2] = -c[2]; /* the inverse of a unit quaternion */
    tc_quat_mul(c, wj, r);
    float q[4] = {(float)r[0], (float)r[1], (float)r[2], (float)r[3]};
    assert_int_equal(pose_local_to_clinical(rig, j, q, hint, deg), POSE_OK);
}

/* All of joint j's truth angles inside its clinical range of motion (none of
 * them limited, with half a degree to spare)? 0 for a joint without clinical data. */
static inline int tc_in_range(const pose_rig *rig, int j, const double truth[3])
{
    pose_joint_clinical c;
    if (pose_rig_joint_clinical(rig, j, &c) != POSE_OK)
        return 0;
    for (int k = 0; k < 3; k++)
        if ((c.limit_flags & (1u << k)) && (truth[k] < c.limit_min_deg[k] + 0.5 || truth[k] > c.limit_max_deg[k] - 0.5))
            return 0;
    return 1;
}

#endif /* POSE_TEST_CLINICAL_CHECK_H */
