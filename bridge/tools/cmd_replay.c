/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge replay: play a mocap clip onto a rig in real time through the
 * bridge thread, as a host would: the main thread is the host's frame loop
 * (60 Hz), takes the newest pose without waiting and applies it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bridge_apply.h"
#include "clock.h"
#include "pose_bridge_cli.h"
#include "runner.h"

static void help(FILE *f)
{
    fprintf(f,
            "usage: pose-bridge replay CLIP [--skeleton ASF] --rig RIG [--map MAP] [options]\n"
            "  CLIP            .bvh, or .amc (ASF from --skeleton, or NN.asf beside NN_MM.amc)\n"
            "  --rig RIG       a .rig file (poses a pose_state and runs pose_apply each host frame),\n"
            "                  a .bvh/.asf whose skeleton is the rig, or 'self' (the clip's own skeleton)\n"
            "  --map MAP       mapping JSON (default: joints of the same name)\n"
            "  --speed X       playback speed (default 1)\n"
            "  --afap          as fast as possible (no real-time pacing)\n"
            "  --loop          wrap at the end\n"
            "  --rate HZ       bridge publish rate (default: the clip's; between frames is slerped)\n"
            "  --host-rate HZ  the host frame loop's rate (default 60)\n"
            "  --frames N      stop after N published poses\n"
            "  --duration S    stop after S seconds of clip time\n"
            "  --start S       start at clip time S\n"
            "  --out FILE.bvh  record the applied joint angles (flushed every frame)\n"
            "  --rt-priority N run the bridge thread SCHED_FIFO at priority N when allowed\n"
            "  --json          print a JSON summary on stdout\n"
            "  --quiet         no status line\n"
            "Status line (stderr): frame, bridge fps, lag of the bridge thread's wake-ups.\n");
}

typedef struct replay_args {
    const char *clip, *skeleton, *rig, *map, *out;
    double speed, rate, host_rate, duration, start;
    long frames, rt_priority;
    int afap, loop, json, quiet;
} replay_args;

static int parse(int argc, char **argv, replay_args *a)
{
    memset(a, 0, sizeof *a);
    a->speed = 1.0;
    a->host_rate = 60.0;
    for (int i = 1; i < argc; i++) {
        const char *s = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        char *e = NULL;
#define NUM(field)                                                             \
    do {                                                                       \
        if (!v)                                                                \
            return -1;                                                         \
        a->field = strtod(v, &e);                                              \
        if (*e || !isfinite((double)a->field) || a->field < 0)                 \
            return -1;                                                         \
        i++;                                                                   \
    } while (0)
        if (strcmp(s, "--skeleton") == 0 && v)
            a->skeleton = argv[++i];
        else if (strcmp(s, "--rig") == 0 && v)
            a->rig = argv[++i];
        else if (strcmp(s, "--map") == 0 && v)
            a->map = argv[++i];
        else if (strcmp(s, "--out") == 0 && v)
            a->out = argv[++i];
        else if (strcmp(s, "--speed") == 0)
            NUM(speed);
        else if (strcmp(s, "--rate") == 0)
            NUM(rate);
        else if (strcmp(s, "--host-rate") == 0)
            NUM(host_rate);
        else if (strcmp(s, "--duration") == 0)
            NUM(duration);
        else if (strcmp(s, "--start") == 0)
            NUM(start);
        else if (strcmp(s, "--frames") == 0 && v) {
            a->frames = strtol(v, &e, 10);
            if (*e || a->frames < 0)
                return -1;
            i++;
        } else if (strcmp(s, "--rt-priority") == 0 && v) {
            a->rt_priority = strtol(v, &e, 10);
            if (*e || a->rt_priority < 1 || a->rt_priority > 99)
                return -1;
            i++;
        } else if (strcmp(s, "--afap") == 0)
            a->afap = 1;
        else if (strcmp(s, "--loop") == 0)
            a->loop = 1;
        else if (strcmp(s, "--json") == 0)
            a->json = 1;
        else if (strcmp(s, "--quiet") == 0)
            a->quiet = 1;
        else if (s[0] != '-' && !a->clip)
            a->clip = s;
        else
            return -1;
#undef NUM
    }
    if (!a->clip || !a->rig || !(a->speed > 0) || !(a->host_rate > 0))
        return -1;
    return 0;
}

static int ends_with(const char *s, const char *suf)
{
    size_t n = strlen(s), m = strlen(suf);
    return n >= m && strcmp(s + n - m, suf) == 0;
}

static int cmp_i64(const void *x, const void *y)
{
    int64_t a = *(const int64_t *)x, b = *(const int64_t *)y;
    return (a > b) - (a < b);
}

static int run(int argc, char **argv)
{
    if (pb_cli_wants_help(argc, argv)) {
        help(stdout);
        return 0;
    }
    replay_args a;
    if (parse(argc, argv, &a) != 0) {
        fprintf(stderr, "pose-bridge replay: bad or missing arguments\n");
        help(stderr);
        return 2;
    }
    pb_error err = {{0}};
    pb_clip *clip = NULL, *rig_clip = NULL;
    pb_rig_skel *skel = NULL;
    pb_mapping *map = NULL;
    pose_rig *rig = NULL;
    pose_state *st = NULL;
    pb_runner *run = NULL;
    int rc = 1;
    pose_status s = pb_clip_load(a.clip, a.skeleton, &clip, &err);
    if (!s) {
        if (ends_with(a.rig, ".rig")) {
            s = pose_rig_load(a.rig, &rig);
            if (s)
                pb_fail(&err, s, "%s", pose_last_error());
            if (!s)
                s = pb_rig_skel_from_rig(rig, &skel, &err);
            if (!s && (s = pose_state_create(rig, &st)) != POSE_OK)
                pb_fail(&err, s, "%s", pose_last_error());
        } else if (strcmp(a.rig, "self") == 0) {
            s = pb_rig_skel_from_clip(clip, 1.0, &skel, &err);
        } else {
            s = pb_clip_load(a.rig, NULL, &rig_clip, &err);
            if (!s)
                s = pb_rig_skel_from_clip(rig_clip, 1.0, &skel, &err);
        }
    }
    if (!s)
        s = a.map ? pb_mapping_load(a.map, &map, &err) : pb_mapping_identity(&map, &err);
    pb_runner_options o = {.speed = a.speed, .afap = a.afap, .loop = a.loop, .rate_hz = a.rate,
                           .max_ticks = a.frames, .max_media_s = a.duration, .start_s = a.start,
                           .record_path = a.out, .rt_priority = (int)a.rt_priority};
    if (!s)
        s = pb_runner_start_clip(clip, skel, map, &o, &run, &err);
    if (s) {
        fprintf(stderr, "pose-bridge replay: %s\n", err.message);
        goto done;
    }
    int tty = isatty(2) && !a.quiet;
    int64_t period = (int64_t)(1e9 / a.host_rate), next = pb_now_ns(), last_status = 0;
    uint64_t host_frames = 0, applied = 0;
    long clamped = 0;
    for (;;) {
        int fresh;
        const pb_pose *p = pb_runner_latest(run, &fresh);
        if (fresh) {
            applied++;
            if (st) {
                int c = 0;
                if (pb_pose_apply_to_state(p, st, &c) != POSE_OK || pose_apply(st) < 0) {
                    fprintf(stderr, "pose-bridge replay: pose_apply: %s\n", pose_last_error());
                    break;
                }
                clamped += c;
            }
        }
        host_frames++;
        pb_runner_stats stt;
        pb_runner_stats_get(run, &stt);
        int64_t now = pb_now_ns();
        if (!a.quiet && (now - last_status > 250000000 || !stt.running)) {
            fprintf(stderr, "%sframe %6ld/%zu  t %8.3f s  fps %6.1f  lag %6.3f ms (max %.3f)%s", tty ? "\r" : "",
                    stt.frame, clip->frame_count, stt.media_s, stt.fps, stt.lag_ms, stt.lag_max_ms,
                    tty ? "" : "\n");
            last_status = now;
        }
        if (!stt.running)
            break;
        next += period;
        if (!a.afap)
            pb_sleep_until_ns(next);
        else
            pb_runner_wait(run, 1);
    }
    if (tty)
        fputc('\n', stderr);
    pb_runner_stats fin;
    pb_runner_stats_get(run, &fin);
    size_t nl = fin.ticks < 65536 ? (size_t)fin.ticks : 65536;
    int64_t *lags = malloc((nl ? nl : 1) * sizeof *lags);
    nl = lags ? pb_runner_lags(run, lags, nl) : 0;
    double p50 = 0, p99 = 0;
    if (nl) {
        qsort(lags, nl, sizeof *lags, cmp_i64);
        p50 = (double)lags[nl / 2] * 1e-6;
        p99 = (double)lags[(nl * 99) / 100] * 1e-6;
    }
    free(lags);
    s = pb_runner_stop(run, &err);
    run = NULL;
    if (s) {
        fprintf(stderr, "pose-bridge replay: %s\n", err.message);
        goto done;
    }
    if (a.json) {
        printf("{\"clip\": ");
        pb_cli_json_string(stdout, a.clip);
        printf(", \"rig_joints\": %d, \"ticks\": %llu, \"last_frame\": %ld, \"media_s\": %.6f, "
               "\"host_frames\": %llu, \"poses_applied\": %llu, \"clamped\": %ld, \"lag_p50_ms\": %.4f, "
               "\"lag_p99_ms\": %.4f, \"lag_max_ms\": %.4f, \"realtime\": %s, \"state\": \"%s\"",
               skel->joint_count, (unsigned long long)fin.ticks, fin.frame, fin.media_s,
               (unsigned long long)host_frames, (unsigned long long)applied, clamped, p50, p99, fin.lag_max_ms,
               fin.realtime ? "true" : "false", pb_source_state_name(fin.state));
        if (a.out) {
            printf(", \"recording\": ");
            pb_cli_json_string(stdout, a.out);
        }
        printf("}\n");
    }
    rc = 0;
done:
    pb_runner_stop(run, NULL);
    pose_state_free(st);
    pose_rig_free(rig);
    pb_mapping_free(map);
    pb_rig_skel_free(skel);
    pb_clip_free(rig_clip);
    pb_clip_free(clip);
    return rc;
}

const pb_command pb_cmd_replay = {"replay", "play a mocap clip onto a rig in real time (status, recording)", run};
