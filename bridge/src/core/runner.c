/* SPDX-License-Identifier: Apache-2.0 */
#include "runner.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "lag_hist.h"
#include "pb_math.h"
#include "pb_thread.h"
#include "pb_warn.h"

struct pb_runner {
    pb_thread thread;
    pb_mutex mu;
    pb_cond cv;
    int started;
    /* control, under mu */
    int stop_req, paused, seek_req, step_req, speed_req;
    double seek_to, speed;
    pb_runner_stats stats;
    int64_t fps_t0;
    uint64_t fps_ticks0;
    /* owned by the bridge thread */
    pb_runner_options opt;
    const pb_clip *clip;
    const pb_rig_skel *rig;
    pb_player player;
    pb_retarget *rt;
    pb_chanmap *cm;
    pb_source *src;
    pb_recorder *rec;
    pb_handoff h;
    pb_clock clock;
    double period;
    double (*lq)[4], (*lt)[3];
    pb_lag_hist lags; /* every tick's lag, constant memory */
    pb_error err;
    pose_status status;
    atomic_int source_state; /* stats.source, for readers that must not lock */
    pb_warnings *warnings;   /* the starting thread's sink, the bridge thread's from then on */
};

static void note_tick(pb_runner *r, const pb_pose *p)
{
    const int64_t lag_ns = p->lag_ns;
    /* caller holds mu */
    r->stats.ticks++;
    if (r->clip) {
        r->stats.samples++;
        r->stats.last_sample_ns = p->t_ns;
    }
    r->stats.frame = p->frame;
    r->stats.media_s = p->media_s;
    r->stats.lag_ms = (double)lag_ns * 1e-6;
    if (r->stats.lag_ms > r->stats.lag_max_ms)
        r->stats.lag_max_ms = r->stats.lag_ms;
    if (p->t_ns - r->fps_t0 >= 250000000 || r->fps_t0 == 0) { /* rate over the last quarter second */
        if (r->fps_t0)
            r->stats.fps = (double)(r->stats.ticks - r->fps_ticks0) * 1e9 / (double)(p->t_ns - r->fps_t0);
        r->fps_t0 = p->t_ns;
        r->fps_ticks0 = r->stats.ticks;
    }
    pb_lag_hist_add(&r->lags, lag_ns);
}

static void finish(pb_runner *r, pb_source_state st)
{
    pb_mutex_lock(&r->mu);
    r->stats.state = st;
    r->stats.running = 0;
    pb_cond_broadcast(&r->cv);
    pb_mutex_unlock(&r->mu);
}

/* Publish the back slot, record it; returns nonzero on a recording error. */
static int publish(pb_runner *r, pb_pose *back)
{
    pb_handoff_publish(&r->h);
    int bad = 0;
    if (r->rec && pb_recorder_write(r->rec, back, &r->err) != POSE_OK) {
        r->status = POSE_ERR_IO;
        bad = 1;
    }
    pb_mutex_lock(&r->mu);
    note_tick(r, back);
    if (bad)
        snprintf(r->stats.fault, sizeof r->stats.fault, "%.255s", r->err.message);
    pb_mutex_unlock(&r->mu);
    return bad;
}

/* The bridge thread's set-up: the starting thread's warning sink (a
 * recording's time jumps and cut lines are found while playing), then the
 * priority. Real-time scheduling is a request: without the privilege the
 * thread runs normally and stats.realtime says so. Under load it is what
 * keeps the wake-up lag of a 120 Hz replay under a millisecond. */
static void apply_priority(pb_runner *r)
{
    pb_warnings_install(r->warnings);
    pb_thread_precise_wakeups(); /* ticks want their deadline, not a coalesced wake-up */
    if (r->opt.rt_priority <= 0)
        return;
    int ok = pb_thread_realtime(r->opt.rt_priority);
    pb_mutex_lock(&r->mu);
    r->stats.realtime = ok;
    pb_mutex_unlock(&r->mu);
}

static void *clip_thread(void *arg)
{
    pb_runner *r = arg;
    apply_priority(r);
    double next = r->opt.start_s, first = r->opt.start_s;
    pb_clock_start(&r->clock, r->speed, next, pb_now_ns());
    if (r->paused)
        pb_clock_pause(&r->clock, 1, pb_now_ns());
    for (;;) {
        int stepping = 0;
        int64_t deadline = 0;
        pb_mutex_lock(&r->mu);
        for (;;) {
            int64_t now = pb_now_ns();
            if (r->stop_req)
                break;
            if (r->seek_req) {
                pb_clock_seek(&r->clock, r->seek_to, now);
                next = r->seek_to;
                r->seek_req = 0;
            }
            if (r->speed_req) {
                pb_clock_set_speed(&r->clock, r->speed, now);
                r->speed_req = 0;
            }
            if (r->paused != r->clock.paused) {
                pb_clock_pause(&r->clock, r->paused, now);
                if (!r->paused)
                    pb_clock_seek(&r->clock, next, now); /* resume where the last tick was due */
            }
            if (r->paused) {
                if (r->step_req > 0) {
                    r->step_req--;
                    stepping = 1;
                    deadline = now;
                    break;
                }
                pb_cond_wait_until(&r->cv, &r->mu, now + 50000000);
                continue;
            }
            if (r->opt.afap) {
                deadline = now;
                break;
            }
            deadline = pb_clock_wall(&r->clock, next);
            if (deadline <= now)
                break;
            if (pb_cond_wait_until(&r->cv, &r->mu, deadline) != 0 && pb_now_ns() >= deadline)
                break; /* timed out: the tick is due (commands re-checked otherwise) */
        }
        int stop = r->stop_req;
        pb_mutex_unlock(&r->mu);
        if (stop)
            break;
        int64_t woke = pb_now_ns();
        double t;
        int past_end = pb_player_wrap(&r->player, next, &t);
        pb_player_sample(&r->player, t, r->lq, r->lt);
        pb_pose *back = pb_handoff_back(&r->h);
        pb_retarget_apply(r->rt, (const double (*)[4])r->lq, (const double (*)[3])r->lt, r->period, back);
        back->t_ns = woke;
        back->lag_ns = stepping ? 0 : woke - deadline;
        back->media_s = next;
        back->frame = (long)floor(t / r->clip->frame_time + 1e-9);
        if (publish(r, back))
            break;
        next += r->period;
        if (past_end || (r->opt.max_ticks > 0 && r->stats.ticks >= (uint64_t)r->opt.max_ticks) ||
            (r->opt.max_media_s > 0 && next - first > r->opt.max_media_s + 1e-9)) {
            finish(r, PB_SOURCE_ENDED);
            return NULL;
        }
    }
    finish(r, r->status ? PB_SOURCE_FAULT : PB_SOURCE_ENDED);
    return NULL;
}

/* After each read, on the bridge thread: the source's health, the last
 * fault's message and the sample counters. */
static void note_source(pb_runner *r, int got_sample)
{
    pb_source_state st = r->src->state;
    uint64_t drops = r->opt.count_drops ? r->opt.count_drops(r->src) : 0;
    pb_mutex_lock(&r->mu);
    if (st != r->stats.source && (st == PB_SOURCE_STALE || st == PB_SOURCE_DISCONNECTED || st == PB_SOURCE_FAULT))
        snprintf(r->stats.fault, sizeof r->stats.fault, "%s", r->src->message);
    r->stats.source = st;
    r->stats.drops = drops;
    if (got_sample) {
        r->stats.samples++;
        r->stats.last_sample_ns = pb_now_ns();
    }
    pb_mutex_unlock(&r->mu);
    atomic_store_explicit(&r->source_state, (int)st, memory_order_release);
}

/* Pause and seek for replays, under mu. A paused replay reads nothing; the
 * replay paces itself from the wall time of its last seek, so resuming (or
 * seeking) re-anchors it with a seek. Returns the recorded time to seek
 * to, or -1; *stop when the runner is stopping. */
static int64_t source_control(pb_runner *r, int64_t last_t_ns, int *stop)
{
    int64_t seek_to = -1;
    pb_mutex_lock(&r->mu);
    for (int was_paused = 0;;) {
        if (r->stop_req)
            break;
        if (r->seek_req) {
            seek_to = (int64_t)(r->seek_to * 1e9 + 0.5);
            r->seek_req = 0;
        }
        if (!r->paused) {
            if (was_paused && seek_to < 0)
                seek_to = last_t_ns + 1; /* continue after the last update delivered */
            break;
        }
        was_paused = 1;
        pb_cond_wait_until(&r->cv, &r->mu, pb_now_ns() + 50000000);
    }
    *stop = r->stop_req;
    pb_mutex_unlock(&r->mu);
    return seek_to;
}

static void *source_thread(void *arg)
{
    pb_runner *r = arg;
    apply_priority(r);
    /* Media time: a replay's recorded time, or, for live sources (stamped
     * with CLOCK_MONOTONIC), time since the first update. */
    int64_t t0 = 0, last_t = -1;
    int have_t0 = r->opt.recorded;
    if (r->opt.recorded && r->opt.start_s > 0)
        pb_source_seek(r->src, (int64_t)(r->opt.start_s * 1e9 + 0.5));
    for (;;) {
        int stop;
        int64_t seek_to = r->opt.recorded ? source_control(r, last_t, &stop) : -1;
        if (!r->opt.recorded) {
            pb_mutex_lock(&r->mu);
            stop = r->stop_req;
            pb_mutex_unlock(&r->mu);
        }
        if (stop)
            break;
        if (seek_to >= 0)
            pb_source_seek(r->src, seek_to);
        pb_update u;
        int got = pb_source_read(r->src, &u, 20);
        note_source(r, got == 1);
        if (got < 0) {
            if (r->src->state == PB_SOURCE_ENDED) {
                finish(r, PB_SOURCE_ENDED);
                return NULL;
            }
            pb_sleep_until_ns(pb_now_ns() + 20000000); /* the backend retries; do not spin */
            continue;
        }
        if (got == 0)
            continue;
        if (!have_t0) {
            t0 = u.t_ns;
            have_t0 = 1;
        }
        double media = (double)(u.t_ns - t0) * 1e-9;
        if (r->opt.max_media_s > 0 && media - r->opt.start_s > r->opt.max_media_s + 1e-9) {
            finish(r, PB_SOURCE_ENDED);
            return NULL;
        }
        last_t = u.t_ns;
        pb_chanmap_update(r->cm, &u);
        pb_pose *back = pb_handoff_back(&r->h);
        pb_chanmap_pose(r->cm, back);
        back->t_ns = pb_now_ns();
        back->lag_ns = 0;
        back->media_s = media;
        back->frame = -1;
        if (publish(r, back))
            break;
        if (r->opt.max_ticks > 0 && r->stats.ticks >= (uint64_t)r->opt.max_ticks) {
            finish(r, PB_SOURCE_ENDED);
            return NULL;
        }
    }
    finish(r, r->status ? PB_SOURCE_FAULT : PB_SOURCE_ENDED);
    return NULL;
}

static void runner_free(pb_runner *r)
{
    if (!r)
        return;
    pb_retarget_free(r->rt);
    pb_chanmap_free(r->cm);
    pb_source_destroy(r->src);
    pb_player_free(&r->player);
    pb_recorder_close(r->rec, NULL);
    pb_handoff_free(&r->h);
    free(r->lq);
    free(r->lt);
    pb_mutex_destroy(&r->mu);
    pb_cond_destroy(&r->cv);
    free(r);
}

static pose_status runner_new(const pb_rig_skel *rig, const pb_runner_options *opt, double frame_time,
                              pb_runner **out, pb_error *err)
{
    pb_runner *r = calloc(1, sizeof *r);
    if (!r)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    pb_mutex_init(&r->mu);
    pb_cond_init(&r->cv);
    if (opt)
        r->opt = *opt;
    r->rig = rig;
    r->warnings = pb_warnings_current();
    r->speed = r->opt.speed > 0 ? r->opt.speed : 1.0;
    r->paused = r->opt.start_paused;
    r->period = r->opt.rate_hz > 0 ? r->speed / r->opt.rate_hz : frame_time;
    r->stats.state = PB_SOURCE_WAITING;
    r->stats.source = PB_SOURCE_WAITING;
    atomic_init(&r->source_state, (int)PB_SOURCE_WAITING);
    r->stats.running = 1;
    r->stats.frame = -1;
    pb_lag_hist_reset(&r->lags);
    if (pb_handoff_init(&r->h, rig->joint_count) != 0) {
        runner_free(r);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
    if (r->opt.record_path) {
        pose_status s = pb_recorder_open(r->opt.record_path, rig, r->period, &r->rec, err);
        if (s) {
            runner_free(r);
            return s;
        }
    }
    *out = r;
    return POSE_OK;
}

static pose_status runner_launch(pb_runner *r, void *(*fn)(void *), pb_runner **out, pb_error *err)
{
    if (pb_thread_start(&r->thread, fn, r) != 0) {
        runner_free(r);
        return pb_fail(err, POSE_ERR_THREAD, "cannot start the bridge thread");
    }
    r->started = 1;
    *out = r;
    return POSE_OK;
}

pose_status pb_runner_start_clip(const pb_clip *clip, const pb_rig_skel *rig, const pb_mapping *map,
                                 const pb_runner_options *opt, pb_runner **out, pb_error *err)
{
    if (!clip || !rig || !map || !out)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_runner_start_clip: NULL argument");
    *out = NULL;
    pb_runner *r;
    pose_status s = runner_new(rig, opt, clip->frame_time, &r, err);
    if (s)
        return s;
    r->clip = clip;
    size_t n = (size_t)(clip->joint_count > 0 ? clip->joint_count : 1);
    r->lq = malloc(n * sizeof *r->lq);
    r->lt = malloc(n * sizeof *r->lt);
    if (!r->lq || !r->lt)
        s = pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    if (!s)
        s = pb_player_init(&r->player, clip, r->opt.loop, err);
    if (!s)
        s = pb_retarget_create(map, clip, rig, &r->rt, err);
    if (s) {
        runner_free(r);
        return s;
    }
    r->stats.state = PB_SOURCE_OK;
    r->stats.source = PB_SOURCE_OK;
    atomic_init(&r->source_state, (int)PB_SOURCE_OK);
    return runner_launch(r, clip_thread, out, err);
}

pose_status pb_runner_start_source(pb_source *src, const pb_rig_skel *rig, const pb_mapping *map,
                                   const pb_runner_options *opt, pb_runner **out, pb_error *err)
{
    /* The source is ours from here on, whatever happens: the caller never
     * has to guess which failures left it alive. */
    if (!src || !rig || !map || !out) {
        pb_source_destroy(src);
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_runner_start_source: NULL argument");
    }
    *out = NULL;
    pb_runner *r;
    pose_status s = runner_new(rig, opt, 0.01, &r, err);
    if (s) {
        pb_source_destroy(src);
        return s;
    }
    r->src = src; /* runner_free destroys it on the failures below */
    s = pb_chanmap_create(map, src->channels, src->channel_count, rig, &r->cm, err);
    if (s) {
        runner_free(r);
        return s;
    }
    r->stats.state = PB_SOURCE_OK;
    return runner_launch(r, source_thread, out, err);
}

const pb_pose *pb_runner_latest(pb_runner *r, int *fresh) { return pb_handoff_latest(&r->h, fresh); }

pb_source_state pb_runner_source_state(pb_runner *r)
{
    return (pb_source_state)atomic_load_explicit(&r->source_state, memory_order_acquire);
}

void pb_runner_stats_get(pb_runner *r, pb_runner_stats *out)
{
    pb_mutex_lock(&r->mu);
    *out = r->stats;
    pb_mutex_unlock(&r->mu);
}

void pb_runner_pause(pb_runner *r, int paused)
{
    pb_mutex_lock(&r->mu);
    r->paused = paused != 0;
    pb_cond_broadcast(&r->cv);
    pb_mutex_unlock(&r->mu);
}

void pb_runner_seek(pb_runner *r, double media_s)
{
    pb_mutex_lock(&r->mu);
    r->seek_to = media_s;
    r->seek_req = 1;
    pb_cond_broadcast(&r->cv);
    pb_mutex_unlock(&r->mu);
}

void pb_runner_step(pb_runner *r, int ticks)
{
    pb_mutex_lock(&r->mu);
    if (r->paused) /* steps only make sense while paused; none queue up during playback */
        r->step_req += ticks > 0 ? ticks : 0;
    pb_cond_broadcast(&r->cv);
    pb_mutex_unlock(&r->mu);
}

void pb_runner_set_speed(pb_runner *r, double speed)
{
    if (!(speed > 0))
        return;
    pb_mutex_lock(&r->mu);
    r->speed = speed;
    r->speed_req = 1;
    pb_cond_broadcast(&r->cv);
    pb_mutex_unlock(&r->mu);
}

int pb_runner_wait(pb_runner *r, int timeout_ms)
{
    int64_t until = timeout_ms < 0 ? INT64_MAX : pb_now_ns() + (int64_t)timeout_ms * 1000000;
    pb_mutex_lock(&r->mu);
    while (r->stats.running) {
        if (until == INT64_MAX) {
            pb_cond_wait(&r->cv, &r->mu);
        } else {
            if (pb_cond_wait_until(&r->cv, &r->mu, until) != 0 && pb_now_ns() >= until)
                break;
        }
    }
    int ended = !r->stats.running;
    pb_mutex_unlock(&r->mu);
    return ended;
}

uint64_t pb_runner_lag_quantiles(pb_runner *r, const double *q, double *out_ms, int n)
{
    pb_mutex_lock(&r->mu);
    for (int i = 0; i < n; i++)
        out_ms[i] = pb_lag_hist_quantile_ns(&r->lags, q[i]) * 1e-6;
    uint64_t count = r->lags.count;
    pb_mutex_unlock(&r->mu);
    return count;
}

pose_status pb_runner_stop(pb_runner *r, pb_error *err)
{
    if (!r)
        return POSE_OK;
    pb_mutex_lock(&r->mu);
    r->stop_req = 1;
    pb_cond_broadcast(&r->cv);
    pb_mutex_unlock(&r->mu);
    if (r->started)
        pb_thread_join(&r->thread);
    pose_status s = r->status;
    if (s && err)
        *err = r->err;
    if (r->rec) {
        pose_status c = pb_recorder_close(r->rec, err);
        r->rec = NULL;
        if (!s)
            s = c;
    }
    runner_free(r);
    return s;
}
