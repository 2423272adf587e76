/* SPDX-License-Identifier: Apache-2.0
 * bench_hid: figures for the HID path.
 *   1. decode + map time per 16-axis mannequin report (target < 20 us): the
 *      decoder alone, decoder + channel mapping (calibration, One Euro,
 *      deadband, limits) + joint quaternions, and the whole source read path;
 *   2. sustained replay of 60 s at 1 kHz as fast as possible, checking that
 *      no sample is dropped or reordered (sample counter and timestamps);
 *   3. a short replay at recorded timing: lateness of each report (design
 *      target: replay timing error < 1 ms).
 * Usage: bench_hid [--json] [--realtime-seconds S] [--repo DIR]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hid_mannequin.h"
#include "hid_replay.h"
#include "hid_report.h"
#include "mapping.h"
#include "clock.h"

#ifndef POSE_SOURCE_DIR_DEFAULT
#define POSE_SOURCE_DIR_DEFAULT "."
#endif

static _Noreturn void die(const char *what, const pb_error *err)
{
    fprintf(stderr, "bench_hid: %s: %s\n", what, err ? err->message : "");
    exit(1);
}

static pb_rig_skel *body_skel(void)
{
    pb_rig_skel *s;
    pb_error err;
    if (pb_rig_skel_schematic_body(&s, &err) != POSE_OK)
        die("rig", &err);
    return s;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int main(int argc, char **argv)
{
    int json = 0;
    double rt_seconds = 2.0;
    const char *repo = POSE_SOURCE_DIR_DEFAULT;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--json") == 0)
            json = 1;
        else if (strcmp(argv[i], "--realtime-seconds") == 0 && i + 1 < argc)
            rt_seconds = atof(argv[++i]);
        else if (strcmp(argv[i], "--repo") == 0 && i + 1 < argc)
            repo = argv[++i];
        else {
            fprintf(stderr, "usage: bench_hid [--json] [--realtime-seconds S] [--repo DIR]\n");
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }
    pb_error err;
    pb_hid_recording *rec;
    if (pb_mannequin_recording(PB_MOTION_SIT_TO_STAND, 500, 8, 7, &rec, &err) != POSE_OK)
        die("recording", &err);
    pb_hid_desc *d;
    if (pb_hid_desc_parse(pb_mannequin_descriptor, pb_mannequin_descriptor_len, "mannequin", &d, &err) != POSE_OK)
        die("descriptor", &err);
    char map_path[1024];
    snprintf(map_path, sizeof map_path, "%s/bridge/maps/hid_mannequin_full_body.json", repo);
    pb_mapping *map;
    if (pb_mapping_load(map_path, &map, &err) != POSE_OK)
        die("mapping", &err);
    pb_rig_skel *skel = body_skel();
    pb_chanmap *cm;
    if (pb_chanmap_create(map, d->channels, d->channel_count, skel, &cm, &err) != POSE_OK)
        die("chanmap", &err);
    pb_pose pose;
    pb_pose_init(&pose, skel->joint_count);

    /* 1. Per report: decode; decode + map + pose. Several passes over 4000 reports. */
    int32_t lg[18];
    double val[18];
    uint8_t ok[18];
    uint32_t idx[18];
    double out[18];
    const int passes = 50;
    size_t n = rec->event_count;
    double sink = 0;
    int64_t t0 = pb_now_ns();
    for (int p = 0; p < passes; p++)
        for (size_t i = 0; i < n; i++) {
            uint32_t first, count;
            pb_hid_report_decode(d, rec->data + rec->events[i].offset, rec->events[i].len, lg, val, ok, &first, &count);
            sink += val[0];
        }
    double decode_ns = (double)(pb_now_ns() - t0) / (double)(passes * n);
    t0 = pb_now_ns();
    for (int p = 0; p < passes; p++)
        for (size_t i = 0; i < n; i++) {
            uint32_t first, count;
            const pb_hid_rec_event *e = &rec->events[i];
            pb_hid_report_decode(d, rec->data + e->offset, e->len, lg, val, ok, &first, &count);
            size_t k = 0;
            for (uint32_t c = first; c < first + count; c++)
                if (ok[c]) {
                    idx[k] = c;
                    out[k++] = val[c];
                }
            pb_update u = {e->t_ns + (int64_t)p * 9000000000LL, k, idx, out};
            pb_chanmap_update(cm, &u);
            pb_chanmap_pose(cm, &pose);
            sink += pose.q[17][1];
        }
    double map_ns = (double)(pb_now_ns() - t0) / (double)(passes * n);

    /* Whole source path (replay transport + state machine + decoder + map), as fast as possible. */
    pb_hid_recording *rec60;
    if (pb_mannequin_recording(PB_MOTION_ARM_RAISE, 1000, 60, 11, &rec60, &err) != POSE_OK)
        die("recording", &err);
    size_t expected = rec60->event_count;
    /* hid-recorder text of those 60 s: write it, read it back. */
    char tmp_path[] = "/tmp/bench_hid_XXXXXX";
    int fd = mkstemp(tmp_path);
    FILE *tf = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!tf)
        die("temporary file", NULL);
    t0 = pb_now_ns();
    int werr = pb_hid_recorder_write_device(tf, -1, &rec60->devices[0]);
    for (size_t i = 0; !werr && i < rec60->event_count; i++)
        werr = pb_hid_recorder_write_event(tf, rec60->events[i].t_ns, rec60->data + rec60->events[i].offset,
                                           rec60->events[i].len);
    if (fclose(tf) != 0 || werr)
        die("writing the recording", NULL);
    double write_s = (double)(pb_now_ns() - t0) * 1e-9;
    pb_hid_recording *back;
    t0 = pb_now_ns();
    if (pb_hid_recording_load(tmp_path, &back, &err) != POSE_OK)
        die("reading the recording", &err);
    double read_s = (double)(pb_now_ns() - t0) * 1e-9;
    FILE *sz = fopen(tmp_path, "rb");
    double mb = 0;
    if (sz) {
        fseek(sz, 0, SEEK_END);
        mb = (double)ftell(sz) / 1e6;
        fclose(sz);
    }
    remove(tmp_path);
    if (back->event_count != expected)
        die("read back a different number of events", NULL);
    pb_hid_recording_free(back);
    pb_hid_replay_options fast = {.as_fast_as_possible = 1};
    pb_source *src;
    if (pb_hid_replay_create(rec60, "60 s at 1 kHz", &fast, &src, &err) != POSE_OK)
        die("replay", &err);
    pb_update u;
    size_t got = 0, dropped = 0, reordered = 0;
    int64_t last_t = -1;
    long last_seq = -1;
    t0 = pb_now_ns();
    while (pb_source_read(src, &u, 100) == 1) {
        long seq = (long)u.values[17];
        if (last_seq >= 0 && seq != ((last_seq + 1) & 0xFFFF)) {
            if (((seq - last_seq) & 0xFFFF) < 0x8000)
                dropped += (size_t)(((seq - last_seq) & 0xFFFF) - 1);
            else
                reordered++;
        }
        if (u.t_ns <= last_t)
            reordered++;
        last_seq = seq;
        last_t = u.t_ns;
        pb_chanmap_update(cm, &u);
        pb_chanmap_pose(cm, &pose);
        got++;
    }
    double replay_s = (double)(pb_now_ns() - t0) * 1e-9;
    pb_source_destroy(src);

    /* 3. Recorded timing: lateness of each report against its schedule. */
    size_t rt_n = 0;
    double *late = NULL;
    if (rt_seconds > 0) {
        pb_hid_recording *rt;
        if (pb_mannequin_recording(PB_MOTION_REACH, 1000, rt_seconds, 5, &rt, &err) != POSE_OK)
            die("recording", &err);
        late = malloc(rt->event_count * sizeof *late);
        pb_source *rs;
        if (!late || pb_hid_replay_create(rt, "realtime", NULL, &rs, &err) != POSE_OK)
            die("replay", &err);
        /* A replay never delivers before a report's due time, so the smallest
         * (arrival - recorded time) marks the schedule; lateness is measured from it. */
        double earliest = 1e300;
        while (pb_source_read(rs, &u, 100) == 1) {
            late[rt_n] = (double)(pb_now_ns() - u.t_ns) * 1e-3; /* us */
            earliest = late[rt_n] < earliest ? late[rt_n] : earliest;
            rt_n++;
        }
        for (size_t i = 0; i < rt_n; i++)
            late[i] -= earliest;
        pb_source_destroy(rs);
        qsort(late, rt_n, sizeof *late, cmp_double);
    }
    double p50 = rt_n ? late[rt_n / 2] : 0, p99 = rt_n ? late[rt_n * 99 / 100] : 0, mx = rt_n ? late[rt_n - 1] : 0;

    if (json) {
        printf("{\"recording_mb\":%.2f,\"write_mb_s\":%.1f,\"read_mb_s\":%.1f,", mb, mb / write_s, mb / read_s);
        printf("\"decode_ns_per_report\":%.1f,\"decode_map_ns_per_report\":%.1f,\"replay_reports\":%zu,"
               "\"replay_expected\":%zu,\"replay_seconds\":%.3f,\"replay_reports_per_s\":%.0f,"
               "\"dropped\":%zu,\"reordered\":%zu,\"realtime_reports\":%zu,\"lateness_us_p50\":%.1f,"
               "\"lateness_us_p99\":%.1f,\"lateness_us_max\":%.1f}\n",
               decode_ns, map_ns, got, expected, replay_s, (double)got / replay_s, dropped, reordered, rt_n, p50, p99,
               mx);
    } else {
        printf("16-axis mannequin report (28 bytes, 18 channels, 16 mapped joint DOFs):\n");
        printf("  decode only                         %8.1f ns/report\n", decode_ns);
        printf("  decode + map + joint quaternions    %8.1f ns/report   (target < 20000 ns)\n", map_ns);
        printf("hid-recorder text, 60 s at 1 kHz (%.2f MB): write %.1f MB/s, read %.1f MB/s\n", mb, mb / write_s,
               mb / read_s);
        printf("sustained replay, 60 s at 1 kHz, as fast as possible (source + decode + map):\n");
        printf("  %zu / %zu reports in %.3f s = %.0f reports/s (%.0fx real time), dropped %zu, reordered %zu\n", got,
               expected, replay_s, (double)got / replay_s, 60.0 / replay_s, dropped, reordered);
        if (rt_n)
            printf("replay at recorded timing, %.1f s at 1 kHz: lateness p50 %.1f us, p99 %.1f us, max %.1f us "
                   "(target < 1000 us)\n",
                   rt_seconds, p50, p99, mx);
    }
    free(late);
    pb_pose_free(&pose);
    pb_chanmap_free(cm);
    pb_rig_skel_free(skel);
    pb_mapping_free(map);
    pb_hid_desc_free(d);
    pb_hid_recording_free(rec);
    return sink == 12345.678 ? 3 : got == expected && dropped == 0 && reordered == 0 ? 0 : 1;
}
