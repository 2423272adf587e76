/* SPDX-License-Identifier: Apache-2.0
 * A mocap clip as a pb_source: one channel per clip channel, named
 * "<joint>.<Xrotation|Yposition|...>" (unit "deg", or "" for positions in
 * the file's length unit; ASF limits fill min/max), one update per frame
 * with every channel, timestamped with the recorded time. read() paces the
 * frames on CLOCK_MONOTONIC at `speed` (0: as fast as possible); seek()
 * jumps to a recorded time. Retargeting a whole skeleton goes through
 * pb_retarget (the runner uses the player directly, to slerp between
 * frames); this source lets scalar mappings ("channels") and tools treat a
 * clip like any device recording. */
#ifndef POSE_BRIDGE_MOCAP_SOURCE_H
#define POSE_BRIDGE_MOCAP_SOURCE_H

#include "mocap.h"
#include "source.h"

/** The clip must outlive the source; destroy with pb_source_destroy. */
pose_status pb_mocap_source_open(const pb_clip *clip, double speed, int loop, pb_source **out, pb_error *err);

#endif /* POSE_BRIDGE_MOCAP_SOURCE_H */
