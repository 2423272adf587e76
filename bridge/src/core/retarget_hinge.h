/* SPDX-License-Identifier: Apache-2.0
 * Hinge axes and mean postures of a clip's joints, measured from its motion.
 *
 * Rest alignment by bone directions alone leaves the twist of each segment
 * about its bone undetermined, and a knee or elbow whose flexion axis is
 * twisted away from the rig's turns every flexion into flexion plus
 * abduction plus twist, which the rig's hinge limits then clamp. The clip's
 * own joint offsets do not say where its flexion axes are (CMU's elbows, for
 * one, flex about an axis 30 degrees off the lateral one in the reference
 * pose), but its motion does: a hinge turns about one fixed axis of its
 * parent. */
#ifndef POSE_BRIDGE_RETARGET_HINGE_H
#define POSE_BRIDGE_RETARGET_HINGE_H

#include "mocap.h"

/**
 * For every clip joint, the axis it mostly turns about relative to its
 * parent, over the clip's frames and relative to the reference pose
 * (`ref_values`, NULL = all channels zero), as a unit vector in the clip's
 * world frame at the reference pose (`ref_wq`: the reference world
 * rotations). ok[c] is 1 where joint c is hinge-like: it turns by at least
 * a few degrees (RMS) and at least 90% of its rotation (by squared angle)
 * is about that one axis; elsewhere ok[c] is 0 and axis[c] is left zero.
 * The axis's sign is arbitrary. Allocates 7 doubles per joint internally;
 * returns 0, or -1 when out of memory (ok[] then all zero).
 */
int pb_clip_hinge_axes(const pb_clip *clip, const double *ref_values, const double (*ref_wq)[4], double (*axis)[3],
                       int *ok);

/**
 * For every clip joint c with want[c] set, its mean local rotation (as
 * pb_clip_local gives it) over the clip's frames: the normalized sum of the
 * frames' quaternions, each taken on the sum's side (a good mean for
 * rotations that stay within a few tens of degrees of each other). Other
 * entries are left zero. Returns 0, or -1 when out of memory.
 */
int pb_clip_mean_local(const pb_clip *clip, const int *want, double (*mean)[4]);

#endif /* POSE_BRIDGE_RETARGET_HINGE_H */
