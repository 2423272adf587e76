/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge replay: play a clip or a HID/CAN recording onto a rig in real
 * time through the public API (pose/bridge.h), as a host would: the bridge
 * thread plays the source, the main thread is the host's frame loop (60 Hz)
 * and applies the newest pose without waiting: pose_apply with --method's
 * skinning or POSE_FEM, or pose_step (cli_replay_method.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli_maps.h"
#include "cli_replay_method.h"
#include "cli_rig.h"
#include "pose_cli.h"
#include "pose/bridge.h"
#include "pose_bridge_cli.h"

static void help(FILE *f)
{
    fprintf(f,
            "usage: pose-bridge replay SOURCE --rig RIG [--map MAP] [--skeleton ASF] [options]\n"
            "  SOURCE          a clip (.bvh, .amc: ASF from --skeleton, or NN.asf beside NN_MM.amc),\n"
            "                  a hid-recorder file (.hid) or a candump -l log (.log); these need --map;\n"
            "                  or any source string of pose/bridge.h (hid:VID:PID, can0 ...)\n"
            "  --rig RIG       a .rig file (poses a pose_state each host frame that brings a fresh pose),\n"
            "                  a .bvh/.asf whose skeleton is the rig, or 'self' (the clip's own skeleton)\n"
            "  --map MAP       mapping JSON (clips: default joints of the same name)\n"
            "  --method M      what each fresh pose runs: lbs (default), dqs, cor or fem: pose_apply with\n"
            "                  that method (fem: POSE_FEM, the quasi-static refinement); dynamics:\n"
            "                  pose_step on the recording's clock, by the recorded time since the last\n"
            "                  pose (steps of at most 1/30 s; a gap over 1 s or backwards restarts\n"
            "                  the simulation at rest). fem and dynamics need a rig baked with FEM\n"
            "                  data (pose-bake's default)\n"
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
            "  --json          print a JSON summary on stdout (with the method, its updates and mean wall\n"
            "                  time; fem: mean CG iterations; dynamics: steps, simulated seconds,\n"
            "                  last and peak kinetic energy)\n"
            "  --quiet         no status line\n"
            "Status line (stderr): time, frame (clips), poses per second, lag of the bridge thread's\n"
            "wake-ups (clips), the source's state.\n");
}

typedef struct replay_args {
    const char *source, *skeleton, *rig, *map, *out;
    pb_replay_method method;
    double speed, rate, host_rate, duration, start;
    long frames, rt_priority;
    int afap, loop, json, quiet;
} replay_args;

/* 0, 1 after --help, or 2 (reported). */
static int parse(int argc, char **argv, replay_args *a)
{
    enum { OPT_SKELETON = POSE_CLI_LONG_ONLY, OPT_RIG, OPT_MAP, OPT_OUT, OPT_SPEED, OPT_RATE, OPT_HOST_RATE,
           OPT_DURATION, OPT_START, OPT_FRAMES, OPT_RT_PRIORITY, OPT_AFAP, OPT_LOOP, OPT_JSON, OPT_QUIET,
           OPT_METHOD };
    static const struct option options[] = {
        {"skeleton", required_argument, NULL, OPT_SKELETON}, {"rig", required_argument, NULL, OPT_RIG},
        {"map", required_argument, NULL, OPT_MAP},           {"out", required_argument, NULL, OPT_OUT},
        {"speed", required_argument, NULL, OPT_SPEED},       {"rate", required_argument, NULL, OPT_RATE},
        {"host-rate", required_argument, NULL, OPT_HOST_RATE}, {"duration", required_argument, NULL, OPT_DURATION},
        {"start", required_argument, NULL, OPT_START},       {"frames", required_argument, NULL, OPT_FRAMES},
        {"rt-priority", required_argument, NULL, OPT_RT_PRIORITY}, {"afap", no_argument, NULL, OPT_AFAP},
        {"loop", no_argument, NULL, OPT_LOOP},               {"json", no_argument, NULL, OPT_JSON},
        {"quiet", no_argument, NULL, OPT_QUIET},             {"method", required_argument, NULL, OPT_METHOD},
        {"help", no_argument, NULL, 'h'},
        {0}};
    memset(a, 0, sizeof *a);
    a->speed = 1.0;
    a->host_rate = 60.0;
    pb_replay_method_parse(NULL, &a->method);
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge replay", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;) {
        int bad = 0;
        switch (c) {
        case 'h':
            help(stdout);
            return 1;
        case OPT_SKELETON:
            a->skeleton = cli.value;
            break;
        case OPT_RIG:
            a->rig = cli.value;
            break;
        case OPT_MAP:
            a->map = cli.value;
            break;
        case OPT_METHOD:
            if (pb_replay_method_parse(cli.value, &a->method) < 0)
                bad = pose_cli_error(&cli, "--method: expected " PB_REPLAY_METHODS ", got '%s'", cli.value);
            break;
        case OPT_OUT:
            a->out = cli.value;
            break;
        case OPT_SPEED:
            bad = pose_cli_double(&cli, 1e-6, 1e6, &a->speed);
            break;
        case OPT_RATE:
            bad = pose_cli_double(&cli, 0, 1e6, &a->rate);
            break;
        case OPT_HOST_RATE:
            bad = pose_cli_double(&cli, 1e-3, 1e6, &a->host_rate);
            break;
        case OPT_DURATION:
            bad = pose_cli_double(&cli, 0, 1e9, &a->duration);
            break;
        case OPT_START:
            bad = pose_cli_double(&cli, 0, 1e9, &a->start);
            break;
        case OPT_FRAMES:
            bad = pose_cli_long(&cli, 0, 1000000000, &a->frames);
            break;
        case OPT_RT_PRIORITY:
            bad = pose_cli_long(&cli, 1, 99, &a->rt_priority);
            break;
        case OPT_AFAP:
            a->afap = 1;
            break;
        case OPT_LOOP:
            a->loop = 1;
            break;
        case OPT_JSON:
            a->json = 1;
            break;
        case OPT_QUIET:
            a->quiet = 1;
            break;
        case POSE_CLI_ARGUMENT:
            if (a->source)
                bad = pose_cli_error(&cli, "unexpected argument '%s' (one source only)", cli.value);
            a->source = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
        if (bad)
            return 2;
    }
    if (!a->source || !a->rig) {
        pose_cli_error(&cli, "SOURCE and --rig are required");
        return 2;
    }
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
    pb_replay_method_json(&a->method, stdout);
    printf("}\n");
}

static int run(int argc, char **argv)
{
    replay_args a;
    int parsed = parse(argc, argv, &a);
    if (parsed != 0)
        return parsed == 1 ? 0 : 2;
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
    if (pb_replay_method_start(&a.method, st) < 0) {
        fprintf(stderr, "pose-bridge replay: --method %s: %s\n", a.method.name, pose_last_error());
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
        if (!a.map)
            pb_cli_hint_maps(a.source);
        goto done;
    }
    /* The files' warnings, then those the bridge thread finds while playing (a time jump ...). */
    size_t warned = 0;
    for (; warned < pose_bridge_warning_count(br); warned++)
        fprintf(stderr, "warning: %s\n", pose_bridge_warning(br, warned));
    int tty = isatty(2) && !a.quiet;
    double period = 1.0 / a.host_rate, next = now_s(), last_status = 0, fps_t = next;
    unsigned long long host_frames = 0, applied = 0, held = 0, fps_poses = 0;
    long clamped = 0;
    double fps = 0;
    pose_bridge_status bs = {.size = sizeof bs};
    for (;;) {
        int ended = pose_bridge_wait(br, 0);
        pose_bridge_frame fr;
        if (pose_bridge_apply(br, st, &fr) < 0 || (fr.fresh && pb_replay_method_update(&a.method, st, &fr) < 0)) {
            fprintf(stderr, "pose-bridge replay: %s\n", pose_last_error());
            goto done;
        }
        for (; warned < pose_bridge_warning_count(br); warned++)
            fprintf(stderr, "%swarning: %s\n", tty ? "\n" : "", pose_bridge_warning(br, warned));
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
