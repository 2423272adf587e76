/* SPDX-License-Identifier: Apache-2.0 */
/* Tiny hand-made rigs for the runtime tests: a bar of unit cubes along x
 * (cross-section [0,1]^2), each cube split into 6 tets, with a chain of
 * joints along its axis. */
#ifndef POSE_TEST_FIXTURE_H
#define POSE_TEST_FIXTURE_H

#include <stddef.h>

#include "pose/pose.h"

typedef struct fx_options {
    int cubes;            /**< bar length (>= 2) */
    int joints;           /**< chain length (1..cubes) */
    int with_cor;         /**< store centres of rotation */
    float child_rest_deg; /**< rest rotation of joints > 0 about x (a non-trivial frame) */
    int limit_joint;      /**< joint with limits, or -1 */
    pose_euler_order limit_order;
    unsigned limit_flags;
    float limit_min[3], limit_max[3];
    int inner_points;     /**< random tissue points inside the bar (tissue 1) */
    unsigned seed;
} fx_options;

/** Defaults: 4 cubes, 2 joints, CoR, rest rotation 30 deg, no limits, 16 points. */
fx_options fx_defaults(void);

/** Build the rig; fails the test on error. Tissue 0 "skin" has one vertex on
 *  every tet vertex (same indices) and the bar's surface triangles; tissue 1
 *  "inner" holds the random points (no triangles). */
pose_rig *fx_bar(const fx_options *o);

/** x of joint j's origin (joints sit on the axis y = z = 0.5). */
float fx_joint_x(const fx_options *o, int j);

#endif /* POSE_TEST_FIXTURE_H */
