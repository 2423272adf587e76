/* SPDX-License-Identifier: Apache-2.0
 * bench_soak: a HID device at 1 kHz (the mannequin's 1 kHz recording,
 * looped), a 16-node CAN bus at 1 kHz per node (the goniometer rig's log,
 * cleaned of its deliberate faults, looped at x5: its nodes send at 200 Hz)
 * and a mocap clip (CMU 131_01, looped), each replayed by a bridge thread at
 * recorded timing through pose/bridge.h into its own pose_state, posed at
 * 120 Hz by two host threads (HID and CAN on one, the clip on the other).
 *
 * Phase 1 runs SECONDS; phase 2 the same while the HID source is unplugged
 * (its bridge closed) for a second every 30 s and plugged back (reopened).
 * Printed per phase: resident memory growth after the warm-up and over the
 * second half (a leak grows both; memory the allocator keeps after the
 * first unplugs, the first growth only), samples,
 * dropped samples (the bridges' drop counters), poses seen out of order (seq
 * or media time going back), and the sample -> posed state lag (time since
 * the bridge thread published the pose, plus pose_apply), p50/p99/max.
 *
 *   bench_soak [--seconds S (per phase, default 600)] [--warmup S (10)] [--rig FILE.rig] [--json]
 */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "candump_log.h"
#include "pose/bridge.h"
#include "pose/pose.h"

enum { SOURCES = 3, HID = 0, CAN = 1, CLIP = 2, HOST_HZ = 120, UNPLUG_EVERY_S = 30 };

static const char *const source_names[SOURCES] = {"hid_1khz", "can_16_nodes_1khz", "mocap_clip"};

typedef struct lane {
    const char *source, *map;
    double speed;
    const pose_rig *rig;
    pose_bridge *bridge;
    pose_state *state;
    uint64_t last_seq;
    double last_media;
    long out_of_order, poses;
    double *lag_us; /* preallocated and touched: filling it does not grow the resident set */
    size_t lag_n, lag_cap;
    uint64_t samples_closed, drops_closed; /* of bridges closed by an unplug */
    int unplugs;
} lane;

typedef struct host {
    lane *lanes[2];
    int count;
    int unplug; /* phase 2: lanes[0] is unplugged and replugged */
    double seconds;
    double warmup;
    atomic_int *warm; /* set by the main thread at the end of the warm-up */
} host;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void sleep_until(double t)
{
    struct timespec ts = {(time_t)t, (long)((t - floor(t)) * 1e9)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) != 0) {
    }
}

static long rss_kib(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0, resident = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &resident) != 2)
            resident = 0;
        fclose(f);
    }
    return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

static void die(const char *what)
{
    fprintf(stderr, "bench_soak: %s: %s\n", what, pose_last_error());
    exit(1);
}

static void lane_open(lane *l)
{
    pose_bridge_options o = {.size = sizeof o, .map_path = l->map, .loop = 1, .speed = l->speed};
    if (pose_bridge_open(l->source, l->rig, &o, &l->bridge) != POSE_OK)
        die(l->source);
    l->last_seq = 0; /* a new bridge counts from 1 */
}

static void lane_close(lane *l)
{
    pose_bridge_status s = {.size = sizeof s};
    if (pose_bridge_status_get(l->bridge, &s) == POSE_OK) {
        l->samples_closed += s.samples;
        l->drops_closed += s.drops;
    }
    pose_bridge_close(l->bridge);
    l->bridge = NULL;
}

static void lane_tick(lane *l, int measure)
{
    if (!l->bridge)
        return;
    pose_bridge_frame f;
    if (pose_bridge_apply(l->bridge, l->state, &f) < 0)
        die("pose_bridge_apply");
    const double t0 = now_s();
    if (pose_apply(l->state) < 0)
        die("pose_apply");
    if (!f.fresh)
        return;
    l->poses++;
    if (f.seq <= l->last_seq || (l->last_seq && f.media_s < l->last_media))
        l->out_of_order++;
    l->last_seq = f.seq;
    l->last_media = f.media_s;
    if (measure && l->lag_n < l->lag_cap)
        l->lag_us[l->lag_n++] = (f.age_s + now_s() - t0) * 1e6;
}

static void *host_thread(void *arg)
{
    host *h = arg;
    const double start = now_s(), period = 1.0 / HOST_HZ;
    double next = start, plugged_out_at = -1;
    int next_unplug = 1;
    for (long k = 0;; k++) {
        next = start + (double)k * period;
        if (next - start >= h->seconds)
            break;
        sleep_until(next);
        const int measure = atomic_load(h->warm);
        if (h->unplug) {
            lane *l = h->lanes[0];
            const double t = next - start;
            if (l->bridge && t >= next_unplug * UNPLUG_EVERY_S) {
                lane_close(l);
                l->unplugs++;
                plugged_out_at = t;
                next_unplug++;
            } else if (!l->bridge && t - plugged_out_at >= 1.0) {
                lane_open(l);
            }
        }
        for (int i = 0; i < h->count; i++)
            lane_tick(h->lanes[i], measure);
    }
    return NULL;
}

static int cmp_d(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The rig log without what it holds on purpose (malformed lines, error
 * frames, a node's silence from 5 s): a bus whose every sample should arrive. */
static void clean_can_log(const char *out_path)
{
    pb_candump_reader r;
    char err[256];
    if (pb_candump_open(&r, POSE_BENCH_DATA "/can-rig/sit_stand_arm_raise.log", err, sizeof err) != 0) {
        fprintf(stderr, "bench_soak: %s\n", err);
        exit(1);
    }
    FILE *f = fopen(out_path, "w");
    if (!f) {
        perror(out_path);
        exit(1);
    }
    pb_can_frame fr;
    int64_t first = -1;
    while (pb_candump_next(&r, &fr) == 1) {
        if (first < 0)
            first = fr.t_ns;
        if (fr.t_ns - first >= 4900000000LL)
            break;
        if (!(fr.flags & PB_CAN_ERR) && pb_candump_write(f, &fr, r.iface) != 0) {
            perror(out_path);
            exit(1);
        }
    }
    fclose(f);
    pb_candump_close(&r);
}

/* The body template's 19 joints, schematic clinical axes, one token tet
 * (as bench_bridge): the bridge only sets joints. */
static pose_rig *synthetic_body(void)
{
    static const char *names[19] = {"pelvis",     "lumbar",     "thorax",  "neck",    "head",
                                    "clavicle_r", "shoulder_r", "elbow_r", "wrist_r", "clavicle_l",
                                    "shoulder_l", "elbow_l",    "wrist_l", "hip_r",   "knee_r",
                                    "ankle_r",    "hip_l",      "knee_l",  "ankle_l"};
    static const int parents[19] = {-1, 0, 1, 2, 3, 2, 5, 6, 7, 2, 9, 10, 11, 0, 13, 14, 0, 16, 17};
    pose_joint_desc d[19];
    pose_joint_clinical c[19];
    memset(d, 0, sizeof d);
    memset(c, 0, sizeof c);
    for (int j = 0; j < 19; j++) {
        d[j].name = names[j];
        d[j].parent = parents[j];
        d[j].rest_model.rotation[3] = 1;
        d[j].rest_model.translation[0] = (float)(j % 5) * 0.1f;
        d[j].rest_model.translation[2] = (float)j * 0.1f;
        if (j) {
            c[j].neutral[3] = 1.0f;
            c[j].axes[0][1] = c[j].axes[1][0] = c[j].axes[2][2] = 1.0f;
            c[j].flags = POSE_CLINICAL_DEFINED;
        }
    }
    static const float tet_p[12] = {0, 0, 0, 0.01f, 0, 0, 0, 0.01f, 0, 0, 0, 0.01f};
    static const uint32_t tet[4] = {0, 1, 2, 3};
    static const uint16_t label[1] = {0}, wj[4] = {0, 0, 0, 0};
    static const float w[4] = {1, 1, 1, 1};
    pose_rig_desc desc = {.joint_count = 19, .joints = d, .tet_vertex_count = 4, .tet_positions = tet_p,
                          .tet_count = 1, .tets = tet, .tet_labels = label, .influences = 1, .weight_joints = wj,
                          .weights = w, .clinical = c};
    pose_rig *rig = NULL;
    if (pose_rig_create(&desc, NULL, &rig) != POSE_OK)
        die("pose_rig_create");
    return rig;
}

typedef struct phase_result {
    long rss_start_kib, rss_warm_kib, rss_max_kib, rss_end_kib;
    long rss_half_kib, rss_late_max_kib; /* at half time, and the most after it */
    uint64_t samples[SOURCES], drops[SOURCES];
    long poses[SOURCES], out_of_order[SOURCES], unplugs;
    double p50[SOURCES], p99[SOURCES], max[SOURCES];
} phase_result;

static void run_phase(lane *lanes, double seconds, double warmup, int unplug, phase_result *res)
{
    memset(res, 0, sizeof *res);
    for (int i = 0; i < SOURCES; i++) {
        lane *l = &lanes[i];
        l->lag_n = 0;
        l->poses = l->out_of_order = 0;
        l->samples_closed = l->drops_closed = 0;
        l->unplugs = 0;
        l->last_seq = 0;
        lane_open(l);
    }
    res->rss_start_kib = rss_kib();
    atomic_int warm = 0;
    host hosts[2] = {{.lanes = {&lanes[HID], &lanes[CAN]}, .count = 2, .unplug = unplug, .seconds = seconds,
                      .warmup = warmup, .warm = &warm},
                     {.lanes = {&lanes[CLIP]}, .count = 1, .seconds = seconds, .warmup = warmup, .warm = &warm}};
    pthread_t th[2];
    for (int i = 0; i < 2; i++)
        if (pthread_create(&th[i], NULL, host_thread, &hosts[i]) != 0) {
            fprintf(stderr, "bench_soak: cannot start a host thread\n");
            exit(1);
        }
    const double start = now_s();
    for (int s = 1; s <= (int)ceil(seconds); s++) {
        sleep_until(start + s);
        const long rss = rss_kib();
        if (s == (int)warmup) {
            res->rss_warm_kib = res->rss_max_kib = rss;
            atomic_store(&warm, 1);
        } else if (s > warmup && rss > res->rss_max_kib) {
            res->rss_max_kib = rss;
        }
        if (s == (int)ceil(seconds) / 2)
            res->rss_half_kib = res->rss_late_max_kib = rss;
        else if (s > (int)ceil(seconds) / 2 && rss > res->rss_late_max_kib)
            res->rss_late_max_kib = rss;
    }
    for (int i = 0; i < 2; i++)
        pthread_join(th[i], NULL);
    res->rss_end_kib = rss_kib();
    for (int i = 0; i < SOURCES; i++) {
        lane *l = &lanes[i];
        if (l->bridge)
            lane_close(l);
        res->samples[i] = l->samples_closed;
        res->drops[i] = l->drops_closed;
        res->poses[i] = l->poses;
        res->out_of_order[i] = l->out_of_order;
        qsort(l->lag_us, l->lag_n, sizeof *l->lag_us, cmp_d);
        if (l->lag_n) {
            res->p50[i] = l->lag_us[l->lag_n / 2];
            res->p99[i] = l->lag_us[l->lag_n * 99 / 100];
            res->max[i] = l->lag_us[l->lag_n - 1];
        }
    }
    res->unplugs = lanes[HID].unplugs;
}

static void print_phase(const char *name, const phase_result *r, double seconds, int json, int last)
{
    const long growth = r->rss_max_kib - r->rss_warm_kib, late = r->rss_late_max_kib - r->rss_half_kib;
    if (json) {
        printf("  \"%s\": {\"seconds\": %.0f, \"rss_kib\": {\"start\": %ld, \"after_warmup\": %ld, \"max\": %ld, "
               "\"end\": %ld, \"growth_after_warmup\": %ld, \"growth_second_half\": %ld}, \"unplugs\": %ld, "
               "\"sources\": {",
               name, seconds, r->rss_start_kib, r->rss_warm_kib, r->rss_max_kib, r->rss_end_kib, growth, late,
               r->unplugs);
        for (int i = 0; i < SOURCES; i++)
            printf("%s\"%s\": {\"samples\": %llu, \"drops\": %llu, \"poses\": %ld, \"out_of_order\": %ld, "
                   "\"lag_us\": {\"p50\": %.1f, \"p99\": %.1f, \"max\": %.1f}}",
                   i ? ", " : "", source_names[i], (unsigned long long)r->samples[i],
                   (unsigned long long)r->drops[i], r->poses[i], r->out_of_order[i], r->p50[i], r->p99[i], r->max[i]);
        printf("}}%s\n", last ? "" : ",");
        return;
    }
    printf("%s (%.0f s): resident memory %ld KiB after warm-up, max %ld KiB: growth %ld KiB (target < 1024); "
           "over the second half %ld KiB\n",
           name, seconds, r->rss_warm_kib, r->rss_max_kib, growth, late);
    if (r->unplugs)
        printf("  HID source unplugged and replugged %ld times\n", r->unplugs);
    for (int i = 0; i < SOURCES; i++)
        printf("  %-18s %10llu samples, %llu dropped, %ld poses applied, %ld out of order; sample -> pose lag "
               "p50 %.1f us, p99 %.1f us, max %.1f us\n",
               source_names[i], (unsigned long long)r->samples[i], (unsigned long long)r->drops[i], r->poses[i],
               r->out_of_order[i], r->p50[i], r->p99[i], r->max[i]);
}

int main(int argc, char **argv)
{
    double seconds = 600, warmup = 10;
    const char *rig_path = NULL;
    int json = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc)
            seconds = atof(argv[++i]);
        else if (strcmp(argv[i], "--warmup") == 0 && i + 1 < argc)
            warmup = atof(argv[++i]);
        else if (strcmp(argv[i], "--rig") == 0 && i + 1 < argc)
            rig_path = argv[++i];
        else if (strcmp(argv[i], "--json") == 0)
            json = 1;
        else {
            fprintf(stderr, "usage: bench_soak [--seconds S] [--warmup S] [--rig FILE.rig] [--json]\n");
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }
    if (!(warmup >= 1) || !(seconds > warmup + 1)) {
        fprintf(stderr, "bench_soak: --seconds must exceed --warmup (>= 1) by more than a second\n");
        return 2;
    }
    pose_rig *rig = NULL;
    if (rig_path ? pose_rig_load(rig_path, &rig) != POSE_OK : !(rig = synthetic_body()))
        die(rig_path);
    char can_log[256];
    snprintf(can_log, sizeof can_log, "/tmp/bench_soak_%ld.log", (long)getpid());
    clean_can_log(can_log);
    lane lanes[SOURCES] = {
        {.source = POSE_BENCH_DATA "/hid/mannequin_reach_1khz.hid", .map = POSE_BENCH_MAPS "/hid_mannequin_full_body.json",
         .speed = 1},
        {.source = can_log, .map = POSE_BENCH_MAPS "/can_rig_fullbody.json", .speed = 5},
        {.source = POSE_BENCH_DATA "/mocap/cmu-bvh/131_01.bvh", .map = POSE_BENCH_MAPS "/cmu131_bvh_to_full_body.json",
         .speed = 1},
    };
    for (int i = 0; i < SOURCES; i++) {
        lanes[i].rig = rig;
        if (pose_state_create(rig, &lanes[i].state) != POSE_OK)
            die("pose_state_create");
        lanes[i].lag_cap = (size_t)(seconds * HOST_HZ) + 16;
        lanes[i].lag_us = malloc(lanes[i].lag_cap * sizeof *lanes[i].lag_us);
        if (!lanes[i].lag_us)
            die("out of memory");
        /* A non-zero fill: malloc + memset(0) becomes calloc, which leaves
         * the pages untouched until the samples arrive and the resident set
         * then grows by the bench's own buffer. */
        for (size_t k = 0; k < lanes[i].lag_cap; k++)
            lanes[i].lag_us[k] = -1.0;
    }
    phase_result steady, unplugged;
    run_phase(lanes, seconds, warmup, 0, &steady);
    run_phase(lanes, seconds, warmup, 1, &unplugged);
    if (json)
        printf("{\n");
    print_phase("steady", &steady, seconds, json, 0);
    print_phase("unplug_every_30s", &unplugged, seconds, json, 1);
    if (json)
        printf("}\n");
    for (int i = 0; i < SOURCES; i++) {
        pose_state_free(lanes[i].state);
        free(lanes[i].lag_us);
    }
    pose_rig_free(rig);
    remove(can_log);
    return 0;
}
