/* SPDX-License-Identifier: Apache-2.0
 *
 * A candump -l log replayed as a simulated bus: frames go through the same
 * decoder as the live source, at recorded timing (scaled by speed) or as
 * fast as possible. Update times count from the log's first frame, and keep
 * counting across loops so consumers see a clock that only moves forward.
 */
#include "can_source.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "candump_log.h"
#include "pb_warn.h"
#include "timeline.h"

typedef struct can_replay {
    pb_can_source_core core;
    pb_candump_reader reader;
    pb_candump_replay_options opt;
    pb_can_frame pending;
    int have_pending;
    int64_t first_ns;     /* recorded stamp of the log's first frame, INT64_MIN before */
    int64_t last_rel_ns;  /* relative time of the latest frame handed on */
    int64_t loop_base_ns; /* added to relative times after each loop */
    int64_t start_mono;   /* wall clock at which relative time start_rel was due */
    int64_t start_rel;
    size_t bad_seen;
    pb_timeline timeline; /* jumps in the log's stamps taken out */
} can_replay;

static void sleep_ns(int64_t ns)
{
    if (ns <= 0)
        return;
    struct timespec ts = {(time_t)(ns / 1000000000), (long)(ns % 1000000000)};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
        ;
}

/* Next frame of the log into pending; 0 at its end. */
static int fetch(can_replay *s)
{
    int r = pb_candump_next(&s->reader, &s->pending);
    if (s->reader.bad_lines != s->bad_seen) {
        pb_can_decoder_add_bad_lines(s->core.dec, s->reader.bad_lines - s->bad_seen, s->reader.last_error);
        s->bad_seen = s->reader.bad_lines;
        pb_can_source_core_report(&s->core);
    }
    if (r != 1)
        return 0;
    if (s->first_ns == INT64_MIN) {
        s->first_ns = s->pending.t_ns;
        pb_timeline_init(&s->timeline, 0);
    }
    int64_t jump;
    const int64_t t = pb_timeline_map(&s->timeline, s->pending.t_ns - s->first_ns, &jump);
    if (jump)
        pb_warn("%s:%zu: time stamp %s %.3f s: replayed one step after the frame before", s->reader.path,
                s->reader.line, jump > 0 ? "jumps ahead" : "goes back", (double)(jump > 0 ? jump : -jump) * 1e-9);
    s->pending.t_ns = t + s->loop_base_ns;
    s->have_pending = 1;
    return 1;
}

static int replay_read(pb_source *src, pb_update *out, int timeout_ms)
{
    can_replay *s = (can_replay *)src;
    const int64_t deadline = timeout_ms < 0 ? INT64_MAX : pb_can_mono_ns() + (int64_t)timeout_ms * 1000000;
    const double speed = s->opt.speed > 0 ? s->opt.speed : 1.0;
    for (;;) {
        if (!s->have_pending && !fetch(s)) {
            if (s->opt.loop && s->reader.frames > 0) {
                /* Start over one mean frame period after the last frame. */
                const int64_t span = s->last_rel_ns - s->loop_base_ns;
                const int64_t gap = s->reader.frames > 1 ? span / (int64_t)(s->reader.frames - 1) : 1000000;
                s->loop_base_ns = s->last_rel_ns + (gap > 0 ? gap : 1);
                s->first_ns = INT64_MIN;
                if (pb_candump_rewind(&s->reader) != 0 || !fetch(s)) {
                    pb_source_set_state(src, PB_SOURCE_FAULT, "%s: cannot loop", s->reader.path);
                    return -1;
                }
                s->bad_seen = 0;
                pb_can_decoder_reset(s->core.dec);
            } else {
                const pb_can_stats *st = pb_can_decoder_stats(s->core.dec);
                if (src->state != PB_SOURCE_ENDED)
                    pb_source_set_state(src, PB_SOURCE_ENDED, "%s: end after %zu frames, %llu malformed lines",
                                        s->reader.path, s->reader.frames,
                                        (unsigned long long)st->bad_lines);
                return -1;
            }
        }
        if (!s->opt.as_fast_as_possible) {
            if (s->start_mono == INT64_MIN) {
                s->start_mono = pb_can_mono_ns();
                s->start_rel = s->pending.t_ns;
            }
            const int64_t due = s->start_mono + (int64_t)((double)(s->pending.t_ns - s->start_rel) / speed);
            const int64_t now = pb_can_mono_ns();
            /* Frames due within 100 us go now: a sleep that short wakes later
             * than that (timer slack), and bursts of frames microseconds
             * apart would pile up the error. */
            if (due - now > 100000) {
                if (deadline <= now)
                    return 0;
                sleep_ns((due < deadline ? due : deadline) - now);
                if (pb_can_mono_ns() < due)
                    return 0;
            }
        }
        s->have_pending = 0;
        s->last_rel_ns = s->pending.t_ns;
        if (pb_can_source_core_frame(&s->core, &s->pending, out))
            return 1;
        if (!s->opt.as_fast_as_possible && pb_can_mono_ns() >= deadline)
            return 0;
    }
}

static int replay_seek(pb_source *src, int64_t t_ns)
{
    can_replay *s = (can_replay *)src;
    if (pb_candump_rewind(&s->reader) != 0)
        return -1;
    s->first_ns = INT64_MIN;
    s->loop_base_ns = 0;
    s->have_pending = 0;
    s->bad_seen = 0;
    pb_can_decoder_reset(s->core.dec);
    /* Frames before t only move the node monitor: they are replayed through
     * the decoder without being delivered, so held values and node states
     * are what they were at t. */
    pb_update scratch;
    while (fetch(s)) {
        if (s->pending.t_ns >= t_ns)
            break;
        s->have_pending = 0;
        s->last_rel_ns = s->pending.t_ns;
        pb_can_decoder_feed(s->core.dec, &s->pending, &scratch);
    }
    s->start_mono = INT64_MIN;
    pb_can_source_core_report(&s->core);
    return 0;
}

static void replay_close(pb_source *src)
{
    can_replay *s = (can_replay *)src;
    pb_candump_close(&s->reader);
    pb_can_source_core_close(&s->core);
}

static const pb_source_ops replay_ops = {"candump-replay", replay_read, replay_seek, replay_close};

pose_status pb_candump_replay_open(const char *log_path, pb_can_bus *bus,
                                   const pb_candump_replay_options *opt, pb_source **out, pb_error *err)
{
    *out = NULL;
    can_replay *s = calloc(1, sizeof *s);
    if (!s) {
        pb_can_bus_free(bus);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "CAN: out of memory");
    }
    pose_status st = pb_can_source_core_init(&s->core, &replay_ops, bus, err);
    if (st == POSE_OK) {
        char msg[256];
        if (pb_candump_open(&s->reader, log_path, msg, sizeof msg) != 0)
            st = pb_fail(err, POSE_ERR_IO, "%s", msg);
    }
    if (st != POSE_OK) {
        replay_close(&s->core.base);
        free(s);
        return st;
    }
    if (opt)
        s->opt = *opt;
    s->first_ns = INT64_MIN;
    s->start_mono = INT64_MIN;
    *out = &s->core.base;
    return POSE_OK;
}
