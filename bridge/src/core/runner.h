/* SPDX-License-Identifier: Apache-2.0
 * The bridge thread: plays a clip (or reads a source) in real time, maps it
 * onto the rig and publishes joint targets through the lock-free hand-off.
 * The host's frame loop calls pb_runner_latest() at its own rate and never
 * waits. Control calls (pause, seek, step, speed) may come from any thread;
 * they take a short mutex the bridge thread only holds between ticks.
 *
 * Timing: tick k is due at media time k * period (period = frame time, or
 * 1/rate_hz when given: samples between frames are slerped). The thread
 * sleeps until the tick's wall time (CLOCK_MONOTONIC, absolute) and records
 * its lateness ("lag"). speed 0 runs as fast as possible, without sleeping.
 *
 * Warnings: the bridge thread reports to the pb_warn sink that was installed
 * on the thread that started it (pose_bridge_open installs the bridge's); that
 * sink must outlive the runner, and nothing else may write to it meanwhile. */
#ifndef POSE_BRIDGE_RUNNER_H
#define POSE_BRIDGE_RUNNER_H

#include <stdint.h>

#include "handoff.h"
#include "mapping.h"
#include "player.h"
#include "recorder.h"
#include "source.h"

typedef struct pb_runner_options {
    double speed;      /**< media seconds per second; 0 = as fast as possible (default 1 when left 0 and afap 0) */
    int afap;          /**< as fast as possible */
    int loop;          /**< clips: wrap at the end */
    double rate_hz;    /**< publish rate; 0 = the clip's frame rate */
    long max_ticks;    /**< stop after this many published poses (0 = no limit) */
    double max_media_s;/**< stop after this much media time (0 = no limit) */
    double start_s;    /**< initial media time */
    int start_paused;
    const char *record_path; /**< BVH of the applied joint angles, or NULL */
    int rt_priority;   /**< > 0: run the bridge thread SCHED_FIFO at this priority (1..99)
                            when the system allows it (see pb_runner_stats.realtime) */
    int recorded;      /**< sources: update times are recorded times, media time = t_ns (a
                            replay); 0: media time counts from the first update (live) */
    /** Sources: samples the backend rejected or lost so far (pb_runner_stats.drops), polled on
     *  the bridge thread after each read; NULL counts none. */
    uint64_t (*count_drops)(pb_source *src);
} pb_runner_options;

typedef struct pb_runner_stats {
    uint64_t ticks;        /**< poses published */
    long frame;            /**< clip frame of the last pose */
    double media_s;        /**< media time of the last pose */
    double fps;            /**< publish rate over the last quarter second */
    double lag_ms;         /**< lateness of the last tick */
    double lag_max_ms;     /**< worst lateness so far */
    pb_source_state state; /**< PB_SOURCE_OK while running, ENDED at the end */
    int running;
    int realtime;          /**< the thread got the SCHED_FIFO priority it asked for */
    pb_source_state source;/**< the source's own health (STALE while a CAN node is silent ...);
                                clips: PB_SOURCE_OK */
    char fault[256];       /**< the last STALE, DISCONNECTED or FAULT message, or why the thread
                                stopped (a recording it could not write); "" when none */
    uint64_t samples;      /**< source updates read (clips: poses) */
    uint64_t drops;        /**< options.count_drops */
    int64_t last_sample_ns;/**< CLOCK_MONOTONIC arrival of the newest sample; 0 before the first */
} pb_runner_stats;

typedef struct pb_runner pb_runner;

/**
 * Start a thread that replays `clip` onto `rig` through `map` (all three must
 * outlive the runner). On failure nothing is started.
 */
pose_status pb_runner_start_clip(const pb_clip *clip, const pb_rig_skel *rig, const pb_mapping *map,
                                 const pb_runner_options *opt, pb_runner **out, pb_error *err);
/**
 * Start a thread that reads `src` (scalar channels) and maps it through
 * map's "channels" onto `rig`. Always takes ownership of `src`: on success
 * pb_runner_stop destroys it, on any failure (NULL arguments included) it is
 * destroyed before this returns. Either way the caller must not use or
 * destroy it afterwards.
 */
pose_status pb_runner_start_source(pb_source *src, const pb_rig_skel *rig, const pb_mapping *map,
                                   const pb_runner_options *opt, pb_runner **out, pb_error *err);
/** Host side, never blocks: the newest pose (see pb_handoff_latest). */
const pb_pose *pb_runner_latest(pb_runner *r, int *fresh);
/** The source's health (pb_runner_stats.source) without locking, for the host's frame loop. */
pb_source_state pb_runner_source_state(pb_runner *r);
/** Snapshot of the counters (takes the control mutex briefly). */
void pb_runner_stats_get(pb_runner *r, pb_runner_stats *out);
/** Clips and replays (a source with seek): a paused replay reads nothing; on resume it
 *  continues from the last update it delivered. */
void pb_runner_pause(pb_runner *r, int paused);
void pb_runner_seek(pb_runner *r, double media_s);
/** While paused: publish the next `ticks` poses, one period apart (ignored while playing). */
void pb_runner_step(pb_runner *r, int ticks);
void pb_runner_set_speed(pb_runner *r, double speed);
/** Block until the runner has ended on its own (limit or clip end) or timeout_ms (-1 forever). 1 ended, 0 timeout. */
int pb_runner_wait(pb_runner *r, int timeout_ms);
/** Stop the thread, close the recording; NULL is a no-op. err may be NULL. */
pose_status pb_runner_stop(pb_runner *r, pb_error *err);
/**
 * Wake-up lateness of every tick so far at the quantiles q[0..n) (0.5 the
 * median, 1 the worst) in milliseconds, within 0.8 % (lag_hist.h); returns
 * the number of ticks counted.
 */
uint64_t pb_runner_lag_quantiles(pb_runner *r, const double *q, double *out_ms, int n);

#endif /* POSE_BRIDGE_RUNNER_H */
