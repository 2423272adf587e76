/* SPDX-License-Identifier: Apache-2.0 */
#include "hid_replay.h"
#include "clock.h"

#include <stdlib.h>
#include <string.h>

typedef struct replay {
    pb_hid_transport base;
    pb_hid_recording *rec;
    pb_hid_replay_options opt;
    pb_hid_fault *faults;
    uint8_t *fired;
    uint32_t *events;   /* indices of this device's events in rec->events */
    size_t count, pos;
    int64_t base_wall, base_t, loop_offset;
    int64_t gone_until, silent_until;
    uint32_t rng;
    int started;
} replay;

static const pb_hid_rec_event *event_at(const replay *r, size_t i)
{
    return &r->rec->events[r->events[i]];
}

static pose_status replay_open(pb_hid_transport *t, uint8_t *desc, size_t cap, size_t *len, pb_error *err)
{
    replay *r = (replay *)t;
    int64_t now = pb_now_ns();
    if (now < r->gone_until)
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: device not present (simulated unplug)", t->origin);
    const pb_hid_rec_device *d = &r->rec->devices[r->opt.device];
    if (d->desc_len > cap)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: descriptor of %zu bytes is too large", t->origin, d->desc_len);
    memcpy(desc, d->desc, d->desc_len);
    *len = d->desc_len;
    if (r->started && !r->opt.as_fast_as_possible) {
        /* Reports sent while unplugged are lost: resume with the first one still due. */
        while (r->pos < r->count &&
               r->base_wall + (int64_t)((double)(event_at(r, r->pos)->t_ns + r->loop_offset - r->base_t) / r->opt.speed) < now)
            r->pos++;
    }
    return POSE_OK;
}

static int inject(replay *r, const pb_hid_fault *f, uint8_t *buf, size_t cap, int64_t *t_ns)
{
    const pb_hid_rec_event *e = event_at(r, r->pos);
    const uint8_t *bytes = r->rec->data + e->offset;
    size_t n = e->len < cap ? e->len : cap;
    *t_ns = e->t_ns + r->loop_offset;
    switch (f->kind) {
    case PB_HID_FAULT_GARBAGE: {
        r->rng = r->rng * 1664525u + 1013904223u; /* fixed LCG: the same garbage every run */
        size_t len = 1 + (r->rng >> 24) % 8;
        for (size_t i = 0; i < len && i < cap; i++) {
            r->rng = r->rng * 1664525u + 1013904223u;
            buf[i] = (uint8_t)(r->rng >> 24);
        }
        return (int)len;
    }
    case PB_HID_FAULT_WRONG_ID:
        memcpy(buf, bytes, n);
        if (n)
            buf[0] = 0xEE;
        return (int)n;
    case PB_HID_FAULT_SHORT:
        memcpy(buf, bytes, n / 2);
        return (int)(n / 2);
    default:
        return 0;
    }
}

static int replay_read(pb_hid_transport *t, uint8_t *buf, size_t cap, int timeout_ms, int64_t *t_ns)
{
    replay *r = (replay *)t;
    int64_t now = pb_now_ns();
    int64_t deadline = timeout_ms < 0 ? INT64_MAX : now + (int64_t)timeout_ms * 1000000;
    if (!r->started) {
        r->started = 1;
        r->base_wall = now;
        r->base_t = r->count ? event_at(r, 0)->t_ns : 0;
    }
    if (now < r->silent_until) {
        pb_hid_sleep_until(r->silent_until < deadline ? r->silent_until : deadline);
        if (pb_now_ns() < r->silent_until)
            return 0;
    }
    if (r->pos >= r->count) {
        if (!r->opt.loop || r->count == 0)
            return PB_HID_READ_ENDED;
        const pb_hid_rec_event *a = event_at(r, 0), *b = event_at(r, r->count - 1);
        int64_t gap = r->count > 1 ? (b->t_ns - a->t_ns) / (int64_t)(r->count - 1) : 1000000;
        r->loop_offset += b->t_ns - a->t_ns + gap; /* the loop continues one mean period later */
        r->pos = 0;
    }
    for (size_t i = 0; i < r->opt.fault_count; i++) {
        pb_hid_fault *f = &r->faults[i];
        if (r->fired[i] || f->at_event != r->pos)
            continue;
        r->fired[i] = 1;
        if (f->kind == PB_HID_FAULT_DISCONNECT) {
            r->gone_until = pb_now_ns() + (int64_t)f->duration_ms * 1000000;
            return PB_HID_READ_GONE;
        }
        if (f->kind == PB_HID_FAULT_SILENCE) {
            int64_t d = (int64_t)f->duration_ms * 1000000;
            r->silent_until = pb_now_ns() + d;
            r->base_wall += d; /* everything after the silence comes that much later */
            return replay_read(t, buf, cap, timeout_ms < 0 ? -1 : (int)((deadline - pb_now_ns()) / 1000000), t_ns);
        }
        return inject(r, f, buf, cap, t_ns);
    }
    const pb_hid_rec_event *e = event_at(r, r->pos);
    if (!r->opt.as_fast_as_possible) {
        int64_t due = r->base_wall + (int64_t)((double)(e->t_ns + r->loop_offset - r->base_t) / r->opt.speed);
        if (due > deadline) {
            pb_hid_sleep_until(deadline);
            return 0;
        }
        pb_hid_sleep_until(due);
    }
    size_t n = e->len < cap ? e->len : cap;
    memcpy(buf, r->rec->data + e->offset, n);
    *t_ns = e->t_ns + r->loop_offset;
    r->pos++;
    return (int)n;
}

static int replay_seek(pb_hid_transport *t, int64_t t_ns)
{
    replay *r = (replay *)t;
    size_t lo = 0, hi = r->count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (event_at(r, mid)->t_ns < t_ns)
            lo = mid + 1;
        else
            hi = mid;
    }
    r->pos = lo;
    r->loop_offset = 0;
    r->started = 1;
    r->base_wall = pb_now_ns();
    r->base_t = lo < r->count ? event_at(r, lo)->t_ns : t_ns;
    return 0;
}

static void replay_close(pb_hid_transport *t)
{
    (void)t; /* nothing to release: the recording stays loaded for a reopen */
}

static void replay_destroy(pb_hid_transport *t)
{
    replay *r = (replay *)t;
    pb_hid_recording_free(r->rec);
    free(r->faults);
    free(r->fired);
    free(r->events);
    free(r);
}

static const pb_hid_transport_ops replay_ops = {
    "hid-replay", replay_open, replay_read, replay_seek, replay_close, replay_destroy,
};

pose_status pb_hid_replay_create(pb_hid_recording *rec, const char *origin, const pb_hid_replay_options *opt,
                                 pb_source **out, pb_error *err)
{
    *out = NULL;
    replay *r = calloc(1, sizeof *r);
    if (!r) {
        pb_hid_recording_free(rec);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", origin);
    }
    r->base.ops = &replay_ops;
    r->rec = rec;
    snprintf(r->base.origin, sizeof r->base.origin, "%s", origin ? origin : "hid recording");
    if (opt)
        r->opt = *opt;
    if (!(r->opt.speed > 0))
        r->opt.speed = 1.0;
    r->rng = 12345u;
    if (r->opt.device >= rec->device_count) {
        pose_status st = pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no device %u (the file has %zu)", r->base.origin,
                                 r->opt.device, rec->device_count);
        replay_destroy(&r->base);
        return st;
    }
    const pb_hid_rec_device *d = &rec->devices[r->opt.device];
    r->base.info = *d;
    r->base.info.desc = NULL;
    r->base.info.desc_len = 0;
    r->events = malloc((d->event_count ? d->event_count : 1) * sizeof *r->events);
    r->faults = malloc((r->opt.fault_count ? r->opt.fault_count : 1) * sizeof *r->faults);
    r->fired = calloc(r->opt.fault_count ? r->opt.fault_count : 1, 1);
    if (!r->events || !r->faults || !r->fired) {
        replay_destroy(&r->base);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", origin);
    }
    if (r->opt.fault_count)
        memcpy(r->faults, opt->faults, r->opt.fault_count * sizeof *r->faults);
    r->opt.faults = NULL;
    for (size_t i = 0; i < rec->event_count; i++)
        if (rec->events[i].device == r->opt.device)
            r->events[r->count++] = (uint32_t)i;
    if (r->opt.absent_ms > 0)
        r->gone_until = pb_now_ns() + (int64_t)r->opt.absent_ms * 1000000;
    return pb_hid_source_create(&r->base, &r->opt.source, out, err);
}

pose_status pb_hid_replay_open(const char *path, const pb_hid_replay_options *opt, pb_source **out, pb_error *err)
{
    pb_hid_recording *rec;
    *out = NULL;
    pose_status st = pb_hid_recording_load(path, &rec, err);
    if (st != POSE_OK)
        return st;
    return pb_hid_replay_create(rec, path, opt, out, err);
}
