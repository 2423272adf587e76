/* SPDX-License-Identifier: Apache-2.0
 * CAN input benchmarks:
 *   1. decode + map time per frame: the reference rig's log (data/can-rig)
 *      preloaded, fed through the bus decoder and the full-body mapping;
 *   2. sustained replay: a 16-node rig (the rig's 12 DBC goniometers and 4
 *      CiA 406 encoders) at 1 kHz per node for 60 s of recorded time,
 *      written as a candump -l log and replayed through the replay source
 *      and the mapping as fast as possible, counting every frame; then two
 *      seconds of it at recorded timing, measuring how late frames come.
 * usage: bench_can [--repo DIR] [--seconds S] [--paced S]
 *   DIR: the repository root; S: recorded seconds of the 16-node log (60);
 *   --paced: seconds of it replayed at recorded timing (default 2; 60 for the whole log)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "can_source.h"
#include "candump_log.h"
#include "mapping.h"
#include "rig_skel.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static pb_rig_skel *body_skel(void)
{
    pb_rig_skel *s = NULL;
    pb_error err;
    if (pb_rig_skel_schematic_body(&s, &err) != POSE_OK) {
        fprintf(stderr, "bench_can: %s\n", err.message);
        exit(1);
    }
    return s;
}

static void die(const char *what, const pb_error *err)
{
    fprintf(stderr, "bench_can: %s: %s\n", what, err ? err->message : "");
    exit(1);
}

/* Put raw bits of a DBC signal into a frame (the inverse of the decoder). */
static void put_signal(const pb_dbc_signal *s, uint8_t *data, int64_t raw)
{
    const uint64_t v = (uint64_t)raw & (s->length >= 64 ? ~0ull : ((1ull << s->length) - 1));
    for (unsigned i = 0; i < s->length; i++) {
        unsigned lin;
        int bit;
        if (s->intel) {
            lin = s->linear_start + i;
            bit = (int)((v >> i) & 1);
        } else {
            lin = s->linear_start + i;
            bit = (int)((v >> (s->length - 1 - i)) & 1);
        }
        const unsigned byte = lin / 8, sh = s->intel ? lin % 8 : 7 - lin % 8;
        if (bit)
            data[byte] |= (uint8_t)(1u << sh);
        else
            data[byte] &= (uint8_t)~(1u << sh);
    }
}

/* 16 nodes x 1 kHz x seconds -> a candump log; returns the frame count. */
static size_t write_rig_log(const char *path, const pb_dbc *dbc, double seconds)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        exit(1);
    }
    static char buf[1 << 16];
    setvbuf(f, buf, _IOFBF, sizeof buf);
    size_t frames = 0;
    const long ms = (long)(seconds * 1000);
    char line[PB_CANDUMP_LINE_MAX];
    for (long k = 0; k < ms; k++) {
        for (int n = 0; n < 16; n++) {
            pb_can_frame fr;
            memset(&fr, 0, sizeof fr);
            fr.t_ns = 1763769600000000000LL + (int64_t)k * 1000000 + n * 50000;
            const double deg = 60.0 * sin(3.14159265358979323846 * (k * 1e-3) + n);
            if (n < 12) {
                const pb_dbc_message *m = &dbc->messages[n];
                fr.id = m->id;
                fr.len = 8;
                const pb_dbc_signal *s = &m->signals[0];
                if (s->value_type == PB_DBC_FLOAT32) {
                    float x = (float)deg;
                    uint32_t bits;
                    memcpy(&bits, &x, 4);
                    put_signal(s, fr.data, bits);
                } else {
                    put_signal(s, fr.data, llround((deg - s->offset) / s->factor));
                }
            } else {
                fr.id = 0x180 + 33 + (n - 12);
                fr.len = 4;
                const uint32_t pos = (uint32_t)((long)llround(deg / 360.0 * 4096) & 4095);
                memcpy(fr.data, &pos, 4); /* little-endian host, as CANopen */
            }
            int len = pb_candump_format(&fr, "can0", line, sizeof line);
            fwrite(line, 1, (size_t)len, f);
            frames++;
        }
        if (k % 100 == 0) { /* heartbeats of the 4 encoders, 100 ms */
            for (int e = 0; e < 4; e++) {
                pb_can_frame hb = {.t_ns = 1763769600000000000LL + (int64_t)k * 1000000 + 900000,
                                   .id = 0x700u + 33 + (unsigned)e, .len = 1, .data = {5}};
                int len = pb_candump_format(&hb, "can0", line, sizeof line);
                fwrite(line, 1, (size_t)len, f);
                frames++;
            }
        }
    }
    fclose(f);
    return frames;
}

int main(int argc, char **argv)
{
    const char *repo = ".";
    double seconds = 60, paced = 2;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--repo") == 0 && i + 1 < argc)
            repo = argv[++i];
        else if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc)
            seconds = atof(argv[++i]);
        else if (strcmp(argv[i], "--paced") == 0 && i + 1 < argc)
            paced = atof(argv[++i]);
        else {
            fprintf(stderr, "usage: bench_can [--repo DIR] [--seconds S] [--paced S]\n");
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }
    char map_path[1024], log_path[1024];
    snprintf(map_path, sizeof map_path, "%s/bridge/maps/can_rig_fullbody.json", repo);
    snprintf(log_path, sizeof log_path, "%s/data/can-rig/sit_stand_arm_raise.log", repo);
    pb_error err;
    pb_can_bus *bus = NULL;
    pb_mapping *map = NULL;
    if (pb_can_bus_load(map_path, &bus, &err) != POSE_OK)
        die(map_path, &err);
    if (pb_mapping_load(map_path, &map, &err) != POSE_OK)
        die(map_path, &err);
    pb_rig_skel *skel = body_skel();

    /* ---- 1. decode + map per frame ---- */
    pb_candump_reader r;
    char e[256];
    if (pb_candump_open(&r, log_path, e, sizeof e) != 0) {
        fprintf(stderr, "bench_can: %s\n", e);
        return 1;
    }
    size_t cap = 40000, n = 0;
    pb_can_frame *frames = malloc(cap * sizeof *frames);
    while (n < cap && pb_candump_next(&r, &frames[n]) == 1)
        n++;
    pb_candump_close(&r);
    pb_can_decoder *dec = NULL;
    pb_chanmap *cm = NULL;
    if (pb_can_decoder_create(pb_can_bus_config(bus), &dec, &err) != POSE_OK)
        die("decoder", &err);
    size_t nch;
    const pb_channel *ch = pb_can_decoder_channels(dec, &nch);
    if (pb_chanmap_create(map, ch, nch, skel, &cm, &err) != POSE_OK)
        die("mapping", &err);
    pb_update u;
    const int passes = 30;
    double t0 = now_s();
    size_t values = 0;
    for (int p = 0; p < passes; p++) {
        pb_can_decoder_reset(dec);
        for (size_t i = 0; i < n; i++) {
            pb_can_frame f = frames[i];
            f.t_ns += (int64_t)p * 20000000000LL; /* keep time moving forward across passes */
            values += pb_can_decoder_feed(dec, &f, &u);
            pb_chanmap_update(cm, &u);
        }
    }
    double dt = now_s() - t0;
    const double per_frame_us = dt / ((double)n * passes) * 1e6;
    t0 = now_s();
    for (int p = 0; p < passes; p++) {
        pb_can_decoder_reset(dec);
        for (size_t i = 0; i < n; i++) {
            pb_can_frame f = frames[i];
            f.t_ns += (int64_t)p * 20000000000LL;
            pb_can_decoder_feed(dec, &f, &u);
        }
    }
    const double decode_us = (now_s() - t0) / ((double)n * passes) * 1e6;
    printf("decode+map: %zu frames x %d passes of the reference rig log, %.3f us/frame "
           "(decode alone %.3f us/frame), %.2f channel values/frame; target < 5 us\n",
           n, passes, per_frame_us, decode_us, (double)values / ((double)n * passes));
    pb_chanmap_free(cm);
    pb_can_decoder_free(dec);
    free(frames);

    /* ---- 2. sustained replay, 16 nodes at 1 kHz ---- */
    char tmp_log[1024];
    const char *tmpdir = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    snprintf(tmp_log, sizeof tmp_log, "%s/bench_can_16x1k_%ld.log", tmpdir, (long)getpid());
    t0 = now_s();
    const size_t written = write_rig_log(tmp_log, pb_can_bus_dbc(bus), seconds);
    fprintf(stderr, "bench_can: wrote %zu frames (%.0f s of 16 nodes at 1 kHz) in %.2f s\n", written,
            seconds, now_s() - t0);
    for (int pass = 0; pass < 2; pass++) {
        pb_can_bus *b2 = NULL;
        if (pb_can_bus_load(map_path, &b2, &err) != POSE_OK)
            die(map_path, &err);
        pb_source *src = NULL;
        pb_candump_replay_options opt = {.as_fast_as_possible = pass == 0};
        if (pb_candump_replay_open(tmp_log, b2, &opt, &src, &err) != POSE_OK)
            die(tmp_log, &err);
        if (pb_chanmap_create(map, src->channels, src->channel_count, skel, &cm, &err) != POSE_OK)
            die("mapping", &err);
        size_t updates = 0;
        double late_max = 0, late_sum = 0;
        static double lates[1 << 20];
        size_t nlate = 0;
        const double start = now_s();
        const double limit = pass == 0 ? 1e9 : paced; /* recorded timing: `paced` seconds of it */
        int rc;
        while ((rc = src->ops->read(src, &u, 100)) >= 0) {
            if (rc == 0)
                continue;
            pb_chanmap_update(cm, &u);
            updates++;
            if (pass == 1) {
                const double late = (now_s() - start) - u.t_ns * 1e-9;
                late_sum += late;
                late_max = late > late_max ? late : late_max;
                if (nlate < sizeof lates / sizeof lates[0])
                    lates[nlate++] = late;
                if (limit < seconds && u.t_ns * 1e-9 >= limit - 0.0005)
                    break; /* the first `limit` seconds' frames: 16 per ms */
            }
        }
        const double wall = now_s() - start;
        const pb_can_stats *st = pb_can_decoder_stats(pb_can_source_decoder(src));
        if (pass == 0) {
            const size_t expected = (size_t)(seconds * 1000) * 16;
            printf("sustained replay: %zu frames (%.0f s recorded, 16 nodes x 1 kHz + heartbeats) in %.2f s "
                   "wall = %.0f frames/s, %.1fx real time; updates %zu of %zu expected, dropped %llu, "
                   "malformed %llu, short %llu -> %s\n",
                   (size_t)st->frames, seconds, wall, st->frames / wall, seconds / wall, updates, expected,
                   (unsigned long long)st->dropped, (unsigned long long)st->bad_lines,
                   (unsigned long long)st->short_frames,
                   updates == expected && st->frames == written && !st->dropped ? "nothing dropped" : "LOST FRAMES");
        } else {
            qsort(lates, nlate, sizeof lates[0], cmp_double);
            /* what this machine's scheduler allows: how late a 200 us sleep wakes */
            double sleep_late[200];
            for (int i = 0; i < 200; i++) {
                const double a = now_s();
                const struct timespec ts = {0, 200000};
                nanosleep(&ts, NULL);
                sleep_late[i] = now_s() - a - 200e-6;
            }
            qsort(sleep_late, 200, sizeof sleep_late[0], cmp_double);
            printf("recorded-timing replay: %zu updates (%zu expected) over %.2f s, lateness mean %.1f us, median %.1f us, "
                   "p99 %.1f us, max %.1f us (target < 1 ms); a 200 us nanosleep here wakes late by "
                   "median %.1f us, max %.1f us\n",
                   updates, (size_t)((paced < seconds ? paced : seconds) * 1000) * 16, wall, late_sum / (double)(updates ? updates : 1) * 1e6,
                   lates[nlate / 2] * 1e6,
                   lates[nlate * 99 / 100] * 1e6, late_max * 1e6, sleep_late[100] * 1e6, sleep_late[199] * 1e6);
        }
        pb_chanmap_free(cm);
        pb_source_destroy(src);
    }
    remove(tmp_log);
    pb_mapping_free(map);
    pb_rig_skel_free(skel);
    pb_can_bus_free(bus);
    return 0;
}
