/* SPDX-License-Identifier: Apache-2.0 */
#include "hid_source.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hid_report.h"
#include "pb_warn.h"
#include "clock.h"

typedef struct hid_source {
    pb_source base; /* first: a pb_source * is a hid_source * */
    pb_hid_transport *t;
    pb_hid_source_options opt;
    pb_hid_desc *desc;
    uint8_t desc_bytes[PB_HID_MAX_DESC_BYTES];
    size_t desc_len;
    uint8_t reopen_desc[PB_HID_MAX_DESC_BYTES]; /* compared with desc_bytes on reopen */
    int open;
    int64_t last_rx_ns;     /* monotonic time of the last report, good or not (silence is measured from it) */
    int64_t next_reopen_ns;
    pb_hid_decode_result last_fault;
    int long_warned; /* a report longer than its descriptor says was reported (once) */
    int32_t *logical;
    double *values;
    uint8_t *valid;
    uint32_t *out_channels; /* the update handed out by read */
    double *out_values;
    uint8_t report[PB_HID_MAX_REPORT_BYTES + 1];
    size_t report_len;
    pb_hid_source_stats stats;
    long hold;              /* hold-pose channel, -1 for none */
    FILE *record;
    int64_t record_t0;
} hid_source;

void pb_hid_sleep_until(int64_t t_ns)
{
    struct timespec ts = {(time_t)(t_ns / 1000000000), (long)(t_ns % 1000000000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
    }
}

static int hid_read(pb_source *src, pb_update *out, int timeout_ms);
static int hid_seek(pb_source *src, int64_t t_ns);
static void hid_close(pb_source *src);

static const pb_source_ops hid_ops = {"hid", hid_read, hid_seek, hid_close};
static const pb_source_ops hid_replay_ops = {"hid-replay", hid_read, hid_seek, hid_close};

int pb_source_is_hid(const pb_source *src)
{
    return src && (src->ops == &hid_ops || src->ops == &hid_replay_ops);
}

static int reopen(hid_source *s)
{
    size_t len = 0;
    pb_error err;
    if (s->t->ops->open(s->t, s->reopen_desc, sizeof s->reopen_desc, &len, &err) != POSE_OK) {
        if (s->base.state != PB_SOURCE_DISCONNECTED || strcmp(s->base.message, err.message) != 0)
            pb_source_set_state(&s->base, PB_SOURCE_DISCONNECTED, "%s", err.message);
        return -1;
    }
    if (len != s->desc_len || memcmp(s->reopen_desc, s->desc_bytes, len) != 0) {
        /* Another device or firmware behind the same match: its reports would decode wrongly. */
        s->t->ops->close(s->t);
        pb_source_set_state(&s->base, PB_SOURCE_FAULT, "%s: came back with a different report descriptor",
                            s->t->origin);
        return -1;
    }
    s->open = 1;
    return 0;
}

pose_status pb_hid_source_create(pb_hid_transport *t, const pb_hid_source_options *opt, pb_source **out,
                                 pb_error *err)
{
    *out = NULL;
    hid_source *s = calloc(1, sizeof *s);
    if (!s) {
        t->ops->destroy(t);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "HID source: out of memory");
    }
    s->t = t;
    s->base.ops = strcmp(t->ops->kind, "hid-replay") == 0 ? &hid_replay_ops : &hid_ops;
    if (opt)
        s->opt = *opt;
    if (s->opt.stale_ms <= 0)
        s->opt.stale_ms = 500;
    if (s->opt.reopen_ms <= 0)
        s->opt.reopen_ms = 1000;
    size_t len = 0;
    pb_error absent;
    pose_status st = t->ops->open(t, s->desc_bytes, sizeof s->desc_bytes, &len, &absent);
    int waiting_for_device = 0;
    if (st == POSE_OK) {
        s->open = 1;
    } else if (st == POSE_ERR_NOT_FOUND && s->opt.expected_desc && s->opt.expected_desc_len <= sizeof s->desc_bytes) {
        /* Not plugged in yet: take the channels from the descriptor it will have. */
        len = s->opt.expected_desc_len;
        memcpy(s->desc_bytes, s->opt.expected_desc, len);
        waiting_for_device = 1;
        st = POSE_OK;
    } else if (err) {
        *err = absent;
    }
    s->opt.expected_desc = NULL; /* not kept: the caller's buffers may go away */
    const char *hold_name = s->opt.hold_channel;
    s->opt.hold_channel = NULL;
    s->hold = -1;
    if (st == POSE_OK) {
        s->desc_len = len;
        st = pb_hid_desc_parse(s->desc_bytes, len, t->origin, &s->desc, err);
    }
    if (st == POSE_OK) {
        size_t n = s->desc->channel_count ? s->desc->channel_count : 1;
        s->logical = calloc(n, sizeof *s->logical);
        s->values = malloc(n * sizeof *s->values);
        s->valid = calloc(n, 1);
        s->out_channels = calloc(n, sizeof *s->out_channels);
        s->out_values = calloc(n, sizeof *s->out_values);
        s->base.channels = malloc(n * sizeof *s->base.channels);
        if (!s->logical || !s->values || !s->valid || !s->out_channels || !s->out_values || !s->base.channels)
            st = pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", t->origin);
    }
    if (st != POSE_OK) {
        hid_close(&s->base);
        free(s);
        return st;
    }
    memcpy(s->base.channels, s->desc->channels, s->desc->channel_count * sizeof *s->base.channels);
    s->base.channel_count = s->desc->channel_count;
    if (hold_name) {
        s->hold = pb_source_find_channel(&s->base, hold_name);
        if (s->hold < 0) {
            pose_status bad = pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no channel '%s' to hold the pose with",
                                      t->origin, hold_name);
            hid_close(&s->base);
            free(s);
            return bad;
        }
    }
    for (size_t i = 0; i < s->desc->channel_count; i++)
        s->values[i] = NAN;
    s->base.state = waiting_for_device ? PB_SOURCE_DISCONNECTED : PB_SOURCE_WAITING;
    if (waiting_for_device)
        snprintf(s->base.message, sizeof s->base.message, "%.200s", absent.message);
    else
        snprintf(s->base.message, sizeof s->base.message, "%s: open, no report yet", t->origin);
    s->last_rx_ns = s->next_reopen_ns = pb_now_ns();
    *out = &s->base;
    return POSE_OK;
}

static void record_report(hid_source *s, int64_t t_ns)
{
    if (!s->record)
        return;
    if (s->record_t0 < 0)
        s->record_t0 = t_ns;
    /* Flushed per report so a crash loses at most the last one. */
    if (pb_hid_recorder_write_event(s->record, t_ns - s->record_t0, s->report, s->report_len) != 0 ||
        fflush(s->record) != 0)
        s->record = NULL; /* disk full or closed: stop recording, keep the pose running */
}

static void fault(hid_source *s, pb_hid_decode_result r)
{
    if (r == PB_HID_DECODE_UNKNOWN_ID)
        s->stats.unknown_ids++;
    else
        s->stats.bad_reports++;
    /* One callback per kind of fault, not one per bad report at 1 kHz. */
    if (s->base.state == PB_SOURCE_FAULT && s->last_fault == r)
        return;
    s->last_fault = r;
    if (r == PB_HID_DECODE_UNKNOWN_ID)
        pb_source_set_state(&s->base, PB_SOURCE_FAULT, "%s: report ID %u is not in the descriptor",
                            s->t->origin, s->report[0]);
    else
        pb_source_set_state(&s->base, PB_SOURCE_FAULT, "%s: %s (%zu bytes, expected %zu)", s->t->origin,
                            pb_hid_decode_result_string(r), s->report_len,
                            pb_hid_desc_input_length(s->desc, s->desc->uses_report_ids && s->report_len ? s->report[0] : 0));
}

static int deliver(hid_source *s, pb_update *out, int64_t t_ns, uint32_t first, uint32_t count)
{
    size_t n = 0;
    int held = s->hold >= 0 && s->valid[s->hold] && s->values[s->hold] != 0.0;
    for (uint32_t c = first; c < first + count; c++) {
        if (!s->valid[c] || (held && s->base.channels[c].unit[0]))
            continue;
        s->out_channels[n] = c;
        s->out_values[n++] = s->values[c];
    }
    out->t_ns = t_ns;
    out->count = n;
    out->channels = s->out_channels;
    out->values = s->out_values;
    return 1;
}

static int hid_read(pb_source *src, pb_update *out, int timeout_ms)
{
    hid_source *s = (hid_source *)src;
    if (s->base.state == PB_SOURCE_ENDED)
        return -1;
    int64_t start = pb_now_ns();
    int64_t deadline = timeout_ms < 0 ? INT64_MAX : start + (int64_t)timeout_ms * 1000000;
    for (;;) {
        int64_t now = pb_now_ns();
        if (!s->open) {
            if (now >= s->next_reopen_ns) {
                if (reopen(s) == 0) {
                    s->stats.reopens++;
                    s->last_rx_ns = now;
                    pb_source_set_state(&s->base, PB_SOURCE_WAITING, "%s: reopened", s->t->origin);
                    continue;
                }
                s->next_reopen_ns = now + (int64_t)s->opt.reopen_ms * 1000000;
            }
            int64_t until = s->next_reopen_ns < deadline ? s->next_reopen_ns : deadline;
            if (now >= deadline)
                return 0;
            pb_hid_sleep_until(until);
            continue;
        }
        /* Wake in time to flag silence even when the caller waits longer. */
        int64_t wake = deadline;
        int64_t stale_at = s->last_rx_ns + (int64_t)s->opt.stale_ms * 1000000;
        if (s->base.state != PB_SOURCE_STALE && stale_at < wake)
            wake = stale_at;
        int wait_ms = wake == INT64_MAX ? -1 : wake <= now ? 0 : (int)((wake - now + 999999) / 1000000);
        int64_t t_ns = 0;
        int n = s->t->ops->read(s->t, s->report, sizeof s->report, wait_ms, &t_ns);
        now = pb_now_ns();
        if (n == PB_HID_READ_ENDED) {
            pb_source_set_state(&s->base, PB_SOURCE_ENDED, "%s: end of recording", s->t->origin);
            return -1;
        }
        if (n < 0) {
            s->t->ops->close(s->t);
            s->open = 0;
            s->stats.disconnects++;
            s->next_reopen_ns = now; /* first reopen attempt right away, then every reopen_ms */
            pb_source_set_state(&s->base, PB_SOURCE_DISCONNECTED, "%s: device disconnected (read failed)",
                                s->t->origin);
            continue;
        }
        if (n == 0) {
            if (s->base.state != PB_SOURCE_STALE && s->base.state != PB_SOURCE_DISCONNECTED &&
                now - s->last_rx_ns >= (int64_t)s->opt.stale_ms * 1000000)
                pb_source_set_state(&s->base, PB_SOURCE_STALE, "%s: no report for %d ms; holding last values",
                                    s->t->origin, s->opt.stale_ms);
            if (now >= deadline)
                return 0;
            continue;
        }
        s->report_len = (size_t)n;
        s->last_rx_ns = now; /* a device sending bad reports is faulty, not silent */
        record_report(s, t_ns);
        uint32_t first, count;
        pb_hid_decode_result r = pb_hid_report_decode(s->desc, s->report, s->report_len, s->logical, s->values,
                                                      s->valid, &first, &count);
        if (r != PB_HID_DECODE_OK) {
            fault(s, r);
            if (now >= deadline)
                return 0;
            continue;
        }
        s->stats.reports++;
        const size_t declared =
            pb_hid_desc_input_length(s->desc, s->desc->uses_report_ids ? s->report[0] : 0);
        /* Devices pad reports, so the extra bytes are ignored; said once, not at 1 kHz. */
        if (s->report_len > declared && !s->long_warned++)
            pb_warn("%s: report of %zu bytes, its descriptor declares %zu: the extra bytes are ignored (reported "
                    "once)",
                    s->t->origin, s->report_len, declared);
        if (s->base.state != PB_SOURCE_OK)
            pb_source_set_state(&s->base, PB_SOURCE_OK, "%s: receiving", s->t->origin);
        return deliver(s, out, t_ns, first, count);
    }
}

static int hid_seek(pb_source *src, int64_t t_ns)
{
    hid_source *s = (hid_source *)src;
    if (!s->t->ops->seek || !s->open)
        return -1;
    if (s->t->ops->seek(s->t, t_ns) != 0)
        return -1;
    if (s->base.state == PB_SOURCE_ENDED)
        pb_source_set_state(&s->base, PB_SOURCE_WAITING, "%s: seeked", s->t->origin);
    s->last_rx_ns = pb_now_ns();
    return 0;
}

static void hid_close(pb_source *src)
{
    hid_source *s = (hid_source *)src;
    if (s->t) {
        if (s->open)
            s->t->ops->close(s->t);
        s->t->ops->destroy(s->t);
        s->t = NULL;
    }
    s->open = 0;
    pb_hid_desc_free(s->desc);
    s->desc = NULL;
    free(s->logical);
    free(s->values);
    free(s->valid);
    free(s->out_channels);
    free(s->out_values);
    free(s->base.channels);
    s->logical = NULL;
    s->values = NULL;
    s->valid = NULL;
    s->out_channels = NULL;
    s->out_values = NULL;
    s->base.channels = NULL;
    s->base.channel_count = 0;
}

const pb_hid_desc *pb_hid_source_desc(const pb_source *src)
{
    return pb_source_is_hid(src) ? ((const hid_source *)src)->desc : NULL;
}

const uint8_t *pb_hid_source_desc_bytes(const pb_source *src, size_t *len)
{
    const hid_source *s = (const hid_source *)src;
    *len = pb_source_is_hid(src) ? s->desc_len : 0;
    return pb_source_is_hid(src) ? s->desc_bytes : NULL;
}

const double *pb_hid_source_values(const pb_source *src)
{
    return pb_source_is_hid(src) ? ((const hid_source *)src)->values : NULL;
}

const int32_t *pb_hid_source_logical(const pb_source *src)
{
    return pb_source_is_hid(src) ? ((const hid_source *)src)->logical : NULL;
}

const uint8_t *pb_hid_source_last_report(const pb_source *src, size_t *len)
{
    const hid_source *s = (const hid_source *)src;
    *len = pb_source_is_hid(src) ? s->report_len : 0;
    return pb_source_is_hid(src) ? s->report : NULL;
}

pb_hid_source_stats pb_hid_source_get_stats(const pb_source *src)
{
    pb_hid_source_stats z = {0};
    return pb_source_is_hid(src) ? ((const hid_source *)src)->stats : z;
}

const pb_hid_rec_device *pb_hid_source_info(const pb_source *src)
{
    return pb_source_is_hid(src) ? &((const hid_source *)src)->t->info : NULL;
}

int pb_hid_source_record(pb_source *src, FILE *f)
{
    if (!pb_source_is_hid(src))
        return -1;
    hid_source *s = (hid_source *)src;
    s->record = NULL;
    if (!f)
        return 0;
    pb_hid_rec_device dev = s->t->info;
    dev.desc = s->desc_bytes;
    dev.desc_len = s->desc_len;
    if (fprintf(f, "# recorded by pose-bridge from %s\n", s->t->origin) < 0 ||
        pb_hid_recorder_write_device(f, -1, &dev) != 0)
        return -1;
    s->record = f;
    s->record_t0 = -1;
    return 0;
}
