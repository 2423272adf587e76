/* SPDX-License-Identifier: Apache-2.0
 * pose/bridge.h: open a source by its string, run it on the bridge thread
 * (runner.c) or not at all (POSE_BRIDGE_MANUAL), hand poses to the host's
 * state, report health. Errors go to pose_last_error() with the message the
 * parser or backend wrote (file and line). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bridge_apply.h"
#include "bridge_internal.h"
#include "clock.h"

/* ------------------------------------------------------------ allocation */

void *pb_bridge_alloc(const pose_bridge *b, size_t size)
{
    if (b->alloc.alloc)
        return b->alloc.alloc(size ? size : 1, 16, b->alloc.user);
    return malloc(size ? size : 1);
}

void pb_bridge_free(const pose_bridge *b, void *p)
{
    if (!p)
        return;
    if (b->alloc.free)
        b->alloc.free(p, b->alloc.user);
    else
        free(p);
}

static char *bridge_strdup(const pose_bridge *b, const char *s)
{
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char *d = pb_bridge_alloc(b, n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static pose_status fail(pose_status s, const char *message)
{
    pose_set_last_error(message);
    return s;
}

/* ------------------------------------------------------------- open/close */

static pose_status check_options(const pose_bridge_options *o, pb_error *err)
{
    if ((unsigned)o->play > POSE_BRIDGE_MANUAL)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pose_bridge_open: options.play %d is not a pose_bridge_play",
                       (int)o->play);
    const double nums[] = {o->speed, o->start_s, o->end_s, o->rate_hz, o->stale_after_s};
    const char *names[] = {"speed", "start_s", "end_s", "rate_hz", "stale_after_s"};
    for (size_t i = 0; i < sizeof nums / sizeof nums[0]; i++)
        if (!isfinite(nums[i]) || nums[i] < 0)
            return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pose_bridge_open: options.%s must be finite and >= 0 (is %g)",
                           names[i], nums[i]);
    if (o->end_s > 0 && o->end_s < o->start_s)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pose_bridge_open: options.end_s %g is before start_s %g",
                       o->end_s, o->start_s);
    if (o->max_poses < 0)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pose_bridge_open: options.max_poses is negative");
    if (!o->allocator.alloc != !o->allocator.free)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pose_bridge_open: options.allocator needs both alloc and free");
    if (o->map_path && o->map_json)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pose_bridge_open: give options.map_path or map_json, not both");
    return POSE_OK;
}

static pose_status load_clip(pose_bridge *b, pb_error *err)
{
    const char *path = b->spec.target;
    pose_status s;
    if (b->spec.kind == PB_SPEC_BVH) {
        s = pb_bvh_load(path, &b->clip, err);
    } else if (b->skeleton) {
        s = pb_asf_load(b->skeleton, &b->clip, err);
        if (s >= 0)
            s = pb_amc_load(b->clip, path, err);
    } else {
        s = pb_clip_load(path, NULL, &b->clip, err); /* finds 01.asf beside 01_01.amc */
    }
    if (s < 0)
        return s;
    if (b->clip->frame_count == 0)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: the clip has no frames", path);
    double speed = b->opt.speed > 0 ? b->opt.speed : 1.0;
    /* as the runner computes its tick period */
    b->period = b->opt.rate_hz > 0 ? speed / b->opt.rate_hz : b->clip->frame_time;
    return POSE_OK;
}

static pb_runner_options runner_options(const pose_bridge *b)
{
    const pose_bridge_options *o = &b->opt;
    return (pb_runner_options){
        .speed = o->speed > 0 ? o->speed : 1.0,
        .afap = o->play == POSE_BRIDGE_AS_FAST_AS_POSSIBLE,
        .loop = o->loop,
        .rate_hz = o->rate_hz,
        .max_ticks = o->max_poses,
        .max_media_s = o->end_s > 0 ? (o->end_s - o->start_s > 0 ? o->end_s - o->start_s : 1e-9) : 0.0,
        .start_s = o->start_s,
        .start_paused = o->start_paused,
        .record_path = o->record_path,
        .rt_priority = o->rt_priority,
        .recorded = !pb_spec_is_live(b->spec.kind),
        .count_drops = pb_spec_source_drops,
    };
}

/* The map's "ranges" against the rig, now: a joint the rig cannot take a
 * range for fails the open, not the first frame. */
static pose_status bind_ranges(pose_bridge *b, pb_error *err)
{
    if (b->map->range_count == 0)
        return POSE_OK;
    b->ranges = pb_bridge_alloc(b, (size_t)b->map->range_count * sizeof *b->ranges);
    if (!b->ranges)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "pose_bridge_open: out of memory");
    for (; b->range_count < b->map->range_count; b->range_count++) {
        pose_status s = pb_mapping_resolve_range(b->map, b->range_count, b->skel, &b->ranges[b->range_count], err);
        if (s < 0)
            return s;
    }
    return POSE_OK;
}

static pose_status open_parts(pose_bridge *b, pb_error *err)
{
    pose_status s = pb_spec_parse(b->source, &b->spec, err);
    if (s < 0)
        return s;
    int clip = pb_spec_is_clip(b->spec.kind);
    if (b->opt.play == POSE_BRIDGE_MANUAL && pb_spec_is_live(b->spec.kind))
        return pb_fail(err, POSE_ERR_UNSUPPORTED, "%s: a live source has no recorded times to play POSE_BRIDGE_MANUAL",
                       b->source);
    if (!clip && !b->map_path && !b->map_json)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT,
                       "%s: a HID, CAN or USB source needs a mapping with \"channels\" (options.map_path or map_json)",
                       b->source);
    s = pb_rig_skel_from_rig(b->rig, &b->skel, err);
    if (s < 0)
        return s;
    if (b->map_json)
        s = pb_mapping_parse(b->map_json, strlen(b->map_json), "map_json", &b->map, err);
    else if (b->map_path)
        s = pb_mapping_load(b->map_path, &b->map, err);
    else
        s = pb_mapping_identity(&b->map, err);
    if (s < 0)
        return s;
    if ((s = bind_ranges(b, err)) < 0)
        return s;
    if (clip && (s = load_clip(b, err)) < 0)
        return s;
    if (!clip && !pb_spec_is_live(b->spec.kind)) {
        /* A recording's duration, by a separate pass now rather than on the
         * first pose_bridge_status_get, which would read the whole file on
         * the host's frame; its warnings are left to the pass that plays. */
        pb_warnings *sink = pb_warnings_install(NULL);
        double duration;
        s = pb_scrub_duration(b, &duration, err);
        pb_warnings_install(sink);
        if (s < 0)
            return s;
    }
    if (b->opt.play == POSE_BRIDGE_MANUAL)
        return pb_scrub_restart(b, err); /* reads and checks the source now */
    pb_runner_options ro = runner_options(b);
    if (clip)
        return pb_runner_start_clip(b->clip, b->skel, b->map, &ro, &b->runner, err);
    pb_source *src = NULL;
    pb_spec_open_options so = {
        .map_path = b->map_path,
        .map_json = b->map_json,
        .as_fast_as_possible = b->opt.play == POSE_BRIDGE_AS_FAST_AS_POSSIBLE,
        .loop = b->opt.loop,
        .speed = b->opt.speed,
        .stale_ms = (int)((b->opt.stale_after_s > 0 ? b->opt.stale_after_s : 0.25) * 1000.0 + 0.5),
    };
    s = pb_spec_open_device(&b->spec, &so, &src, err);
    if (s < 0)
        return s;
    return pb_runner_start_source(src, b->skel, b->map, &ro, &b->runner, err); /* takes src */
}

pose_status pose_bridge_open(const char *source, const pose_rig *rig, const pose_bridge_options *options,
                             pose_bridge **out)
{
    if (!out)
        return fail(POSE_ERR_INVALID_ARGUMENT, "pose_bridge_open: out is NULL");
    *out = NULL;
    if (!source || !rig)
        return fail(POSE_ERR_INVALID_ARGUMENT, "pose_bridge_open: source and rig are required");
    pose_bridge_options o;
    memset(&o, 0, sizeof o);
    if (options && options->size) {
        if (options->size < POSE_BRIDGE_OPTIONS_SIZE_0_2) {
            char m[160];
            snprintf(m, sizeof m, "pose_bridge_open: options.size %zu is neither 0 nor at least %zu (the 0.2 layout)",
                     options->size, (size_t)POSE_BRIDGE_OPTIONS_SIZE_0_2);
            return fail(POSE_ERR_INVALID_ARGUMENT, m);
        }
        memcpy(&o, options, options->size < sizeof o ? options->size : sizeof o);
    }
    o.size = sizeof o;
    pb_error err = {{0}};
    if (check_options(&o, &err) < 0)
        return fail(POSE_ERR_INVALID_ARGUMENT, err.message);

    pose_bridge tmp = {.alloc = o.allocator};
    pose_bridge *b = pb_bridge_alloc(&tmp, sizeof *b);
    if (!b)
        return fail(POSE_ERR_OUT_OF_MEMORY, "pose_bridge_open: out of memory");
    memset(b, 0, sizeof *b);
    b->alloc = o.allocator;
    b->opt = o;
    b->rig = rig;
    b->duration_s = -1.0;
    b->source = bridge_strdup(b, source);
    b->map_path = bridge_strdup(b, o.map_path);
    b->map_json = bridge_strdup(b, o.map_json);
    b->skeleton = bridge_strdup(b, o.skeleton);
    pose_status s;
    if (!b->source || (o.map_path && !b->map_path) || (o.map_json && !b->map_json) ||
        (o.skeleton && !b->skeleton)) {
        s = pb_fail(&err, POSE_ERR_OUT_OF_MEMORY, "pose_bridge_open: out of memory");
    } else {
        b->opt.map_path = b->map_path;
        b->opt.map_json = b->map_json;
        b->opt.skeleton = b->skeleton;
        /* Parsers report what they accepted with a warning to this thread's sink. */
        pb_warnings *prev = pb_warnings_install(&b->warnings);
        s = open_parts(b, &err);
        pb_warnings_install(prev);
    }
    b->opt.record_path = NULL; /* the runner opened it; the caller's string need not outlive the call */
    if (s < 0) {
        pose_bridge_close(b);
        return fail(s, err.message[0] ? err.message : pose_status_string(s));
    }
    b->paused = o.start_paused;
    *out = b;
    return POSE_OK;
}

void pose_bridge_close(pose_bridge *b)
{
    if (!b)
        return;
    pb_runner_stop(b->runner, NULL);
    pb_scrub_close(b);
    pb_clip_free(b->clip);
    pb_mapping_free(b->map);
    pb_bridge_free(b, b->ranges);
    pb_rig_skel_free(b->skel);
    pb_bridge_free(b, b->source);
    pb_bridge_free(b, b->map_path);
    pb_bridge_free(b, b->map_json);
    pb_bridge_free(b, b->skeleton);
    pb_bridge_free(b, b);
}

/* ------------------------------------------------------------------ poses */

static pose_status set_state(const pose_bridge *b, const pb_pose *p, pose_state *st, pose_bridge_frame *f)
{
    /* Every call rather than once per state: a host's next state may sit
     * where its last one was freed. A state that has them already costs a
     * read per range. */
    for (int i = 0; i < b->range_count; i++) {
        pose_status s = pb_joint_range_apply(&b->ranges[i], st);
        if (s < 0)
            return s;
    }
    int clamped = 0;
    pose_status s = pb_pose_apply_to_state(p, st, &clamped);
    if (s < 0)
        return s;
    int n = 0;
    for (int j = 0; j < p->joint_count; j++)
        n += p->active[j] != 0;
    f->joints = n;
    f->clamped = clamped;
    f->media_s = p->media_s;
    return clamped ? POSE_CLAMPED : POSE_OK;
}

static pose_status check_state(const pose_bridge *b, const pose_state *st, const char *fn)
{
    char m[160];
    if (!b || !st) {
        snprintf(m, sizeof m, "%s: bridge and state are required", fn);
        return fail(POSE_ERR_INVALID_ARGUMENT, m);
    }
    if (pose_state_rig(st) != b->rig) {
        snprintf(m, sizeof m, "%s: the state is of another rig than the bridge's", fn);
        return fail(POSE_ERR_INVALID_ARGUMENT, m);
    }
    return POSE_OK;
}

pose_status pose_bridge_apply(pose_bridge *b, pose_state *st, pose_bridge_frame *frame)
{
    pose_bridge_frame f = {0};
    pose_status s = check_state(b, st, "pose_bridge_apply");
    if (s < 0)
        return s;
    if (!b->runner) {
        f = b->manual;
        f.fresh = 0;
    } else {
        int fresh = 0;
        const pb_pose *p = pb_runner_latest(b->runner, &fresh);
        f.held = pb_state_holds(pb_runner_source_state(b->runner));
        if (p->seq > 0) {
            s = set_state(b, p, st, &f);
            if (s < 0)
                return s;
            f.fresh = fresh;
            f.seq = p->seq;
            f.age_s = (double)(pb_now_ns() - p->t_ns) * 1e-9;
        }
    }
    if (frame)
        *frame = f;
    return s;
}

pose_status pose_bridge_pose_at(pose_bridge *b, double t_s, pose_state *st, pose_bridge_frame *frame)
{
    pose_status s = check_state(b, st, "pose_bridge_pose_at");
    if (s < 0)
        return s;
    char m[320];
    if (pb_spec_is_live(b->spec.kind)) {
        snprintf(m, sizeof m, "%s: a live source has no recorded time to pose at", b->source);
        return fail(POSE_ERR_UNSUPPORTED, m);
    }
    if (!isfinite(t_s) || t_s < 0) {
        snprintf(m, sizeof m, "pose_bridge_pose_at: time %g s is not a recorded time (finite, >= 0)", t_s);
        return fail(POSE_ERR_INVALID_ARGUMENT, m);
    }
    pb_error err = {{0}};
    s = pb_scrub_to(b, t_s, &err);
    if (s < 0)
        return fail(s, err.message);
    pose_bridge_frame f = {.fresh = 1, .held = b->scrub.held, .seq = b->manual.seq + 1};
    s = set_state(b, &b->scrub.pose, st, &f);
    if (s < 0)
        return s;
    f.age_s = t_s - b->scrub.media_s;
    b->manual = f;
    if (frame)
        *frame = f;
    return s;
}

/* ----------------------------------------------------------------- status */

pose_status pose_bridge_status_get(pose_bridge *b, pose_bridge_status *status)
{
    if (!b || !status)
        return fail(POSE_ERR_INVALID_ARGUMENT, "pose_bridge_status_get: bridge and status are required");
    if (status->size < sizeof *status) {
        char m[160];
        snprintf(m, sizeof m, "pose_bridge_status_get: status.size %zu is smaller than the 0.2 layout (%zu)",
                 status->size, sizeof *status);
        return fail(POSE_ERR_INVALID_ARGUMENT, m);
    }
    pose_bridge_status o;
    memset(&o, 0, sizeof o);
    o.size = status->size;
    o.kind = pb_spec_kind_name(b->spec.kind);
    o.connected = 1;
    o.last_sample_age_s = -1.0;
    o.frame = -1;
    o.frame_count = b->clip ? (long)b->clip->frame_count : -1;
    o.frame_time_s = b->clip ? b->clip->frame_time : 0.0;
    pb_error err = {{0}};
    if (pb_spec_is_live(b->spec.kind))
        o.duration_s = -1.0;
    else if (pb_scrub_duration(b, &o.duration_s, &err) < 0)
        return fail(POSE_ERR_IO, err.message);
    if (b->runner) {
        pb_runner_stats s;
        pb_runner_stats_get(b->runner, &s);
        o.state = (pose_bridge_source_state)(s.running ? s.source : s.state);
        if (pb_spec_is_live(b->spec.kind))
            o.connected = s.source != PB_SOURCE_DISCONNECTED;
        o.samples = s.samples;
        o.drops = s.drops;
        o.poses = s.ticks;
        if (s.last_sample_ns)
            o.last_sample_age_s = (double)(pb_now_ns() - s.last_sample_ns) * 1e-9;
        o.media_s = s.media_s;
        o.frame = b->clip ? s.frame : -1;
        o.lag_max_ms = s.lag_max_ms;
        o.realtime = s.realtime;
        snprintf(o.fault, sizeof o.fault, "%s", s.fault);
        if (b->clip) {
            static const double q[2] = {0.5, 0.99};
            double ms[2];
            pb_runner_lag_quantiles(b->runner, q, ms, 2);
            o.lag_p50_ms = ms[0];
            o.lag_p99_ms = ms[1];
        }
    } else {
        o.state = (pose_bridge_source_state)b->scrub.state;
        o.samples = b->scrub.samples;
        o.poses = b->manual.seq;
        o.media_s = b->manual.media_s;
        o.frame = b->clip && b->manual.seq ? b->scrub.pose.frame : -1;
        snprintf(o.fault, sizeof o.fault, "%s", b->fault);
    }
    *status = o;
    return POSE_OK;
}

/* --------------------------------------------------------------- controls */

/* The controls act on recorded sources played by the bridge thread. */
static pose_status check_control(const pose_bridge *b, const char *fn)
{
    char m[320];
    if (!b) {
        snprintf(m, sizeof m, "%s: bridge is NULL", fn);
        return fail(POSE_ERR_INVALID_ARGUMENT, m);
    }
    if (!b->runner) {
        snprintf(m, sizeof m, "%s: %s plays POSE_BRIDGE_MANUAL (use pose_bridge_pose_at)", fn, b->source);
        return fail(POSE_ERR_UNSUPPORTED, m);
    }
    if (pb_spec_is_live(b->spec.kind)) {
        snprintf(m, sizeof m, "%s: %s is live", fn, b->source);
        return fail(POSE_ERR_UNSUPPORTED, m);
    }
    return POSE_OK;
}

pose_status pose_bridge_pause(pose_bridge *b, int paused)
{
    pose_status s = check_control(b, "pose_bridge_pause");
    if (s < 0)
        return s;
    b->paused = paused != 0;
    pb_runner_pause(b->runner, b->paused);
    return POSE_OK;
}

pose_status pose_bridge_seek(pose_bridge *b, double t_s)
{
    pose_status s = check_control(b, "pose_bridge_seek");
    if (s < 0)
        return s;
    if (!isfinite(t_s) || t_s < 0)
        return fail(POSE_ERR_INVALID_ARGUMENT, "pose_bridge_seek: time must be finite and >= 0");
    pb_runner_seek(b->runner, t_s);
    if (b->paused && b->clip)
        pb_runner_step(b->runner, 1); /* show the pose at t_s */
    return POSE_OK;
}

pose_status pose_bridge_set_speed(pose_bridge *b, double speed)
{
    pose_status s = check_control(b, "pose_bridge_set_speed");
    if (s < 0)
        return s;
    if (!b->clip)
        return fail(POSE_ERR_UNSUPPORTED, "pose_bridge_set_speed: a HID or CAN recording plays at the "
                                          "options.speed it was opened with");
    if (!(speed > 0) || !isfinite(speed))
        return fail(POSE_ERR_INVALID_ARGUMENT, "pose_bridge_set_speed: speed must be > 0");
    pb_runner_set_speed(b->runner, speed);
    return POSE_OK;
}

int pose_bridge_wait(pose_bridge *b, int timeout_ms)
{
    if (!b || !b->runner)
        return 0;
    return pb_runner_wait(b->runner, timeout_ms);
}

/* ------------------------------------------------------------- warnings */

size_t pose_bridge_warning_count(const pose_bridge *b)
{
    return b ? b->warnings.count : 0;
}

const char *pose_bridge_warning(const pose_bridge *b, size_t index)
{
    return b && index < b->warnings.count ? b->warnings.text[index] : NULL;
}

const char *pose_bridge_state_name(pose_bridge_source_state state)
{
    /* the public states are the sources' own, value for value */
    return pb_source_state_name((pb_source_state)state);
}
