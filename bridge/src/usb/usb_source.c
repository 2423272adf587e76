/* SPDX-License-Identifier: Apache-2.0 */
#include "usb_source.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "usbmon.h"
#include "clock.h"

typedef struct usb_source {
    pb_source base; /* first */
    pb_usb_transport *t;
    pb_usb_source_options opt;
    pb_usb_layout layout;
    pb_usb_decoder dec;
    int open;
    int64_t last_rx_ns, next_reopen_ns;
    uint64_t reopens;
    int retry_open; /* hotplug reported the device, but opening it failed: retry every reopen_ms */
    int last_fault; /* what the FAULT state reports, to call back once per kind */
    long hold;
    uint32_t *out_channels;
    double *out_values;
    uint8_t frame[PB_USB_MAX_FRAME + 64];
    size_t frame_len;
    pb_usb_status frame_status;
    FILE *record;
    int64_t record_t0;
    uint64_t record_tag;
} usb_source;

static int usb_read(pb_source *src, pb_update *out, int timeout_ms);
static int usb_seek(pb_source *src, int64_t t_ns);
static void usb_close(pb_source *src);

static const pb_source_ops usb_ops = {"usb", usb_read, usb_seek, usb_close};
static const pb_source_ops usb_replay_ops = {"usbmon-replay", usb_read, usb_seek, usb_close};

int pb_source_is_usb(const pb_source *src)
{
    return src && (src->ops == &usb_ops || src->ops == &usb_replay_ops);
}

static void sleep_until(int64_t t_ns)
{
    struct timespec ts = {(time_t)(t_ns / 1000000000), (long)(t_ns % 1000000000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
    }
}

pose_status pb_usb_source_create(pb_usb_transport *t, const pb_usb_layout *layout, const pb_usb_source_options *opt,
                                 pb_source **out, pb_error *err)
{
    *out = NULL;
    usb_source *s = calloc(1, sizeof *s);
    if (!s) {
        t->ops->destroy(t);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "USB source: out of memory");
    }
    s->t = t;
    s->base.ops = strcmp(t->ops->kind, "usbmon-replay") == 0 ? &usb_replay_ops : &usb_ops;
    s->layout = *layout;
    t->layout = &s->layout;
    if (opt)
        s->opt = *opt;
    if (s->opt.stale_ms <= 0)
        s->opt.stale_ms = 500;
    if (s->opt.reopen_ms <= 0)
        s->opt.reopen_ms = 1000;
    s->hold = -1;
    pose_status st = pb_usb_layout_check(&s->layout, t->origin, err);
    size_t n = s->layout.channel_count ? s->layout.channel_count : 1;
    if (st == POSE_OK)
        st = pb_usb_decoder_init(&s->dec, &s->layout, err);
    if (st == POSE_OK) {
        s->base.channels = calloc(n, sizeof *s->base.channels);
        s->out_channels = calloc(n, sizeof *s->out_channels);
        s->out_values = calloc(n, sizeof *s->out_values);
        if (!s->base.channels || !s->out_channels || !s->out_values)
            st = pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", t->origin);
    }
    if (st == POSE_OK) {
        pb_usb_layout_channels(&s->layout, s->base.channels);
        s->base.channel_count = s->layout.channel_count;
        const char *hold = s->opt.hold_channel;
        s->opt.hold_channel = NULL;
        if (hold && (s->hold = pb_source_find_channel(&s->base, hold)) < 0)
            st = pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no channel '%s' to hold the pose with", t->origin, hold);
    }
    pb_error absent;
    if (st == POSE_OK) {
        st = t->ops->open(t, &absent);
        if (st == POSE_OK) {
            s->open = 1;
            s->base.state = PB_SOURCE_WAITING;
            snprintf(s->base.message, sizeof s->base.message, "%s: open, no frame yet", t->origin);
        } else if (st == POSE_ERR_NOT_FOUND && !t->ops->seek) {
            /* a live device not plugged in yet: wait for it */
            st = POSE_OK;
            s->base.state = PB_SOURCE_DISCONNECTED;
            snprintf(s->base.message, sizeof s->base.message, "%.200s", absent.message);
        } else if (err) {
            *err = absent;
        }
    }
    if (st != POSE_OK) {
        usb_close(&s->base);
        free(s);
        return st;
    }
    s->last_rx_ns = s->next_reopen_ns = pb_now_ns();
    *out = &s->base;
    return POSE_OK;
}

static void record_frame(usb_source *s, const pb_usb_completion *c)
{
    if (!s->record)
        return;
    if (s->record_t0 < 0)
        s->record_t0 = c->t_ns;
    static const int errnos[] = {0, -EPIPE, -EOVERFLOW, -ENODEV, -EPROTO, -ENOENT};
    pb_usbmon_event e = {
        .t_us = (c->t_ns - s->record_t0) / 1000,
        .event = 'C',
        .xfer = s->layout.bulk ? 'B' : 'I',
        .in = 1,
        .bus = s->t->bus ? s->t->bus : 1,
        .dev = s->t->dev ? s->t->dev : 1,
        .ep = (uint8_t)(s->layout.endpoint & 0x0F),
        .status = errnos[c->status <= PB_USB_XFER_CANCELLED ? c->status : PB_USB_XFER_ERROR],
        .interval = s->layout.bulk ? -1 : 1,
        .length = (uint32_t)c->len,
        .captured = (uint32_t)c->len,
    };
    if (pb_usbmon_write(s->record, ++s->record_tag, &e, s->frame) != 0 || fflush(s->record) != 0)
        s->record = NULL; /* disk full: stop recording, keep posing */
}

static void fault(usb_source *s, int kind, const char *what)
{
    if (s->base.state == PB_SOURCE_FAULT && s->last_fault == kind)
        return; /* one callback per kind of fault, not one per frame at 1 kHz */
    s->last_fault = kind;
    pb_source_set_state(&s->base, PB_SOURCE_FAULT, "%s: %s (%zu bytes, frame %u); holding the last good values",
                        s->t->origin, what, s->frame_len, s->layout.frame_bytes);
}

static int deliver(usb_source *s, pb_update *out, int64_t t_ns)
{
    size_t n = 0;
    int held = s->hold >= 0 && s->dec.values[s->hold] != 0.0;
    for (size_t c = 0; c < s->layout.channel_count; c++) {
        if (held && s->base.channels[c].unit[0])
            continue;
        s->out_channels[n] = (uint32_t)c;
        s->out_values[n++] = s->dec.values[c];
    }
    out->t_ns = t_ns;
    out->count = n;
    out->channels = s->out_channels;
    out->values = s->out_values;
    return 1;
}

static void gone(usb_source *s, int64_t now, const char *why)
{
    s->t->ops->close(s->t);
    s->open = 0;
    pb_usb_decoder_resync(&s->dec); /* a device that comes back starts its counter anew */
    s->next_reopen_ns = now;
    pb_source_set_state(&s->base, PB_SOURCE_DISCONNECTED, "%s: %s; %s", s->t->origin, why,
                        s->t->hotplug ? "waiting for it to come back (hotplug)" : "reopening");
}

static int usb_read(pb_source *src, pb_update *out, int timeout_ms)
{
    usb_source *s = (usb_source *)src;
    if (s->base.state == PB_SOURCE_ENDED)
        return -1;
    int64_t start = pb_now_ns();
    int64_t deadline = timeout_ms < 0 ? INT64_MAX : start + (int64_t)timeout_ms * 1000000;
    for (;;) {
        int64_t now = pb_now_ns();
        if (!s->open) {
            /* With hotplug, wait for the arrival; an open that fails right after it (udev still setting
             * permissions, the device still starting) is retried every reopen_ms until it works. */
            int poll = !s->t->hotplug || s->retry_open, arrived = 0;
            if (s->t->hotplug && s->t->ops->wait_arrival) {
                int64_t until = poll && s->next_reopen_ns < deadline ? s->next_reopen_ns : deadline;
                int64_t w = until == INT64_MAX ? 1000 : (until - now) / 1000000;
                arrived = s->t->ops->wait_arrival(s->t, (int)(w > 1000 ? 1000 : w < 0 ? 0 : w));
                now = pb_now_ns();
            }
            if (arrived || (poll && now >= s->next_reopen_ns)) {
                pb_error e;
                if (s->t->ops->open(s->t, &e) == POSE_OK) {
                    s->open = 1;
                    s->retry_open = 0;
                    s->reopens++;
                    s->last_rx_ns = now;
                    pb_source_set_state(&s->base, PB_SOURCE_WAITING, "%s: reopened%s", s->t->origin,
                                        arrived ? " on hotplug arrival" : "");
                    continue;
                }
                if (strcmp(s->base.message, e.message) != 0)
                    pb_source_set_state(&s->base, PB_SOURCE_DISCONNECTED, "%s", e.message);
                s->next_reopen_ns = now + (int64_t)s->opt.reopen_ms * 1000000;
                if (arrived)
                    s->retry_open = 1;
            }
            if (now >= deadline)
                return 0;
            if (!s->t->hotplug)
                sleep_until(s->next_reopen_ns < deadline ? s->next_reopen_ns : deadline);
            continue;
        }
        int64_t wake = deadline, stale_at = s->last_rx_ns + (int64_t)s->opt.stale_ms * 1000000;
        if (s->base.state != PB_SOURCE_STALE && stale_at < wake)
            wake = stale_at;
        int wait_ms = wake == INT64_MAX ? -1 : wake <= now ? 0 : (int)((wake - now + 999999) / 1000000);
        pb_usb_completion c = {PB_USB_XFER_OK, 0, 0};
        int r = s->t->ops->read(s->t, s->frame, sizeof s->frame, wait_ms, &c);
        now = pb_now_ns();
        if (r == PB_USB_READ_ENDED) {
            pb_source_set_state(&s->base, PB_SOURCE_ENDED, "%s: end of capture", s->t->origin);
            return -1;
        }
        if (r == PB_USB_READ_GONE) {
            pb_usb_decoder_count_status(&s->dec, PB_USB_XFER_NO_DEVICE);
            gone(s, now, "device disconnected");
            continue;
        }
        if (r == 0) {
            if (s->base.state != PB_SOURCE_STALE && s->base.state != PB_SOURCE_DISCONNECTED &&
                now - s->last_rx_ns >= (int64_t)s->opt.stale_ms * 1000000)
                pb_source_set_state(&s->base, PB_SOURCE_STALE, "%s: no frame for %d ms; holding last values",
                                    s->t->origin, s->opt.stale_ms);
            if (now >= deadline)
                return 0;
            continue;
        }
        s->frame_len = c.len;
        s->frame_status = c.status;
        s->last_rx_ns = now;
        record_frame(s, &c);
        if (c.status == PB_USB_XFER_NO_DEVICE) {
            pb_usb_decoder_count_status(&s->dec, PB_USB_XFER_NO_DEVICE);
            gone(s, now, "device unplugged mid-transfer");
            continue;
        }
        if (c.status != PB_USB_XFER_OK) {
            pb_usb_decoder_count_status(&s->dec, c.status);
            if (c.status != PB_USB_XFER_CANCELLED)
                fault(s, 100 + (int)c.status, pb_usb_status_name(c.status));
            if (now >= deadline)
                return 0;
            continue;
        }
        pb_usb_decode_result d = pb_usb_decode(&s->dec, s->frame, c.len, NULL);
        if (d != PB_USB_DECODE_OK) {
            fault(s, (int)d, pb_usb_decode_result_string(d));
            if (now >= deadline)
                return 0;
            continue;
        }
        if (s->base.state != PB_SOURCE_OK)
            pb_source_set_state(&s->base, PB_SOURCE_OK, "%s: receiving", s->t->origin);
        return deliver(s, out, c.t_ns);
    }
}

static int usb_seek(pb_source *src, int64_t t_ns)
{
    usb_source *s = (usb_source *)src;
    if (!s->t->ops->seek || s->t->ops->seek(s->t, t_ns) != 0)
        return -1;
    s->open = 1;
    pb_usb_decoder_resync(&s->dec);
    if (s->base.state == PB_SOURCE_ENDED)
        pb_source_set_state(&s->base, PB_SOURCE_WAITING, "%s: seeked", s->t->origin);
    s->last_rx_ns = pb_now_ns();
    return 0;
}

static void usb_close(pb_source *src)
{
    usb_source *s = (usb_source *)src;
    if (s->t) {
        if (s->open)
            s->t->ops->close(s->t);
        s->t->ops->destroy(s->t);
        s->t = NULL;
    }
    s->open = 0;
    pb_usb_decoder_free(&s->dec);
    free(s->base.channels);
    free(s->out_channels);
    free(s->out_values);
    s->base.channels = NULL;
    s->out_channels = NULL;
    s->out_values = NULL;
    s->base.channel_count = 0;
}

const pb_usb_frame_stats *pb_usb_source_stats(const pb_source *src)
{
    return pb_source_is_usb(src) ? &((const usb_source *)src)->dec.stats : NULL;
}

uint64_t pb_usb_source_drops(const pb_source *src)
{
    const pb_usb_frame_stats *s = pb_usb_source_stats(src);
    return s ? s->lost + s->short_frames + s->long_frames + s->bad_checksums + s->reordered + s->stalls +
                   s->overflows + s->wire_errors
             : 0;
}

uint64_t pb_usb_source_reopens(const pb_source *src)
{
    return pb_source_is_usb(src) ? ((const usb_source *)src)->reopens : 0;
}

const pb_usb_layout *pb_usb_source_layout(const pb_source *src)
{
    return pb_source_is_usb(src) ? &((const usb_source *)src)->layout : NULL;
}

const uint8_t *pb_usb_source_last_frame(const pb_source *src, size_t *len, pb_usb_status *status)
{
    if (!pb_source_is_usb(src)) {
        *len = 0;
        return NULL;
    }
    const usb_source *s = (const usb_source *)src;
    *len = s->frame_len;
    if (status)
        *status = s->frame_status;
    return s->frame;
}

const int64_t *pb_usb_source_raw(const pb_source *src)
{
    return pb_source_is_usb(src) ? ((const usb_source *)src)->dec.raw : NULL;
}

int pb_usb_source_record(pb_source *src, FILE *f)
{
    if (!pb_source_is_usb(src))
        return -1;
    usb_source *s = (usb_source *)src;
    s->record = NULL;
    if (!f)
        return 0;
    if (fprintf(f, "# usbmon text (u format) recorded by pose-bridge usb-record from %s, endpoint 0x%02x, %u-byte "
                   "frames; every byte of each transfer\n",
                s->t->origin, s->layout.endpoint, s->layout.frame_bytes) < 0)
        return -1;
    s->record = f;
    s->record_t0 = -1;
    return 0;
}

/* ------------------------------------------------------------- the spec */

static int hex_part(const char *s, size_t n, unsigned max, unsigned *out)
{
    if (n == 0 || n > 4)
        return -1;
    unsigned v = 0;
    for (size_t i = 0; i < n; i++) {
        char c = s[i];
        int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
        if (d < 0)
            return -1;
        v = v * 16 + (unsigned)d;
    }
    if (v > max)
        return -1;
    *out = v;
    return 0;
}

pose_status pb_usb_parse_spec(const char *spec, pb_usb_layout *l, pb_error *err)
{
    const char *p = strncmp(spec, "usb:", 4) == 0 ? spec + 4 : spec;
    const char *slash = strchr(p, '/');
    const char *end = slash ? slash : p + strlen(p);
    const char *c1 = memchr(p, ':', (size_t)(end - p));
    unsigned vid, pid;
    if (!c1 || hex_part(p, (size_t)(c1 - p), 0xFFFF, &vid) != 0)
        goto bad;
    const char *c2 = memchr(c1 + 1, ':', (size_t)(end - c1 - 1));
    if (hex_part(c1 + 1, (size_t)((c2 ? c2 : end) - c1 - 1), 0xFFFF, &pid) != 0)
        goto bad;
    l->vid = (uint16_t)vid;
    l->pid = (uint16_t)pid;
    if (c2) {
        size_t n = (size_t)(end - c2 - 1);
        if (n == 0 || n >= sizeof l->serial)
            goto bad;
        memcpy(l->serial, c2 + 1, n);
        l->serial[n] = '\0';
    }
    if (slash) {
        char *e1;
        errno = 0;
        long iface = strtol(slash + 1, &e1, 10);
        if (errno || e1 == slash + 1 || *e1 != '/' || iface < 0 || iface > 255)
            goto bad;
        unsigned ep;
        if (hex_part(e1 + 1 + (strncmp(e1 + 1, "0x", 2) == 0 ? 2 : 0), strlen(e1 + 1) - (strncmp(e1 + 1, "0x", 2) == 0 ? 2 : 0), 0xFF, &ep) != 0 ||
            !(ep & 0x80) || (ep & 0x70) || !(ep & 0x0F))
            goto bad;
        l->interface = (int)iface;
        l->endpoint = (uint8_t)ep;
    }
    return POSE_OK;
bad:
    return pb_fail(err, POSE_ERR_INVALID_ARGUMENT,
                   "%s: expected usb:VID:PID[:SERIAL][/INTERFACE/ENDPOINT] (hex ids, decimal interface, IN endpoint "
                   "0x81..0x8f), e.g. usb:1209:0002/0/81",
                   spec);
}
