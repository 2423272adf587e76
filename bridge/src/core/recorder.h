/* SPDX-License-Identifier: Apache-2.0
 * Session recording: the joint targets applied to a rig, written as BVH
 * (readable by Blender and other tools). The hierarchy is the rig's, with
 * axis-aligned joint frames: each joint's channels are its rotation
 * relative to rest expressed in model axes, so replaying the file onto the
 * same rig with same-name mapping reproduces the recorded targets. Each
 * frame is written and flushed at once, and the header's frame count is
 * rewritten in place, so a crash loses at most the frame being written. */
#ifndef POSE_BRIDGE_RECORDER_H
#define POSE_BRIDGE_RECORDER_H

#include <stdio.h>

#include "handoff.h"
#include "rig_skel.h"

typedef struct pb_recorder pb_recorder;

pose_status pb_recorder_open(const char *path, const pb_rig_skel *rig, double frame_time, pb_recorder **out,
                             pb_error *err);
/** Append one frame (the pose's rig joint rotations and root motion). */
pose_status pb_recorder_write(pb_recorder *r, const pb_pose *pose, pb_error *err);
/** Frames written so far. */
long pb_recorder_frames(const pb_recorder *r);
/** Close the file; NULL is a no-op. */
pose_status pb_recorder_close(pb_recorder *r, pb_error *err);

#endif /* POSE_BRIDGE_RECORDER_H */
