/* SPDX-License-Identifier: Apache-2.0
 * bench_bridge [--json] [--replay-seconds S]
 * Prints: BVH parse speed (MB/s) on a large BVH (131_01's frames repeated to
 * ~20 MB); decode + retarget + publish per frame for the 31-joint CMU
 * skeleton (onto itself and onto the 19-joint body template), target < 50 us;
 * scalar channel mapping per device sample; replay timing error p50/p99 at
 * x1 over S seconds (default 5), target p99 < 1 ms, with normal scheduling
 * and with the bridge thread at SCHED_FIFO priority 10 (when allowed); and
 * sample -> posed state through the public API (pose/bridge.h): from the
 * bridge thread publishing a device sample's pose to pose_bridge_apply
 * having set the state, with the host polling without pause, for the 1 kHz
 * HID recording and the CAN rig's log played at x1 (up to 4 s each). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sched.h>

#include "clock.h"
#include "mapping.h"
#include "pb_math.h"
#include "player.h"
#include "pose/bridge.h"
#include "runner.h"

#ifndef POSE_BENCH_DATA
#define POSE_BENCH_DATA "data"
#endif

static int cmp_d(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f || fseek(f, 0, SEEK_END) != 0) {
        fprintf(stderr, "bench_bridge: cannot read %s\n", path);
        exit(1);
    }
    long len = ftell(f);
    rewind(f);
    char *d = malloc((size_t)len + 1);
    if (!d || fread(d, 1, (size_t)len, f) != (size_t)len) {
        fprintf(stderr, "bench_bridge: cannot read %s\n", path);
        exit(1);
    }
    fclose(f);
    d[len] = '\0';
    *n = (size_t)len;
    return d;
}

/* 131_01's hierarchy with its motion lines repeated to about `target` bytes */
static char *big_bvh(size_t target, size_t *size, size_t *frames)
{
    size_t n;
    char *src = slurp(POSE_BENCH_DATA "/mocap/cmu-bvh/131_01.bvh", &n);
    char *motion = strstr(src, "MOTION");
    char *ft = strstr(motion, "Frame Time:");
    char *body = strchr(ft, '\n') + 1;
    size_t body_len = n - (size_t)(body - src);
    size_t lines = 0;
    for (size_t i = 0; i < body_len; i++)
        lines += body[i] == '\n';
    size_t reps = target / body_len + 1;
    size_t head_len = (size_t)(motion - src);
    char *out = malloc(head_len + 128 + reps * body_len + 1);
    size_t k = 0;
    memcpy(out, src, head_len);
    k += head_len;
    k += (size_t)sprintf(out + k, "MOTION\nFrames: %zu\nFrame Time: 0.0083333\n", reps * lines);
    for (size_t r = 0; r < reps; r++) {
        memcpy(out + k, body, body_len);
        k += body_len;
    }
    out[k] = '\0';
    free(src);
    *size = k;
    *frames = reps * lines;
    return out;
}

static double bench_parse(int json)
{
    size_t size, frames;
    char *text = big_bvh(20u << 20, &size, &frames);
    double best = 1e30;
    for (int rep = 0; rep < 3; rep++) {
        pb_clip *c;
        pb_error err;
        int64_t t0 = pb_now_ns();
        if (pb_bvh_parse(text, size, "big.bvh", &c, &err) != POSE_OK) {
            fprintf(stderr, "bench_bridge: %s\n", err.message);
            exit(1);
        }
        double s = (double)(pb_now_ns() - t0) * 1e-9;
        best = s < best ? s : best;
        pb_clip_free(c);
    }
    double mbs = (double)size / 1e6 / best;
    if (!json)
        printf("BVH parse: %.1f MB (%zu frames x 96 channels) in %.3f s: %.1f MB/s\n", (double)size / 1e6, frames,
               best, mbs);
    free(text);
    return mbs;
}

typedef struct frame_stats {
    double mean_us, p50_us, p99_us;
    int joints_in, joints_out;
} frame_stats;

/* player sample at a fractional time (two-frame slerp) + retarget + publish */
static frame_stats bench_frame(const pb_clip *clip, const pb_rig_skel *rig, const pb_mapping *map)
{
    pb_player pl;
    pb_retarget *rt;
    pb_handoff h;
    pb_error err;
    if (pb_player_init(&pl, clip, 1, &err) || pb_retarget_create(map, clip, rig, &rt, &err) ||
        pb_handoff_init(&h, rig->joint_count)) {
        fprintf(stderr, "bench_bridge: %s\n", err.message);
        exit(1);
    }
    size_t n = (size_t)clip->joint_count;
    double (*lq)[4] = malloc(n * sizeof *lq), (*lt)[3] = malloc(n * sizeof *lt);
    enum { N = 20000 };
    double *us = malloc(N * sizeof *us), sum = 0;
    for (int i = 0; i < N; i++) {
        /* 2.5 samples per clip frame: every sample decodes a new frame pair half the time */
        double t = fmod((double)i * 0.4 * clip->frame_time, pb_player_duration(&pl));
        int64_t t0 = pb_now_ns();
        pb_player_sample(&pl, t, lq, lt);
        pb_pose *back = pb_handoff_back(&h);
        pb_retarget_apply(rt, (const double (*)[4])lq, (const double (*)[3])lt, clip->frame_time, back);
        pb_handoff_publish(&h);
        us[i] = (double)(pb_now_ns() - t0) * 1e-3;
        sum += us[i];
    }
    qsort(us, N, sizeof *us, cmp_d);
    frame_stats s = {sum / N, us[N / 2], us[N * 99 / 100], clip->joint_count, rig->joint_count};
    free(us);
    free(lq);
    free(lt);
    pb_handoff_free(&h);
    pb_retarget_free(rt);
    pb_player_free(&pl);
    return s;
}

static double bench_channels(void)
{
    /* 16 scalar channels onto 8 joints, two-point calibration, deadband, One Euro filter, limits */
    pb_rig_skel *rig;
    pose_joint_desc d[8];
    memset(d, 0, sizeof d);
    static const char *names[8] = {"j0", "j1", "j2", "j3", "j4", "j5", "j6", "j7"};
    for (int j = 0; j < 8; j++) {
        d[j].name = names[j];
        d[j].parent = j - 1;
        d[j].rest_model.rotation[3] = 1;
        d[j].rest_model.translation[0] = (float)j;
    }
    pb_error err;
    pb_rig_skel_from_desc(d, 8, &rig, &err);
    char json[8192];
    size_t k = (size_t)snprintf(json, sizeof json, "{\"filter\": {\"min_cutoff\": 1, \"beta\": 0.01}, \"channels\": [");
    pb_channel ch[16];
    memset(ch, 0, sizeof ch);
    for (int i = 0; i < 16; i++) {
        snprintf(ch[i].name, sizeof ch[i].name, "c%d", i);
        k += (size_t)snprintf(json + k, sizeof json - k,
                              "%s{\"channel\": \"c%d\", \"joint\": \"j%d\", \"axis\": \"%c\", \"calibration\": "
                              "{\"raw\": [0, 4095], \"deg\": [-90, 90]}, \"deadband\": 0.1, \"limits\": [-80, 80]}",
                              i ? "," : "", i, i / 2, i % 2 ? 'x' : 'z');
    }
    snprintf(json + k, sizeof json - k, "]}");
    pb_mapping *m;
    pb_chanmap *cm;
    if (pb_mapping_parse(json, strlen(json), "bench.json", &m, &err) ||
        pb_chanmap_create(m, ch, 16, rig, &cm, &err)) {
        fprintf(stderr, "bench_bridge: %s\n", err.message);
        exit(1);
    }
    pb_pose pose;
    pb_pose_init(&pose, 8);
    uint32_t idx[16];
    double val[16];
    for (int i = 0; i < 16; i++)
        idx[i] = (uint32_t)i;
    enum { N = 200000 };
    int64_t t0 = pb_now_ns();
    for (int s = 0; s < N; s++) {
        for (int i = 0; i < 16; i++)
            val[i] = 2048 + 1000 * sin(0.001 * s + i);
        pb_update u = {.t_ns = (int64_t)s * 1000000, .count = 16, .channels = idx, .values = val};
        pb_chanmap_update(cm, &u);
        pb_chanmap_pose(cm, &pose);
    }
    double us = (double)(pb_now_ns() - t0) * 1e-3 / N;
    pb_pose_free(&pose);
    pb_chanmap_free(cm);
    pb_mapping_free(m);
    pb_rig_skel_free(rig);
    return us;
}

static int bench_replay(const pb_clip *clip, const pb_rig_skel *rig, const pb_mapping *map, double seconds,
                        int rt_priority, double out[3], long *ticks)
{
    pb_runner *r;
    pb_error err;
    long n = (long)(seconds / clip->frame_time);
    pb_runner_options o = {.speed = 1.0, .loop = 1, .max_ticks = n, .rt_priority = rt_priority};
    if (pb_runner_start_clip(clip, rig, map, &o, &r, &err) != POSE_OK) {
        fprintf(stderr, "bench_bridge: %s\n", err.message);
        exit(1);
    }
    pb_runner_wait(r, -1);
    pb_runner_stats st;
    pb_runner_stats_get(r, &st);
    static const double q[3] = {0.5, 0.99, 1.0};
    *ticks = (long)pb_runner_lag_quantiles(r, q, out, 3);
    pb_runner_stop(r, NULL);
    return st.realtime;
}

/* The 19 joints of the body template with schematic clinical axes (the
 * device maps speak clinical angles) and one token tet: the bridge reads
 * only joints, and pose_bridge_apply only sets them. */
static pose_rig *api_body_rig(const pose_joint_desc *d)
{
    pose_joint_clinical c[19];
    memset(c, 0, sizeof c);
    for (int j = 1; j < 19; j++) {
        c[j].neutral[3] = 1.0f;
        c[j].axes[0][1] = c[j].axes[1][0] = c[j].axes[2][2] = 1.0f;
        c[j].flags = POSE_CLINICAL_DEFINED;
    }
    static const float tet_p[12] = {0, 0, 0, 0.01f, 0, 0, 0, 0.01f, 0, 0, 0, 0.01f};
    static const uint32_t tet[4] = {0, 1, 2, 3};
    static const uint16_t label[1] = {0}, wj[4] = {0, 0, 0, 0};
    static const float w[4] = {1, 1, 1, 1};
    pose_rig_desc desc = {.joint_count = 19, .joints = d, .tet_vertex_count = 4, .tet_positions = tet_p,
                          .tet_count = 1, .tets = tet, .tet_labels = label, .influences = 1, .weight_joints = wj,
                          .weights = w, .clinical = c};
    pose_rig *rig = NULL;
    if (pose_rig_create(&desc, NULL, &rig) != POSE_OK) {
        fprintf(stderr, "bench_bridge: %s\n", pose_last_error());
        exit(1);
    }
    return rig;
}

typedef struct api_latency {
    double p50_us, p99_us, max_us;
    long poses;
} api_latency;

/* Publication -> state set, as pose_bridge_frame.age_s measures it right
 * after pose_bridge_apply has set the joints; the host polls, yielding. */
static api_latency bench_api(const pose_rig *rig, const char *source, const char *map, double seconds)
{
    pose_bridge_options o = {.size = sizeof o, .map_path = map, .end_s = seconds};
    pose_bridge *b;
    pose_state *st;
    if (pose_state_create(rig, &st) != POSE_OK || pose_bridge_open(source, rig, &o, &b) != POSE_OK) {
        fprintf(stderr, "bench_bridge: %s\n", pose_last_error());
        exit(1);
    }
    size_t cap = (size_t)(seconds * 5000) + 16, n = 0;
    double *age = malloc(cap * sizeof *age);
    while (!pose_bridge_wait(b, 0)) {
        pose_bridge_frame f;
        if (pose_bridge_apply(b, st, &f) < 0) {
            fprintf(stderr, "bench_bridge: %s\n", pose_last_error());
            exit(1);
        }
        if (f.fresh && n < cap)
            age[n++] = f.age_s * 1e6;
        sched_yield();
    }
    pose_bridge_close(b);
    pose_state_free(st);
    qsort(age, n, sizeof *age, cmp_d);
    api_latency r = {n ? age[n / 2] : 0, n ? age[n * 99 / 100] : 0, n ? age[n - 1] : 0, (long)n};
    free(age);
    return r;
}

int main(int argc, char **argv)
{
    int json = 0;
    double replay_s = 5.0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--json") == 0)
            json = 1;
        else if (strcmp(argv[i], "--replay-seconds") == 0 && i + 1 < argc)
            replay_s = atof(argv[++i]);
        else {
            fprintf(stderr, "usage: bench_bridge [--json] [--replay-seconds S]\n");
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }
    double mbs = bench_parse(json);
    pb_clip *clip;
    pb_rig_skel *self, *body;
    pb_mapping *same, *map;
    pb_error err;
    if (pb_bvh_load(POSE_BENCH_DATA "/mocap/cmu-bvh/131_01.bvh", &clip, &err) ||
        pb_rig_skel_from_clip(clip, 1.0, &self, &err) || pb_mapping_identity(&same, &err) ||
        pb_mapping_load(POSE_BENCH_DATA "/../bridge/maps/cmu131_bvh_to_full_body.json", &map, &err)) {
        fprintf(stderr, "bench_bridge: %s\n", err.message);
        return 1;
    }
    /* the body template's 19 joints: positions do not matter for timing */
    pose_joint_desc d[19];
    memset(d, 0, sizeof d);
    static const char *names[19] = {"pelvis", "lumbar", "thorax", "neck", "head", "clavicle_r", "shoulder_r",
                                    "elbow_r", "wrist_r", "clavicle_l", "shoulder_l", "elbow_l", "wrist_l",
                                    "hip_r", "knee_r", "ankle_r", "hip_l", "knee_l", "ankle_l"};
    static const int parents[19] = {-1, 0, 1, 2, 3, 2, 5, 6, 7, 2, 9, 10, 11, 0, 13, 14, 0, 16, 17};
    for (int j = 0; j < 19; j++) {
        d[j].name = names[j];
        d[j].parent = parents[j];
        d[j].rest_model.rotation[3] = 1;
        d[j].rest_model.translation[0] = (float)(j % 5) * 0.1f;
        d[j].rest_model.translation[2] = (float)j * 0.1f;
    }
    if (pb_rig_skel_from_desc(d, 19, &body, &err)) {
        fprintf(stderr, "bench_bridge: %s\n", err.message);
        return 1;
    }
    int real_joints = 0;
    for (int j = 0; j < clip->joint_count; j++)
        real_joints += !clip->joints[j].is_end;
    frame_stats fs = bench_frame(clip, self, same);
    frame_stats fb = bench_frame(clip, body, map);
    double ch_us = bench_channels();
    double lag[3], rlag[3];
    long ticks, rticks;
    bench_replay(clip, self, same, replay_s, 0, lag, &ticks);
    int rt = bench_replay(clip, self, same, replay_s, 10, rlag, &rticks);
    pose_rig *api_rig = api_body_rig(d);
    double api_s = replay_s < 4.0 ? replay_s : 4.0;
    api_latency ah = bench_api(api_rig, POSE_BENCH_DATA "/hid/mannequin_reach_1khz.hid",
                               POSE_BENCH_DATA "/../bridge/maps/hid_mannequin_full_body.json", api_s);
    api_latency ac = bench_api(api_rig, POSE_BENCH_DATA "/can-rig/sit_stand_arm_raise.log",
                               POSE_BENCH_DATA "/../bridge/maps/can_rig_fullbody.json", api_s);
    pose_rig_free(api_rig);
    if (json) {
        printf("{\"bvh_parse_mb_s\": %.1f, \"frame_self_us\": {\"mean\": %.2f, \"p50\": %.2f, \"p99\": %.2f, "
               "\"clip_joints\": %d, \"rig_joints\": %d}, \"frame_body_us\": {\"mean\": %.2f, \"p50\": %.2f, "
               "\"p99\": %.2f, \"rig_joints\": %d}, \"channels16_us\": %.3f, \"replay_x1_lag_ms\": {\"p50\": %.4f, "
               "\"p99\": %.4f, \"max\": %.4f, \"ticks\": %ld}, \"replay_x1_fifo_lag_ms\": {\"p50\": %.4f, \"p99\": %.4f, "
               "\"max\": %.4f, \"granted\": %s}, \"api_sample_to_state_us\": {\"hid_1khz\": {\"p50\": %.1f, "
               "\"p99\": %.1f, \"max\": %.1f, \"poses\": %ld}, \"can_rig\": {\"p50\": %.1f, \"p99\": %.1f, "
               "\"max\": %.1f, \"poses\": %ld}}}\n",
               mbs, fs.mean_us, fs.p50_us, fs.p99_us, real_joints, fs.joints_out, fb.mean_us, fb.p50_us, fb.p99_us,
               fb.joints_out, ch_us, lag[0], lag[1], lag[2], ticks, rlag[0], rlag[1], rlag[2], rt ? "true" : "false",
               ah.p50_us, ah.p99_us, ah.max_us, ah.poses, ac.p50_us, ac.p99_us, ac.max_us, ac.poses);
    } else {
        printf("decode + retarget + publish, %d-joint CMU skeleton (+%d end sites) onto itself: mean %.2f us, "
               "p50 %.2f us, p99 %.2f us (target < 50 us)\n",
               real_joints, clip->joint_count - real_joints, fs.mean_us, fs.p50_us, fs.p99_us);
        printf("decode + retarget + publish onto the 19-joint body template: mean %.2f us, p50 %.2f us, p99 %.2f us\n",
               fb.mean_us, fb.p50_us, fb.p99_us);
        printf("channel mapping, 16 channels (calibrate, filter, deadband, limits) -> 8 joints: %.3f us per sample\n",
               ch_us);
        printf("replay at x1, %ld ticks (%.1f s): wake-up lag p50 %.3f ms, p99 %.3f ms, max %.3f ms (target p99 < 1 ms)\n",
               ticks, replay_s, lag[0], lag[1], lag[2]);
        printf("replay at x1, bridge thread SCHED_FIFO 10 (%s): lag p50 %.3f ms, p99 %.3f ms, max %.3f ms\n",
               rt ? "granted" : "NOT granted: normal scheduling", rlag[0], rlag[1], rlag[2]);
        printf("sample -> posed state through pose/bridge.h (publication to pose_bridge_apply done, host polling):\n"
               "  HID 1 kHz recording at x1, %ld poses: p50 %.1f us, p99 %.1f us, max %.1f us\n"
               "  CAN rig log at x1, %ld poses: p50 %.1f us, p99 %.1f us, max %.1f us\n",
               ah.poses, ah.p50_us, ah.p99_us, ah.max_us, ac.poses, ac.p50_us, ac.p99_us, ac.max_us);
    }
    pb_mapping_free(map);
    pb_mapping_free(same);
    pb_rig_skel_free(body);
    pb_rig_skel_free(self);
    pb_clip_free(clip);
    return 0;
}
