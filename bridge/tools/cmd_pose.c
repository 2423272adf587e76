/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge pose: where every rig joint is at chosen recorded times of a
 * source, after the source's sample at that time went through the same
 * decoder, mapping and apply path as a host's (pose_bridge_pose_at, then
 * pose_apply): a check of a mapping or a recording against a rig, in
 * numbers. Public API only (pose/bridge.h, pose/pose.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_maps.h"
#include "cli_rig.h"
#include "pose_cli.h"
#include "pose/bridge.h"
#include "pose_bridge_cli.h"

enum { MAX_TIMES = 1024 };

static void help(FILE *f)
{
    fprintf(f,
            "usage: pose-bridge pose SOURCE --rig RIG [--map MAP] [--skeleton ASF] --times T1,T2,... [--json]\n"
            "  SOURCE          a recorded source: .bvh, .amc, .hid (hid-recorder), .log (candump -l),\n"
            "                  or KIND:PATH (pose/bridge.h); HID and CAN recordings need --map\n"
            "  --rig RIG       a .rig file, a .bvh/.asf whose skeleton is the rig, or 'self'\n"
            "  --map MAP       mapping JSON (clips: default joints of the same name)\n"
            "  --skeleton ASF  the .asf of an .amc (default: NN.asf beside NN_MM.amc)\n"
            "  --times LIST    recorded times in seconds, comma-separated (e.g. 0.5,2,7.25)\n"
            "  --json          {\"times\":[{\"t\":0.5,\"held\":false,\"clamped\":0,\"joints\":{\"knee_r\":[x,y,z],...}},...]}\n"
            "                  (clamped: joints whose request a limit changed at that time)\n"
            "Prints every rig joint's world position (the rig's unit: metres for a baked rig, the\n"
            "clip's unit for a skeleton rig) after pose_bridge_pose_at and pose_apply, per time;\n"
            "without --json a table. Exits 1 when a time is past the recording's end.\n");
}

typedef struct pose_args {
    const char *source, *rig, *map, *skeleton;
    double times[MAX_TIMES];
    int ntimes, json;
} pose_args;

static int parse_times(const char *s, pose_args *a)
{
    a->ntimes = 0;
    while (*s) {
        char *e;
        double t = strtod(s, &e);
        if (e == s || !isfinite(t) || t < 0 || a->ntimes >= MAX_TIMES || (*e && *e != ','))
            return -1;
        a->times[a->ntimes++] = t;
        s = *e ? e + 1 : e;
    }
    return a->ntimes > 0 ? 0 : -1;
}

/* 0, 1 after --help, or 2 (reported). */
static int parse(int argc, char **argv, pose_args *a)
{
    enum { OPT_RIG = POSE_CLI_LONG_ONLY, OPT_MAP, OPT_SKELETON, OPT_TIMES, OPT_JSON };
    static const struct option options[] = {
        {"rig", required_argument, NULL, OPT_RIG},   {"map", required_argument, NULL, OPT_MAP},
        {"skeleton", required_argument, NULL, OPT_SKELETON}, {"times", required_argument, NULL, OPT_TIMES},
        {"json", no_argument, NULL, OPT_JSON},       {"help", no_argument, NULL, 'h'},
        {0}};
    memset(a, 0, sizeof *a);
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge pose", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            help(stdout);
            return 1;
        case OPT_RIG:
            a->rig = cli.value;
            break;
        case OPT_MAP:
            a->map = cli.value;
            break;
        case OPT_SKELETON:
            a->skeleton = cli.value;
            break;
        case OPT_TIMES:
            if (parse_times(cli.value, a) != 0)
                return pose_cli_error(&cli, "--times: expected up to %d seconds as 0.5,2,7.25, got '%s'", MAX_TIMES,
                                      cli.value), 2;
            break;
        case OPT_JSON:
            a->json = 1;
            break;
        case POSE_CLI_ARGUMENT:
            if (a->source)
                return pose_cli_error(&cli, "unexpected argument '%s' (one source only)", cli.value), 2;
            a->source = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    if (!a->source || !a->rig || a->ntimes == 0)
        return pose_cli_error(&cli, "SOURCE, --rig and --times are required"), 2;
    return 0;
}

static void print_time(const pose_args *a, const pose_rig *rig, const pose_state *st, double t,
                       const pose_bridge_frame *fr, int first)
{
    size_t n = pose_rig_joint_count(rig);
    if (a->json) {
        printf("%s{\"t\":%.6g,\"held\":%s,\"clamped\":%d,\"joints\":{", first ? "" : ",", t,
               fr->held ? "true" : "false", fr->clamped);
    } else {
        printf("t = %.3f s%s", t, fr->held ? "  (held: the source was silent or faulty)" : "");
        if (fr->clamped)
            printf("  (%d joints clamped by their limits)", fr->clamped);
        putchar('\n');
    }
    for (size_t j = 0; j < n; j++) {
        pose_joint_info info;
        pose_transform w;
        pose_rig_joint_info(rig, (int)j, &info);
        pose_joint_world(st, (int)j, &w);
        const float *p = w.translation;
        if (a->json) {
            printf("%s", j ? "," : "");
            pb_cli_json_string(stdout, info.name);
            printf(":[%.6f,%.6f,%.6f]", p[0], p[1], p[2]);
        } else {
            printf("  %-24s %11.6f %11.6f %11.6f\n", info.name, p[0], p[1], p[2]);
        }
    }
    if (a->json)
        printf("}}");
}

static int run(int argc, char **argv)
{
    pose_args a;
    int parsed = parse(argc, argv, &a);
    if (parsed != 0)
        return parsed == 1 ? 0 : 2;
    char err[512];
    pose_rig *rig = NULL;
    pose_state *st = NULL;
    pose_bridge *br = NULL;
    int rc = 1;
    if (pb_cli_rig_load(a.rig, a.source, a.skeleton, &rig, err, sizeof err) < 0) {
        fprintf(stderr, "pose-bridge pose: %s\n", err);
        return 1;
    }
    pose_bridge_options o = {.size = sizeof o, .map_path = a.map, .skeleton = a.skeleton, .play = POSE_BRIDGE_MANUAL};
    if (pose_state_create(rig, &st) < 0) {
        fprintf(stderr, "pose-bridge pose: %s\n", pose_last_error());
        goto done;
    }
    if (pose_bridge_open(a.source, rig, &o, &br) < 0) {
        fprintf(stderr, "pose-bridge pose: %s\n", pose_last_error());
        if (!a.map)
            pb_cli_hint_maps(a.source);
        goto done;
    }
    for (size_t i = 0; i < pose_bridge_warning_count(br); i++)
        fprintf(stderr, "warning: %s\n", pose_bridge_warning(br, i));
    /* Times past the end fail before anything is printed (clips: up to the bridge thread's last tick). */
    pose_bridge_status bs = {.size = sizeof bs};
    if (pose_bridge_status_get(br, &bs) < 0) {
        fprintf(stderr, "pose-bridge pose: %s\n", pose_last_error());
        goto done;
    }
    for (int i = 0; i < a.ntimes; i++) {
        if (a.times[i] > bs.duration_s + bs.frame_time_s + 1e-6) {
            fprintf(stderr, "pose-bridge pose: %s: %.3f s is past the end of the recording (%.3f s)\n", a.source,
                    a.times[i], bs.duration_s);
            goto done;
        }
    }
    if (a.json) {
        printf("{\"source\":");
        pb_cli_json_string(stdout, a.source);
        printf(",\"times\":[");
    }
    for (int i = 0; i < a.ntimes; i++) {
        pose_bridge_frame fr;
        if (pose_bridge_pose_at(br, a.times[i], st, &fr) < 0 || pose_apply(st) < 0) {
            fprintf(stderr, "pose-bridge pose: %s\n", pose_last_error());
            goto done;
        }
        print_time(&a, rig, st, a.times[i], &fr, i == 0);
    }
    if (a.json)
        printf("]}\n");
    rc = 0;
done:
    pose_bridge_close(br);
    pose_state_free(st);
    pose_rig_free(rig);
    return rc;
}

const pb_command pb_cmd_pose = {"pose", "world positions of every rig joint at recorded times of a source (JSON)",
                                run};
