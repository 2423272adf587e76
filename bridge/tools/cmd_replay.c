/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge replay: play a clip or a HID/CAN recording onto a rig in real
 * time through the public API (pose/bridge.h), as a host would: the bridge
 * thread plays the source, the main thread is the host's frame loop (60 Hz)
 * and applies the newest pose without waiting. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli_rig.h"
#include "pose/bridge.h"
#include "pose_bridge_cli.h"

static void help(FILE *f)
{
    fprintf(f,
            "usage: pose-bridge replay SOURCE --rig RIG [--map MAP] [--skeleton ASF] [options]\n"
            "  SOURCE          a clip (.bvh, .amc: ASF from --skeleton, or NN.asf beside NN_MM.amc),\n"
            "                  a hid-recorder file (.hid) or a candump -l log (.log); these need --map;\n"
            "                  or any source string of pose/bridge.h (hid:VID:PID, can0 ...)\n"
            "  --rig RIG       a .rig file (poses a pose_state and runs pose_apply each host frame),\n"
            "                  a .bvh/.asf whose skeleton is the rig, or 'self' (the clip's own skeleton)\n"
            "  --map MAP       mapping JSON (clips: default joints of the same name)\n"
            "  --speed X       playback speed (default 1)\n"
            "  --afap          as fast as possible (no real-time pacing)\n"
            "  --loop          wrap at the end\n"
            "  --rate HZ       clips: bridge publish rate (default: the clip's; between frames is slerped)\n"
            "  --host-rate HZ  the host frame loop's rate (default 60)\n"
            "  --frames N      stop after N published poses\n"
            "  --duration S    stop after S seconds of recorded time\n"
            "  --start S       start at recorded time S\n"
            "  --out FILE.bvh  record the published joint angles (flushed every pose)\n"
            "  --rt-priority N run the bridge thread SCHED_FIFO at priority N when allowed\n"
            "  --json          print a JSON summary on stdout\n"
            "  --quiet         no status line\n"
            "Status line (stderr): time, frame (clips), poses per second, lag of the bridge thread's\n"
            "wake-ups (clips), the source's state.\n");
}

typedef struct replay_args {
    const char *source, *skeleton, *rig, *map, *out;
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
        else if (s[0] != '-' && !a->source)
            a->source = s;
        else
            return -1;
#undef NUM
    }
    if (!a->source || !a->rig || !(a->speed > 0) || !(a->host_rate > 0))
        return -1;
    return 0;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void sleep_until(double t)
{
    double d = t - now_s();
    if (d <= 0)
        return;
    struct timespec ts = {(time_t)d, (long)((d - floor(d)) * 1e9)};
    nanosleep(&ts, NULL);
}

static void status_line(const pose_bridge_status *st, double fps, int tty)
{
    if (st->frame_count >= 0)
        fprintf(stderr, "%sframe %6ld/%ld  t %8.3f s  fps %6.1f  lag max %.3f ms  %s%s", tty ? "\r" : "",
                st->frame, st->frame_count, st->media_s, fps, st->lag_max_ms,
                pose_bridge_state_name(st->state), tty ? "" : "\n");
    else
        fprintf(stderr, "%st %8.3f s  poses %8llu  fps %6.1f  drops %llu  %s%s", tty ? "\r" : "", st->media_s,
                (unsigned long long)st->poses, fps, (unsigned long long)st->drops,
                pose_bridge_state_name(st->state), tty ? "" : "\n");
}

static void print_json(const replay_args *a, const pose_rig *rig, const pose_bridge_status *st,
                       unsigned long long host_frames, unsigned long long applied, unsigned long long held,
                       long clamped)
{
    printf("{\"clip\": ");
    pb_cli_json_string(stdout, a->source);
    printf(", \"kind\": \"%s\", \"rig_joints\": %zu, \"ticks\": %llu, \"last_frame\": %ld, \"media_s\": %.6f, "
           "\"host_frames\": %llu, \"poses_applied\": %llu, \"held_frames\": %llu, \"clamped\": %ld, "
           "\"samples\": %llu, \"drops\": %llu, \"lag_p50_ms\": %.4f, \"lag_p99_ms\": %.4f, \"lag_max_ms\": %.4f, "
           "\"realtime\": %s, \"state\": \"%s\"",
           st->kind, pose_rig_joint_count(rig), (unsigned long long)st->poses, st->frame, st->media_s, host_frames,
           applied, held, clamped, (unsigned long long)st->samples, (unsigned long long)st->drops, st->lag_p50_ms,
           st->lag_p99_ms, st->lag_max_ms, st->realtime ? "true" : "false", pose_bridge_state_name(st->state));
    if (st->fault[0]) {
        printf(", \"fault\": ");
        pb_cli_json_string(stdout, st->fault);
    }
    if (a->out) {
        printf(", \"recording\": ");
        pb_cli_json_string(stdout, a->out);
    }
    printf("}\n");
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
    char err[512];
    pose_rig *rig = NULL;
    pose_state *st = NULL;
    pose_bridge *br = NULL;
    int rc = 1;
    if (pb_cli_rig_load(a.rig, a.source, a.skeleton, &rig, err, sizeof err) < 0) {
        fprintf(stderr, "pose-bridge replay: %s\n", err);
        return 1;
    }
    if (pose_state_create(rig, &st) < 0) {
        fprintf(stderr, "pose-bridge replay: %s\n", pose_last_error());
        goto done;
    }
    pose_bridge_options o = {
        .size = sizeof o,
        .map_path = a.map,
        .skeleton = a.skeleton,
        .play = a.afap ? POSE_BRIDGE_AS_FAST_AS_POSSIBLE : POSE_BRIDGE_REALTIME,
        .speed = a.speed,
        .loop = a.loop,
        .start_s = a.start,
        .end_s = a.duration > 0 ? a.start + a.duration : 0.0,
        .max_poses = a.frames,
        .rate_hz = a.rate,
        .rt_priority = (int)a.rt_priority,
        .record_path = a.out,
    };
    if (pose_bridge_open(a.source, rig, &o, &br) < 0) {
        fprintf(stderr, "pose-bridge replay: %s\n", pose_last_error());
        goto done;
    }
    for (size_t i = 0; i < pose_bridge_warning_count(br); i++)
        fprintf(stderr, "warning: %s\n", pose_bridge_warning(br, i));
    int tty = isatty(2) && !a.quiet;
    double period = 1.0 / a.host_rate, next = now_s(), last_status = 0, fps_t = next;
    unsigned long long host_frames = 0, applied = 0, held = 0, fps_poses = 0;
    long clamped = 0;
    double fps = 0;
    pose_bridge_status bs = {.size = sizeof bs};
    for (;;) {
        int ended = pose_bridge_wait(br, 0);
        pose_bridge_frame fr;
        if (pose_bridge_apply(br, st, &fr) < 0 || (fr.fresh && pose_apply(st) < 0)) {
            fprintf(stderr, "pose-bridge replay: %s\n", pose_last_error());
            goto done;
        }
        applied += fr.fresh != 0;
        held += fr.held != 0;
        clamped += fr.clamped;
        host_frames++;
        double now = now_s();
        if (!a.quiet && (now - last_status > 0.25 || ended)) {
            pose_bridge_status_get(br, &bs);
            fps = now > fps_t ? (double)(bs.poses - fps_poses) / (now - fps_t) : 0.0;
            fps_t = now;
            fps_poses = bs.poses;
            status_line(&bs, fps, tty);
            last_status = now;
        }
        if (ended)
            break;
        next += period;
        if (a.afap)
            pose_bridge_wait(br, 1);
        else
            sleep_until(next);
    }
    if (tty)
        fputc('\n', stderr);
    if (pose_bridge_status_get(br, &bs) < 0) {
        fprintf(stderr, "pose-bridge replay: %s\n", pose_last_error());
        goto done;
    }
    if (bs.state == POSE_BRIDGE_FAULT) { /* the bridge thread stopped (a recording it could not write) */
        fprintf(stderr, "pose-bridge replay: %s\n", bs.fault);
        goto done;
    }
    if (a.json)
        print_json(&a, rig, &bs, host_frames, applied, held, clamped);
    rc = 0;
done:
    pose_bridge_close(br);
    pose_state_free(st);
    pose_rig_free(rig);
    return rc;
}

const pb_command pb_cmd_replay = {"replay", "play a clip or a HID/CAN recording onto a rig in real time (status, recording)",
                                  run};
