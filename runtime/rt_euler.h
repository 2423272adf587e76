/* SPDX-License-Identifier: Apache-2.0 */
/* Euler angles <-> quaternions for the six Tait-Bryan orders of pose.h:
 * angles are per axis {x, y, z} in degrees; order ABC means R = RA * RB * RC
 * (intrinsic A, then the new B, then the new C). */
#ifndef POSE_RT_EULER_H
#define POSE_RT_EULER_H

/** Axes of order `order` (0..5, pose_euler_order), first to last. */
void pose__euler_axes(int order, int axes[3]);
/** "XYZ", "ZXY", ...; "?" for an unknown order. */
const char *pose__euler_name(int order);
/** Unit quaternion of Euler angles deg = {x, y, z} composed in `order`. */
void pose__euler_to_quat(const float deg[3], int order, float q[4]);
/**
 * Euler angles {x, y, z} in degrees of a unit quaternion, for `order`: the
 * middle axis in [-90, 90], the others in (-180, 180]. At gimbal lock the
 * last axis is set to 0.
 */
void pose__quat_to_euler(const float q[4], int order, float deg[3]);

#endif /* POSE_RT_EULER_H */
