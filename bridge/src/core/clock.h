/* SPDX-License-Identifier: Apache-2.0
 * Media clock: maps CLOCK_MONOTONIC time to clip time with a speed factor,
 * pause and seek. Speed 0 means "as fast as possible": the replay loop then
 * steps frame by frame without sleeping and the clock is not consulted. */
#ifndef POSE_BRIDGE_CLOCK_H
#define POSE_BRIDGE_CLOCK_H

#include <stdint.h>

/** A monotonic clock in nanoseconds (CLOCK_MONOTONIC; Windows: QueryPerformanceCounter). */
int64_t pb_now_ns(void);
/** Sleep until pb_now_ns() reaches t_ns (absolute; returns at once if past). */
void pb_sleep_until_ns(int64_t t_ns);

typedef struct pb_clock {
    double speed;        /**< media seconds per wall second (> 0) */
    int paused;
    int64_t anchor_ns;   /**< wall time at which media time was anchor_s */
    double anchor_s;
} pb_clock;

void pb_clock_start(pb_clock *c, double speed, double media_s, int64_t now_ns);
/** Media time at wall time now_ns. */
double pb_clock_media(const pb_clock *c, int64_t now_ns);
/** Wall time at which media time media_s is reached (INT64_MAX while paused). */
int64_t pb_clock_wall(const pb_clock *c, double media_s);
void pb_clock_set_speed(pb_clock *c, double speed, int64_t now_ns);
void pb_clock_pause(pb_clock *c, int paused, int64_t now_ns);
void pb_clock_seek(pb_clock *c, double media_s, int64_t now_ns);

#endif /* POSE_BRIDGE_CLOCK_H */
