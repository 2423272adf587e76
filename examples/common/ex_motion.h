/* SPDX-License-Identifier: Apache-2.0
 *
 * Driving a pose_state from a bridge source (mocap file, HID or CAN
 * recording) through a mapping file. The examples never parse inputs
 * themselves: this is a thin adapter over the bridge library, and builds
 * without the bridge get a stub that says so.
 */
#ifndef POSE_EX_MOTION_H
#define POSE_EX_MOTION_H

#include <stddef.h>

#include "pose/pose.h"

typedef struct ex_motion ex_motion;

/** 1 when this build can drive from sources (the bridge is linked in), else 0. */
int ex_motion_available(void);

/** Open `source` with mapping `map` (NULL: the bridge's default for the source) for `rig`. */
int ex_motion_open(const char *source, const char *map, const pose_rig *rig, ex_motion **out, char *err,
                   size_t err_size);
void ex_motion_close(ex_motion *m);

/** Frames in a recording (-1 for a live source). */
long ex_motion_frame_count(const ex_motion *m);
/** Seconds between recorded frames (0 when unknown). */
double ex_motion_frame_time(const ex_motion *m);

/** Set the state's joints to recorded frame `frame` (pose_apply is the caller's). */
int ex_motion_set_frame(ex_motion *m, pose_state *st, long frame, char *err, size_t err_size);
/** Set the state's joints to recorded time `t` seconds (interpolated between frames). */
int ex_motion_set_time(ex_motion *m, pose_state *st, double t, char *err, size_t err_size);

/** One line for a HUD: source kind, rate, health. */
const char *ex_motion_status(const ex_motion *m);

#endif
