/* SPDX-License-Identifier: Apache-2.0 */
/* A beam of tets along x for the binding tests: cross-section [0,1]^2 of
 * 4 x 4 cubes (edge 0.25), length 8 (32 cubes), 6 Kuhn tets per cube; a
 * chain of 9 joints on the axis (y = z = 0.5) at x = 0..8, each tet vertex
 * weighted between the two joints around it (hat functions of x), so DQS
 * bends and twists it smoothly. */
#ifndef POSE_TEST_BIND_BAR_H
#define POSE_TEST_BIND_BAR_H

#include "pose/pose.h"

#define BAR_JOINTS 9

/** Build the beam (fails the test on error). */
pose_rig *bar_rig(void);

/** Skinning transform (rest -> posed) of joint j after pose_apply. */
void bar_skin(const pose_state *st, int j, float q[4], float t[3]);

/** DQS of a point with the beam's weights at its x (the smooth reference
 *  deformation the bar's skinning defines, off the mesh too). */
void bar_dqs(const pose_state *st, const float p[3], float out[3]);

#endif /* POSE_TEST_BIND_BAR_H */
