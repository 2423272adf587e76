/* SPDX-License-Identifier: Apache-2.0
 *
 * Driving a pose_state from a bridge source through a mapping file: a mocap
 * clip (BVH, ASF/AMC), a HID device or hid-recorder file, a CAN interface or
 * candump log. The examples never parse inputs themselves: this is a thin
 * adapter over the bridge library. Builds without the bridge get a stub that
 * refuses every source and says why.
 *
 * Two ways to drive: frame by frame (clips) or by recorded time (clips and
 * recordings), for images; or live, where
 * the bridge's own thread plays the source in real time and publishes joint
 * targets through its lock-free hand-off, and the host's frame loop picks up
 * the newest pose without waiting (ex_motion_start / ex_motion_poll).
 */
#ifndef POSE_EX_MOTION_H
#define POSE_EX_MOTION_H

#include <stddef.h>

#include "pose/pose.h"

typedef struct ex_motion ex_motion;

/** 1 when this build can drive from sources (the bridge is linked in), else 0. */
int ex_motion_available(void);

/**
 * Open `source` with mapping `map` for `rig`. map may be NULL for clips (rig
 * joints then take the clip joints of the same name); HID and CAN sources
 * need one (its "channels", and for CAN its "can" bus description).
 */
int ex_motion_open(const char *source, const char *map, const pose_rig *rig, ex_motion **out, char *err,
                   size_t err_size);
/** Stop playback and free everything; NULL is a no-op. */
void ex_motion_close(ex_motion *m);

/** Frames of a clip; -1 for device sources and their recordings (they have no frames). */
long ex_motion_frame_count(const ex_motion *m);
/** Seconds between clip frames (0 for device sources). */
double ex_motion_frame_time(const ex_motion *m);
/** Set the state's joints to clip frame `frame` (pose_apply is the caller's). Clips only. */
int ex_motion_set_frame(ex_motion *m, pose_state *st, long frame, char *err, size_t err_size);

/**
 * Set the state's joints to the pose held at `t_s` seconds of recorded time
 * (pose_apply is the caller's). Recordings (.hid, candump .log) replay as fast
 * as possible through the same decoder and mapping as live play, up to t_s;
 * a later time continues, an earlier one replays from the start. Clips take
 * the frame at t_s. Live devices are refused.
 */
int ex_motion_set_time(ex_motion *m, pose_state *st, double t_s, char *err, size_t err_size);

/** Start live playback on the bridge thread (clips and recordings loop). */
int ex_motion_start(ex_motion *m, char *err, size_t err_size);
/** Apply the newest published pose; never blocks. 1: a new pose was applied, 0: none new, -1: error. */
int ex_motion_poll(ex_motion *m, pose_state *st, char *err, size_t err_size);
/** Live playback controls (seek and step only move clips). */
void ex_motion_pause(ex_motion *m, int paused);
int ex_motion_paused(const ex_motion *m);
void ex_motion_seek(ex_motion *m, double media_s);
void ex_motion_step(ex_motion *m, int ticks);
/** Media time of the newest pose (seconds). */
double ex_motion_time(const ex_motion *m);

/** One line for a HUD: source, frame, rate, lag, health (stale, faulty, ended ...). */
const char *ex_motion_status(ex_motion *m);

#endif
