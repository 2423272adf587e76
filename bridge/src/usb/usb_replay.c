/* SPDX-License-Identifier: Apache-2.0
 * The simulated vendor-class device: a usbmon capture's completed IN
 * transfers on the layout's endpoint, replayed through the live path's
 * decoder at the recorded timing (x speed) or as fast as possible. A
 * completion with ENODEV/ESHUTDOWN (or a submission error saying so) is
 * the device leaving; the capture's next transfer on the endpoint, from
 * whatever address the device re-enumerated at, is it coming back. */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pb_warn.h"
#include "timeline.h"
#include "usb_source.h"
#include "usbmon.h"
#include "clock.h"

typedef struct replay {
    pb_usb_transport base;
    pb_usbmon_capture *cap;
    pb_usb_replay_options opt;
    uint32_t *events; /* C and E events of the endpoint, in file order */
    int64_t *times;   /* their replay times (ns): the kernel's wrap undone, jumps taken out */
    size_t count, pos;
    int64_t t0_ns;    /* the first event's time: recorded times start at 0 */
    int64_t base_wall, base_t, loop_offset;
    int started;
    int gone;         /* the capture's device left; it is back at its next transfer's time */
    int dev;          /* the address followed, -1 until the first event */
    int truncated_warned;
} replay;

static const pb_usbmon_event *ev(const replay *r, size_t i)
{
    return &r->cap->events[r->events[i]];
}

static int64_t ev_t(const replay *r, size_t i)
{
    return r->times[i] - r->t0_ns;
}

/* Wall time the event at pos is due (recorded timing). */
static int64_t due_at(const replay *r, size_t pos)
{
    return r->base_wall + (int64_t)((double)(ev_t(r, pos) + r->loop_offset - r->base_t) / r->opt.speed);
}

/* The first completion at or after pos (the device's first transfer when it is back). */
static size_t next_completion(const replay *r)
{
    size_t i = r->pos;
    while (i < r->count && ev(r, i)->event != 'C')
        i++;
    return i;
}

static pose_status replay_open(pb_usb_transport *t, pb_error *err)
{
    replay *r = (replay *)t;
    size_t back = next_completion(r);
    /* Unplugged in the capture: absent until its next transfer (as fast as possible: at once). */
    if (r->gone && !r->opt.as_fast_as_possible && back < r->count && pb_now_ns() < due_at(r, back))
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: device not present (unplugged in the capture)", t->origin);
    r->gone = 0;
    return POSE_OK;
}

/* The simulated hotplug: the device arrives when the capture's next transfer is due. */
static int replay_wait_arrival(pb_usb_transport *t, int timeout_ms)
{
    replay *r = (replay *)t;
    size_t back = next_completion(r);
    if (!r->gone || back >= r->count)
        return 1;
    int64_t until = pb_now_ns() + (int64_t)timeout_ms * 1000000, due = due_at(r, back);
    int64_t wake = due < until ? due : until;
    struct timespec ts = {(time_t)(wake / 1000000000), (long)(wake % 1000000000)};
    while (pb_now_ns() < wake && clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) != 0) {
    }
    return pb_now_ns() >= due;
}

static int replay_read(pb_usb_transport *t, uint8_t *buf, size_t cap, int timeout_ms, pb_usb_completion *c)
{
    replay *r = (replay *)t;
    int64_t now = pb_now_ns();
    int64_t deadline = timeout_ms < 0 ? INT64_MAX : now + (int64_t)timeout_ms * 1000000;
    if (!r->started) {
        r->started = 1;
        r->base_wall = now;
        r->base_t = r->count ? ev_t(r, 0) : 0;
    }
    for (;;) {
        if (r->pos >= r->count) {
            if (!r->opt.loop || r->count == 0)
                return PB_USB_READ_ENDED;
            int64_t span = ev_t(r, r->count - 1) - ev_t(r, 0);
            int64_t gap = r->count > 1 ? span / (int64_t)(r->count - 1) : 1000000;
            r->loop_offset += span + gap;
            r->pos = 0;
        }
        const pb_usbmon_event *e = ev(r, r->pos);
        if (r->dev >= 0 && e->dev != r->dev) {
            r->pos++; /* another device on the same endpoint number */
            continue;
        }
        int64_t t_ns = ev_t(r, r->pos) + r->loop_offset;
        if (!r->opt.as_fast_as_possible) {
            int64_t due = due_at(r, r->pos);
            if (due > deadline) {
                struct timespec ts = {(time_t)(deadline / 1000000000), (long)(deadline % 1000000000)};
                clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
                return 0;
            }
            struct timespec ts = {(time_t)(due / 1000000000), (long)(due % 1000000000)};
            while (pb_now_ns() < due && clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) != 0) {
            }
        }
        r->pos++;
        pb_usb_status st = pb_usb_status_from_errno(e->status);
        if (e->event == 'E') {
            if (st != PB_USB_XFER_NO_DEVICE || r->dev < 0)
                continue; /* refused for another reason, or the unplug a completion already reported */
            r->dev = -1;
            r->gone = 1;
            return PB_USB_READ_GONE;
        }
        c->t_ns = t_ns;
        c->status = st;
        if (st == PB_USB_XFER_NO_DEVICE) {
            r->dev = -1; /* it re-enumerates, perhaps at another address */
            r->gone = 1;
            c->len = 0;
            return 1;
        }
        r->dev = e->dev;
        t->bus = e->bus;
        t->dev = e->dev;
        size_t n = e->captured < e->length ? e->captured : e->length;
        if (e->captured < e->length && !r->truncated_warned++)
            pb_warn("%s:%u: the capture holds %u of the transfer's %u bytes (the kernel's text capture keeps 32; "
                    "record with pose-bridge usb-record to keep every byte): such transfers decode as short "
                    "(reported once)",
                    t->origin, e->line, e->captured, e->length);
        if (n > cap)
            n = cap;
        memcpy(buf, r->cap->data + e->offset, n);
        c->len = n;
        return 1;
    }
}

static int replay_seek(pb_usb_transport *t, int64_t t_ns)
{
    replay *r = (replay *)t;
    size_t lo = 0, hi = r->count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (ev_t(r, mid) < t_ns)
            lo = mid + 1;
        else
            hi = mid;
    }
    r->pos = lo;
    r->gone = 0;
    r->loop_offset = 0;
    r->started = 1;
    r->base_wall = pb_now_ns();
    r->base_t = lo < r->count ? ev_t(r, lo) : t_ns;
    return 0;
}

static void replay_close(pb_usb_transport *t)
{
    (void)t;
}

static void replay_destroy(pb_usb_transport *t)
{
    replay *r = (replay *)t;
    pb_usbmon_capture_free(r->cap);
    free(r->events);
    free(r->times);
    free(r);
}

static const pb_usb_transport_ops replay_ops = {
    "usbmon-replay", replay_open, replay_read, replay_seek, replay_wait_arrival, replay_close, replay_destroy,
};

pose_status pb_usb_replay_create(pb_usbmon_capture *cap, const char *origin, const pb_usb_layout *layout,
                                 const pb_usb_replay_options *opt, pb_source **out, pb_error *err)
{
    *out = NULL;
    replay *r = calloc(1, sizeof *r);
    if (!r) {
        pb_usbmon_capture_free(cap);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", origin);
    }
    r->base.ops = &replay_ops;
    r->cap = cap;
    r->dev = -1;
    snprintf(r->base.origin, sizeof r->base.origin, "%s", origin ? origin : "usbmon capture");
    if (opt)
        r->opt = *opt;
    r->base.hotplug = !r->opt.as_fast_as_possible; /* at recorded timing, the device comes back when it came back */
    if (!(r->opt.speed > 0))
        r->opt.speed = 1.0;
    r->events = malloc((cap->count ? cap->count : 1) * sizeof *r->events);
    r->times = malloc((cap->count ? cap->count : 1) * sizeof *r->times);
    if (!r->events || !r->times) {
        replay_destroy(&r->base);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", origin);
    }
    const char want = layout->bulk ? 'B' : 'I';
    const uint8_t ep = layout->endpoint & 0x0F;
    for (size_t i = 0; i < cap->count; i++) {
        const pb_usbmon_event *e = &cap->events[i];
        if (e->in && e->xfer == want && e->ep == ep && (e->event == 'C' || e->event == 'E'))
            r->events[r->count++] = (uint32_t)i;
    }
    if (r->count == 0) {
        pose_status st = pb_fail(err, POSE_ERR_NOT_FOUND,
                                 "%s: no completed %s IN transfer on endpoint 0x%02x in the capture (%zu events)",
                                 r->base.origin, layout->bulk ? "bulk" : "interrupt", layout->endpoint, cap->count);
        replay_destroy(&r->base);
        return st;
    }
    /* The kernel's text time stamps are (seconds mod 4096) * 10^6 + microseconds: a capture longer than
     * 68 minutes wraps, which is undone; other jumps back, or ahead by more than a minute, are taken out
     * (pb_timeline) with a warning naming the line. */
    const int64_t wrap_us = INT64_C(4096000000);
    int64_t unwrap = 0, prev_us = -1;
    pb_timeline tl;
    pb_timeline_init(&tl, PB_TIMELINE_MAX_GAP_NS);
    for (size_t i = 0; i < r->count; i++) {
        const pb_usbmon_event *e = ev(r, i);
        if (prev_us >= 0 && e->t_us < prev_us && prev_us < wrap_us && prev_us - e->t_us > wrap_us / 2)
            unwrap += wrap_us;
        prev_us = e->t_us;
        int64_t jump = 0;
        r->times[i] = pb_timeline_map(&tl, (e->t_us + unwrap) * 1000, &jump);
        if (jump < 0)
            pb_warn("%s:%u: time stamp %lld us goes back %.6f s; replayed one step after the transfer before",
                    r->base.origin, e->line, (long long)e->t_us, (double)-jump * 1e-9);
        else if (jump > 0)
            pb_warn("%s:%u: time stamp %lld us jumps %.1f s ahead; taken out (replayed one step later)",
                    r->base.origin, e->line, (long long)e->t_us, (double)jump * 1e-9);
    }
    r->t0_ns = r->times[0];
    return pb_usb_source_create(&r->base, layout, &r->opt.source, out, err);
}

pose_status pb_usb_replay_open(const char *path, const pb_usb_layout *layout, const pb_usb_replay_options *opt,
                               pb_source **out, pb_error *err)
{
    pb_usbmon_capture *cap;
    *out = NULL;
    pose_status st = pb_usbmon_load(path, &cap, err);
    if (st != POSE_OK)
        return st;
    return pb_usb_replay_create(cap, path, layout, opt, out, err);
}
