/* SPDX-License-Identifier: Apache-2.0 */
/* Euler angles <-> quaternions for the six Tait-Bryan orders of pose.h:
 * angles are per axis {x, y, z} in degrees; order ABC means R = RA * RB * RC
 * (intrinsic A, then the new B, then the new C). The one implementation:
 * the SDK, its clinical angles and the bridge (through pose_euler_to_quat /
 * pose_quat_to_euler) all call these. */
#ifndef POSE_RT_EULER_H
#define POSE_RT_EULER_H

/** Below this |cos(middle angle)| a rotation is taken as gimbal-locked: the
 *  middle angle is set to exactly +-90 and the first angle takes the whole
 *  free rotation. A float quaternion locked at 90 degrees reads up to ~1e-7
 *  here, so this catches it; forcing the lock moves the rotation by at most
 *  1e-6 * 180 degrees (2e-4 degrees). */
#define POSE__GIMBAL_COS 1e-6

/** Axes of order `order` (0..5, pose_euler_order), first to last. */
void pose__euler_axes(int order, int axes[3]);
/** "XYZ", "ZXY", ...; "?" for an unknown order. */
const char *pose__euler_name(int order);
/** Unit quaternion of Euler angles deg = {x, y, z} composed in `order`. */
void pose__euler_to_quat_d(const double deg[3], int order, double q[4]);
/**
 * Euler angles {x, y, z} in degrees of a quaternion (normalized here), for
 * `order`: the middle axis in [-90, 90], the others in [-180, 180]. Returns 1
 * at gimbal lock (see POSE__GIMBAL_COS; the last axis is then 0), else 0.
 */
int pose__quat_to_euler_d(const double q[4], int order, double deg[3]);
/** Float versions of the two above (computed in double, rounded once). */
void pose__euler_to_quat(const float deg[3], int order, float q[4]);
void pose__quat_to_euler(const float q[4], int order, float deg[3]);

#endif /* POSE_RT_EULER_H */
