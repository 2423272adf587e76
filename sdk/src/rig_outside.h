/* SPDX-License-Identifier: Apache-2.0 */
/* Tissue vertices outside the tet mesh: bound to it at load (rig_outside.c),
 * placed by pose_apply after the transfer (state_outside.c). */
#ifndef POSE_RIG_OUTSIDE_H
#define POSE_RIG_OUTSIDE_H

#include <stddef.h>

#include "pose/pose.h"

struct pose_state;

/** Find the tissue vertices outside the tet mesh and bind them (rig->rt's
 *  outside fields); called by pose__rig_prepare. */
pose_status pose__rig_prepare_outside(pose_rig *rig);
/** Free what pose__rig_prepare_outside made. */
void pose__rig_release_outside(pose_rig *rig);
/** Place the outside vertices among tissue vertices [begin, end) (a part of
 *  the transfer: tet positions and joint transforms are final). */
void pose__state_place_outside(struct pose_state *st, size_t begin, size_t end);

#endif /* POSE_RIG_OUTSIDE_H */
