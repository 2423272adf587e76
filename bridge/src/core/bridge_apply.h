/* SPDX-License-Identifier: Apache-2.0
 * Applying bridge poses to a libpose state (rig_pose.c). */
#ifndef POSE_BRIDGE_APPLY_H
#define POSE_BRIDGE_APPLY_H

#include "handoff.h"
#include "rig_skel.h"

/**
 * pose_set_joint for every active joint and pose_set_root when the pose has
 * root motion. The pose's joint indices must be the rig's (a pb_rig_skel made
 * by pb_rig_skel_from_rig). *clamped (may be NULL) counts POSE_CLAMPED joints.
 */
pose_status pb_pose_apply_to_state(const pb_pose *p, pose_state *st, int *clamped);

#endif /* POSE_BRIDGE_APPLY_H */
