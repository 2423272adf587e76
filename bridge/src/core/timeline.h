/* SPDX-License-Identifier: Apache-2.0
 * Recorded time stamps made fit for replay. A stamp that jumps ahead by more
 * than a threshold (a clock set forward mid-recording, a corrupt line) would
 * stall a real-time replay for that long; one that goes backwards would be
 * played at once and out of order. Either jump is taken out -- replaced by
 * the step between the two stamps before it -- and the caller reports it
 * (naming the file and line); later stamps keep their spacing. The replays
 * of candump logs (at read time) and hid-recorder files (at load) use it.
 */
#ifndef POSE_BRIDGE_TIMELINE_H
#define POSE_BRIDGE_TIMELINE_H

#include <stdint.h>

/** Gaps up to a minute are replayed as recorded (a device idle or unplugged
 *  for a while is part of the recording); longer ones are taken out. */
#define PB_TIMELINE_MAX_GAP_NS (60 * INT64_C(1000000000))

typedef struct pb_timeline {
    int64_t max_gap_ns;
    int64_t offset_ns; /**< added to recorded stamps */
    int64_t last_ns;   /**< the previous replay time */
    int64_t step_ns;   /**< the previous step, in [0, max_gap_ns] */
    int have;          /**< a stamp was mapped already */
} pb_timeline;

void pb_timeline_init(pb_timeline *t, int64_t max_gap_ns);
/**
 * Replay time of recorded stamp t_ns (the first stamp maps to itself). When a
 * jump was taken out, *jump_ns (may be NULL) gets it: > max_gap_ns ahead, or
 * negative for backwards; else 0.
 */
int64_t pb_timeline_map(pb_timeline *t, int64_t t_ns, int64_t *jump_ns);

#endif /* POSE_BRIDGE_TIMELINE_H */
