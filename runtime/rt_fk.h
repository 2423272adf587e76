/* SPDX-License-Identifier: Apache-2.0 */
/* Forward kinematics over a parent array (parents before children). */
#ifndef POSE_RT_FK_H
#define POSE_RT_FK_H

#include <stddef.h>
#include <stdint.h>

#include "rt_quat.h"

/**
 * For every joint j, the skinning transform skin[j] (model space, rest ->
 * posed) and the posed joint frame world[j]:
 *   D_j    = rotation local[j], expressed in the joint's rest frame, about
 *            the joint's rest origin;
 *   skin_j = skin_parent o D_j (root: `root` o D_j);
 *   world_j = skin_j o rest_j.
 * Joints at rest with an identity root give exactly identity skin transforms
 * (no rounding), so the rest pose reproduces rest positions bit for bit.
 */
void pose__fk(size_t joint_count, const int32_t *parents, const pose__xform *rest_model,
              const float (*local)[4], const pose__xform *root, pose__xform *skin,
              pose__xform *world);

#endif /* POSE_RT_FK_H */
