/* SPDX-License-Identifier: Apache-2.0
 * bench_usb [--json] [--realtime-seconds S] [--repo DIR]
 *
 * The reference USB goniometer box (16 channels + hold, 32-byte frames):
 *  - frame decode (length, CRC-16, counter, 17 fields) + channel mapping
 *    (calibration, One Euro filter, deadband, limits, 16 joint DOFs ->
 *    joint rotations) per transfer: mean, p50, p99 (target < 5 us);
 *  - usbmon text of 60 s at 1 kHz: write and parse speed;
 *  - that capture replayed through the source (replay transport + state
 *    machine + decoder) and mapped, as fast as possible: frames, drops,
 *    reordered (target: all 60000, zero drops);
 *  - at recorded timing for S seconds (default 2; 60 for the whole
 *    capture): frames, drops and lateness against the schedule.
 * Exits 1 when a replay drops or reorders a frame. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mapping.h"
#include "usb_gonio.h"
#include "usb_source.h"
#include "usbmon.h"
#include "clock.h"

#ifndef POSE_SOURCE_DIR_DEFAULT
#define POSE_SOURCE_DIR_DEFAULT "."
#endif

static void die(const char *what, const pb_error *err)
{
    fprintf(stderr, "bench_usb: %s: %s\n", what, err ? err->message : "");
    exit(1);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

typedef struct run {
    size_t frames;
    uint64_t drops, reordered;
    double seconds, late_p50, late_p99, late_max;
} run;

static run replay(const char *path, const pb_usb_layout *l, pb_chanmap *cm, pb_pose *pose, int afap, double seconds)
{
    pb_source *src;
    pb_error err;
    pb_usb_replay_options o = {.as_fast_as_possible = afap, .speed = 1.0, .source = {.hold_channel = "hold"}};
    if (pb_usb_replay_open(path, l, &o, &src, &err) != POSE_OK)
        die("replay", &err);
    run r = {0};
    double *late = afap ? NULL : malloc((size_t)(seconds * 1100 + 16) * sizeof *late);
    double earliest = 1e300;
    int64_t last_t = -1, t0 = pb_now_ns();
    pb_update u;
    for (;;) {
        int k = pb_source_read(src, &u, 200);
        if (k < 0)
            break;
        if (k == 0)
            continue;
        if (u.t_ns <= last_t)
            r.reordered++;
        last_t = u.t_ns;
        if (late) {
            late[r.frames] = (double)(pb_now_ns() - u.t_ns) * 1e-3;
            earliest = late[r.frames] < earliest ? late[r.frames] : earliest;
        }
        pb_chanmap_update(cm, &u);
        pb_chanmap_pose(cm, pose);
        r.frames++;
        if (!afap && (double)u.t_ns * 1e-9 >= seconds)
            break;
    }
    r.seconds = (double)(pb_now_ns() - t0) * 1e-9;
    r.drops = pb_usb_source_drops(src);
    pb_source_destroy(src);
    if (late && r.frames) {
        for (size_t i = 0; i < r.frames; i++)
            late[i] -= earliest; /* a replay never delivers early: the smallest offset is the schedule */
        qsort(late, r.frames, sizeof *late, cmp_double);
        r.late_p50 = late[r.frames / 2];
        r.late_p99 = late[r.frames * 99 / 100];
        r.late_max = late[r.frames - 1];
    }
    free(late);
    return r;
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
            fprintf(stderr, "usage: bench_usb [--json] [--realtime-seconds S] [--repo DIR]\n");
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }
    pb_error err;
    char map_path[1024];
    snprintf(map_path, sizeof map_path, "%s/bridge/maps/usb_gonio_full_body.json", repo);
    static pb_usb_layout layout;
    pb_mapping *map;
    if (pb_usb_layout_load(map_path, &layout, &err) != POSE_OK || pb_mapping_load(map_path, &map, &err) != POSE_OK)
        die("mapping", &err);
    pb_rig_skel *skel;
    if (pb_rig_skel_schematic_body(&skel, &err) != POSE_OK)
        die("rig", &err);
    pb_channel ch[PB_USB_MAX_CHANNELS];
    pb_usb_layout_channels(&layout, ch);
    pb_chanmap *cm;
    if (pb_chanmap_create(map, ch, layout.channel_count, skel, &cm, &err) != POSE_OK)
        die("chanmap", &err);
    pb_pose pose;
    pb_pose_init(&pose, skel->joint_count);

    /* 60 s at 1 kHz of the arm raise (it loops), as usbmon text */
    char tmp[] = "/tmp/bench_usb_XXXXXX";
    int fd = mkstemp(tmp);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f)
        die("temporary file", NULL);
    int64_t t0 = pb_now_ns();
    long sent = pb_gonio_write_capture(f, PB_MOTION_ARM_RAISE, 1000.0, 60.0, 17, NULL);
    if (fclose(f) != 0 || sent != 60000)
        die("writing the capture", NULL);
    double write_s = (double)(pb_now_ns() - t0) * 1e-9;
    pb_usbmon_capture *cap;
    t0 = pb_now_ns();
    if (pb_usbmon_load(tmp, &cap, &err) != POSE_OK)
        die("reading the capture", &err);
    double read_s = (double)(pb_now_ns() - t0) * 1e-9;
    FILE *sz = fopen(tmp, "rb");
    double mb = 0;
    if (sz) {
        fseek(sz, 0, SEEK_END);
        mb = (double)ftell(sz) / 1e6;
        fclose(sz);
    }

    /* decode + map per transfer, timed one by one */
    size_t nframes = 0;
    const uint8_t **frames = malloc(cap->count * sizeof *frames);
    for (size_t i = 0; frames && i < cap->count; i++)
        if (cap->events[i].event == 'C' && cap->events[i].xfer == 'I' && cap->events[i].captured == 32)
            frames[nframes++] = cap->data + cap->events[i].offset;
    pb_usb_decoder dec;
    if (!frames || nframes != 60000 || pb_usb_decoder_init(&dec, &layout, &err) != POSE_OK)
        die("frames", &err);
    /* decode alone, in bulk (no per-frame clock reads) */
    int64_t d0 = pb_now_ns();
    for (int p = 0; p < 5; p++) {
        pb_usb_decoder_resync(&dec);
        for (size_t i = 0; i < nframes; i++)
            if (pb_usb_decode(&dec, frames[i], 32, NULL) != PB_USB_DECODE_OK)
                die("a frame did not decode", NULL);
    }
    double decode_ns = (double)(pb_now_ns() - d0) / (5.0 * (double)nframes);
    const int passes = 3;
    double *ns = malloc((size_t)passes * nframes * sizeof *ns);
    uint32_t idx[PB_USB_MAX_CHANNELS];
    for (size_t c = 0; c < layout.channel_count; c++)
        idx[c] = (uint32_t)c;
    double sink = 0;
    size_t k = 0;
    int64_t all0 = pb_now_ns();
    for (int p = 0; p < passes; p++) {
        pb_usb_decoder_resync(&dec);
        for (size_t i = 0; i < nframes; i++, k++) {
            int64_t a = pb_now_ns();
            if (pb_usb_decode(&dec, frames[i], 32, NULL) != PB_USB_DECODE_OK)
                die("a frame did not decode", NULL);
            pb_update u = {(int64_t)(p * 60000 + (long)i) * 1000000, layout.channel_count, idx, dec.values};
            pb_chanmap_update(cm, &u);
            pb_chanmap_pose(cm, &pose);
            ns[k] = (double)(pb_now_ns() - a);
            sink += pose.q[1][0];
        }
    }
    double mean_ns = (double)(pb_now_ns() - all0) / (double)k;
    qsort(ns, k, sizeof *ns, cmp_double);
    double p50 = ns[k / 2], p99 = ns[k * 99 / 100];
    pb_usb_decoder_free(&dec);
    free(ns);
    free(frames);
    pb_usbmon_capture_free(cap);

    run fast = replay(tmp, &layout, cm, &pose, 1, 60);
    run rt = {0};
    if (rt_seconds > 0)
        rt = replay(tmp, &layout, cm, &pose, 0, rt_seconds);
    remove(tmp);

    if (json) {
        printf("{\"decode_ns\":%.1f,\"decode_map_ns_mean\":%.1f,\"decode_map_ns_p50\":%.1f,\"decode_map_ns_p99\":%.1f,"
               "\"capture_mb\":%.2f,\"write_mb_s\":%.1f,\"parse_mb_s\":%.1f,\"afap_frames\":%zu,\"afap_seconds\":%.3f,"
               "\"afap_drops\":%llu,\"afap_reordered\":%llu,\"realtime_seconds\":%.1f,\"realtime_frames\":%zu,"
               "\"realtime_drops\":%llu,\"realtime_reordered\":%llu,\"lateness_us_p50\":%.1f,\"lateness_us_p99\":%.1f,"
               "\"lateness_us_max\":%.1f}\n",
               decode_ns, mean_ns, p50, p99, mb, mb / write_s, mb / read_s, fast.frames, fast.seconds,
               (unsigned long long)fast.drops, (unsigned long long)fast.reordered, rt_seconds, rt.frames,
               (unsigned long long)rt.drops, (unsigned long long)rt.reordered, rt.late_p50, rt.late_p99, rt.late_max);
    } else {
        printf("USB goniometer box frame (32 bytes: counter, 16 x 12-bit angles, hold, CRC-16), 17 channels, 16 mapped:\n");
        printf("  decode (length, CRC-16, counter, 17 fields)  %6.0f ns per transfer\n", decode_ns);
        printf("  decode + map + joint rotations   mean %6.0f ns, p50 %6.0f ns, p99 %6.0f ns per transfer (target < 5000 ns)\n",
               mean_ns, p50, p99);
        printf("usbmon text, 60 s at 1 kHz (%.2f MB): write %.1f MB/s, parse %.1f MB/s\n", mb, mb / write_s,
               mb / read_s);
        printf("replay 60 s at 1 kHz as fast as possible (source + decode + map): %zu / 60000 frames in %.3f s "
               "(%.0fx real time), drops %llu, reordered %llu\n",
               fast.frames, fast.seconds, 60.0 / fast.seconds, (unsigned long long)fast.drops,
               (unsigned long long)fast.reordered);
        if (rt_seconds > 0)
            printf("replay at recorded timing, %.0f s at 1 kHz: %zu frames in %.3f s, drops %llu, reordered %llu, "
                   "lateness p50 %.1f us, p99 %.1f us, max %.1f us\n",
                   rt_seconds, rt.frames, rt.seconds, (unsigned long long)rt.drops, (unsigned long long)rt.reordered,
                   rt.late_p50, rt.late_p99, rt.late_max);
    }
    pb_pose_free(&pose);
    pb_chanmap_free(cm);
    pb_rig_skel_free(skel);
    pb_mapping_free(map);
    if (sink == 12345.678)
        return 3;
    return fast.frames == 60000 && fast.drops == 0 && fast.reordered == 0 && rt.drops == 0 && rt.reordered == 0 ? 0 : 1;
}
