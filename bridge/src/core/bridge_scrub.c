/* SPDX-License-Identifier: Apache-2.0
 * pose_bridge_pose_at: a second replay of the source, owned by the host
 * thread, fed as fast as possible up to the requested recorded time through
 * the same pieces as the bridge thread (runner.c): clips tick by tick, one
 * period apart from 0, through a player and a retargeter of their own (the
 * filters see the same samples at the same spacing); HID and CAN recordings
 * update by update through the same decoder and channel mapping. A later
 * time continues, an earlier one starts over, so the result never depends
 * on which times were asked before. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bridge_apply.h"
#include "bridge_internal.h"

void pb_scrub_close(pose_bridge *b)
{
    pb_scrub *s = &b->scrub;
    pb_retarget_free(s->rt);
    pb_chanmap_free(s->cm);
    pb_source_destroy(s->src);
    if (s->player_ok)
        pb_player_free(&s->player);
    pb_bridge_free(b, s->lq);
    pb_bridge_free(b, s->lt);
    pb_bridge_free(b, s->next_ch);
    pb_bridge_free(b, s->next_val);
    pb_bridge_free(b, s->pose.q);
    pb_bridge_free(b, s->pose.active);
    memset(s, 0, sizeof *s);
}

/* The pose buffers come from the host's allocator (pb_pose_init would use malloc). */
static pose_status scrub_pose_init(pose_bridge *b, pb_error *err)
{
    pb_pose *p = &b->scrub.pose;
    if (p->q)
        return POSE_OK;
    size_t n = (size_t)(b->skel->joint_count > 0 ? b->skel->joint_count : 1);
    p->q = pb_bridge_alloc(b, n * sizeof *p->q);
    p->active = pb_bridge_alloc(b, n);
    if (!p->q || !p->active)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    p->joint_count = b->skel->joint_count;
    pb_pose_reset(p);
    return POSE_OK;
}

static pose_status restart_clip(pose_bridge *b, pb_error *err)
{
    pb_scrub *s = &b->scrub;
    if (!s->player_ok) {
        size_t n = (size_t)b->clip->joint_count;
        s->lq = pb_bridge_alloc(b, n * sizeof *s->lq);
        s->lt = pb_bridge_alloc(b, n * sizeof *s->lt);
        if (!s->lq || !s->lt)
            return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        pose_status st = pb_player_init(&s->player, b->clip, 0, err);
        if (st < 0)
            return st;
        s->player_ok = 1;
    }
    /* A fresh retargeter: its filters start as the bridge thread's did. */
    pb_retarget_free(s->rt);
    s->rt = NULL;
    pose_status st = pb_retarget_create(b->map, b->clip, b->skel, &s->rt, err);
    if (st < 0)
        return st;
    s->next_tick = 0.0;
    return POSE_OK;
}

static pose_status restart_device(pose_bridge *b, pb_error *err)
{
    pb_scrub *s = &b->scrub;
    pb_chanmap_free(s->cm);
    pb_source_destroy(s->src);
    s->cm = NULL;
    s->src = NULL;
    pb_spec_open_options o = {.map_path = b->map_path, .map_json = b->map_json, .as_fast_as_possible = 1};
    pose_status st = pb_spec_open_device(&b->spec, &o, &s->src, err);
    if (st < 0)
        return st;
    st = pb_chanmap_create(b->map, s->src->channels, s->src->channel_count, b->skel, &s->cm, err);
    if (st < 0)
        return st;
    size_t need = s->src->channel_count + 1;
    if (s->next_cap < need) {
        pb_bridge_free(b, s->next_ch);
        pb_bridge_free(b, s->next_val);
        s->next_ch = pb_bridge_alloc(b, need * sizeof *s->next_ch);
        s->next_val = pb_bridge_alloc(b, need * sizeof *s->next_val);
        s->next_cap = s->next_ch && s->next_val ? need : 0;
        if (!s->next_cap)
            return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
    s->last_t = -1;
    s->have_next = 0;
    s->samples = 0;
    return POSE_OK;
}

pose_status pb_scrub_restart(pose_bridge *b, pb_error *err)
{
    pose_status st = scrub_pose_init(b, err);
    if (st >= 0)
        st = b->clip ? restart_clip(b, err) : restart_device(b, err);
    if (st < 0)
        return st;
    pb_pose_reset(&b->scrub.pose);
    b->scrub.media_s = 0.0;
    b->scrub.held = 0;
    b->scrub.state = PB_SOURCE_WAITING;
    b->scrub.open = 1;
    return POSE_OK;
}

static pose_status clip_to(pose_bridge *b, double t_s, pb_error *err)
{
    pb_scrub *s = &b->scrub;
    double end = pb_player_duration(&s->player);
    /* The bridge thread's last tick is the first one past the end (showing the last frame). */
    if (t_s > end + b->period + 1e-9)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "%s: %.3f s is past the end of the clip (%.3f s)",
                       b->clip->path, t_s, end);
    /* Ticks accumulate as the runner's do (next += period), so their times match to the bit. */
    while (s->next_tick <= t_s + 1e-9) {
        double ct;
        pb_player_wrap(&s->player, s->next_tick, &ct);
        pb_player_sample(&s->player, ct, s->lq, s->lt);
        pb_retarget_apply(s->rt, (const double (*)[4])s->lq, (const double (*)[3])s->lt, b->period, &s->pose);
        s->pose.media_s = s->next_tick;
        s->pose.frame = (long)floor(ct / b->clip->frame_time + 1e-9);
        s->media_s = s->next_tick;
        s->samples++;
        s->next_tick += b->period;
    }
    s->state = PB_SOURCE_OK;
    s->held = 0;
    return POSE_OK;
}

/* Keep the first update past the requested time for the next request (the
 * source owns its arrays only until the next read). */
static void hold_next(pb_scrub *s, const pb_update *u)
{
    size_t n = u->count < s->next_cap ? u->count : s->next_cap;
    memcpy(s->next_ch, u->channels, n * sizeof *s->next_ch);
    memcpy(s->next_val, u->values, n * sizeof *s->next_val);
    s->next = (pb_update){.t_ns = u->t_ns, .count = n, .channels = s->next_ch, .values = s->next_val};
    s->have_next = 1;
}

static pose_status device_to(pose_bridge *b, double t_s, pb_error *err)
{
    pb_scrub *s = &b->scrub;
    const int64_t want = (int64_t)(t_s * 1e9 + 0.5);
    /* Faults the recording reports (a silent node, bus-off) are the
     * recording's and play on, as they do live. */
    for (int misses = 0;;) {
        pb_update u;
        if (s->have_next) {
            u = s->next;
        } else {
            int got = pb_source_read(s->src, &u, 1000);
            if (got <= 0) {
                /* The last sample's own time is the recording's end, not past it. */
                if (s->src->state == PB_SOURCE_ENDED && s->last_t >= 0 && want <= s->last_t + 1000)
                    break;
                if (s->src->state == PB_SOURCE_ENDED || ++misses > 10000)
                    return pb_fail(err, POSE_ERR_INVALID_ARGUMENT,
                                   "%s: %.3f s is past the end of the recording (%.3f s)", b->spec.target, t_s,
                                   s->last_t > 0 ? (double)s->last_t * 1e-9 : 0.0);
                continue;
            }
            misses = 0;
        }
        if (u.t_ns > want) {
            if (!s->have_next)
                hold_next(s, &u);
            break;
        }
        s->have_next = 0;
        pb_chanmap_update(s->cm, &u);
        s->last_t = u.t_ns;
        s->samples++;
        if (pb_state_holds(s->src->state))
            snprintf(b->fault, sizeof b->fault, "%s", s->src->message);
    }
    pb_chanmap_pose(s->cm, &s->pose);
    s->media_s = s->last_t >= 0 ? (double)s->last_t * 1e-9 : 0.0;
    s->pose.media_s = s->media_s;
    s->pose.frame = -1;
    s->state = s->last_t < 0 ? PB_SOURCE_WAITING : s->src->state;
    /* Recordings play as fast as possible here, so silence is judged on the recorded clock. */
    double stale = b->opt.stale_after_s > 0 ? b->opt.stale_after_s : 0.25;
    s->held = pb_state_holds(s->state) || (s->last_t >= 0 && t_s - s->media_s > stale);
    return POSE_OK;
}

pose_status pb_scrub_to(pose_bridge *b, double t_s, pb_error *err)
{
    pb_scrub *s = &b->scrub;
    double shown = b->clip ? s->next_tick - b->period : (s->last_t >= 0 ? (double)s->last_t * 1e-9 : 0.0);
    if (!s->open || t_s < shown - 1e-9) {
        pose_status st = pb_scrub_restart(b, err);
        if (st < 0)
            return st;
    }
    return b->clip ? clip_to(b, t_s, err) : device_to(b, t_s, err);
}

pose_status pb_scrub_duration(pose_bridge *b, double *out, pb_error *err)
{
    if (b->duration_s >= 0 || b->clip || pb_spec_is_live(b->spec.kind)) {
        *out = b->clip ? (double)(b->clip->frame_count - 1) * b->clip->frame_time : b->duration_s;
        return POSE_OK;
    }
    /* A separate pass, so the scrubber keeps its place. */
    pb_source *src = NULL;
    pb_spec_open_options o = {.map_path = b->map_path, .map_json = b->map_json, .as_fast_as_possible = 1};
    pose_status st = pb_spec_open_device(&b->spec, &o, &src, err);
    if (st < 0)
        return st;
    int64_t last = 0;
    pb_update u;
    for (int misses = 0; misses < 10000;) {
        int got = pb_source_read(src, &u, 1000);
        if (got == 1) {
            last = u.t_ns;
            misses = 0;
        } else if (src->state == PB_SOURCE_ENDED) {
            break;
        } else {
            misses++;
        }
    }
    pb_source_destroy(src);
    b->duration_s = (double)last * 1e-9;
    *out = b->duration_s;
    return POSE_OK;
}
