/* SPDX-License-Identifier: Apache-2.0
 * The calibration commands (hid-calibrate, can-calibrate) over any source.
 * A lab calibrates its mannequin in two steps:
 *   --neutral            the mannequin stands in the anatomical neutral
 *                        posture: every mapped channel's reading becomes 0
 *                        degrees at once, each keeping its gain;
 *   --channel NAME       one joint held at two known angles (default 0 and
 *                        90): the channel's offset and gain.
 * Live, the operator holds each posture and presses Enter; from a recording,
 * --at gives the recorded times of the postures. */
#include "cli_calibrate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "calibrate.h"
#include "pose_bridge_cli.h"
#include "pose_cli.h"

static void usage(FILE *f, const pb_cli_calibrate_kind *k)
{
    fprintf(f,
            "usage: pose-bridge %s SOURCE --map MAP.json --neutral [--at T] [--samples N] [--json]\n"
            "       pose-bridge %s SOURCE --map MAP.json (--channel NAME | --entry N)\n"
            "                                [--angles A0,A1] [--at T0,T1] [--samples N] [--json]\n"
            "SOURCE: %s.\n"
            "--neutral: hold the mannequin in the anatomical neutral posture (standing, arms at the\n"
            "  sides) and press Enter: every entry of MAP reads 0 degrees there, keeping its gain.\n"
            "--channel/--entry: hold the joint at A0 degrees (default 0), press Enter; at A1 (default\n"
            "  90), press Enter: the entry's offset and gain.\n"
            "The mean over N samples (default 50) at each posture is written into the entries'\n"
            "\"calibration\" (the file is replaced atomically). --at (recordings only) measures at\n"
            "recorded times instead of waiting for Enter.\n",
            k->command, k->command, k->sources);
}

typedef struct calib_args {
    const char *spec, *map, *name;
    int entry, samples, json, have_at, neutral;
    double angle[2], at[2];
} calib_args;

/* 0, 1 after --help, or 2 (reported). */
static int parse_args(int argc, char **argv, const pb_cli_calibrate_kind *k, calib_args *a)
{
    enum { OPT_MAP = POSE_CLI_LONG_ONLY, OPT_CHANNEL, OPT_ENTRY, OPT_SAMPLES, OPT_NEUTRAL, OPT_ANGLES, OPT_AT,
           OPT_JSON };
    static const struct option options[] = {
        {"map", required_argument, NULL, OPT_MAP},         {"channel", required_argument, NULL, OPT_CHANNEL},
        {"entry", required_argument, NULL, OPT_ENTRY},     {"samples", required_argument, NULL, OPT_SAMPLES},
        {"neutral", no_argument, NULL, OPT_NEUTRAL},       {"angles", required_argument, NULL, OPT_ANGLES},
        {"at", required_argument, NULL, OPT_AT},           {"json", no_argument, NULL, OPT_JSON},
        {"help", no_argument, NULL, 'h'},                  {0}};
    char tool[64];
    snprintf(tool, sizeof tool, "pose-bridge %s", k->command);
    *a = (calib_args){.entry = -1, .samples = 50, .angle = {0, 90}};
    pose_cli cli;
    pose_cli_begin(&cli, tool, argc, argv, options);
    long n;
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            usage(stdout, k);
            return 1;
        case OPT_MAP:
            a->map = cli.value;
            break;
        case OPT_CHANNEL:
            a->name = cli.value;
            break;
        case OPT_ENTRY:
            if (pose_cli_long(&cli, 0, 100000, &n) < 0)
                return 2;
            a->entry = (int)n;
            break;
        case OPT_SAMPLES:
            if (pose_cli_long(&cli, 1, 1000000, &n) < 0)
                return 2;
            a->samples = (int)n;
            break;
        case OPT_NEUTRAL:
            a->neutral = 1;
            break;
        case OPT_ANGLES:
            if (sscanf(cli.value, "%lf,%lf", &a->angle[0], &a->angle[1]) != 2) {
                pose_cli_error(&cli, "--angles wants A0,A1");
                return 2;
            }
            break;
        case OPT_AT:
            a->have_at = sscanf(cli.value, "%lf,%lf", &a->at[0], &a->at[1]);
            if (a->have_at < 1) {
                pose_cli_error(&cli, "--at wants T0,T1 (or T with --neutral) in seconds");
                return 2;
            }
            break;
        case OPT_JSON:
            a->json = 1;
            break;
        case POSE_CLI_ARGUMENT:
            if (a->spec) {
                pose_cli_error(&cli, "unexpected argument '%s' (one source only)", cli.value);
                return 2;
            }
            a->spec = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    const int one = a->name || a->entry >= 0;
    if (!a->spec || !a->map || one == a->neutral) {
        pose_cli_error(&cli, "SOURCE, --map and one of --neutral, --channel, --entry are required");
        return 2;
    }
    if (one && a->angle[0] == a->angle[1]) {
        pose_cli_error(&cli, "--angles: the two angles must differ");
        return 2;
    }
    if (one && a->have_at == 1) {
        pose_cli_error(&cli, "--at: --channel and --entry measure at two times, T0,T1");
        return 2;
    }
    return 0;
}

/* Bring the source to the posture: seek to a recorded time, or wait for Enter. */
static int reach_posture(pb_source *src, const calib_args *a, int k, const char *what, const char *command)
{
    if (a->have_at) {
        if (!src->ops->seek) {
            fprintf(stderr, "pose-bridge %s: --at needs a recording\n", command);
            return -1;
        }
        if (pb_source_seek(src, (int64_t)(a->at[k] * 1e9)) != 0) {
            fprintf(stderr, "pose-bridge %s: cannot seek to %g s\n", command, a->at[k]);
            return -1;
        }
        return 0;
    }
    fprintf(stderr, "Hold %s and press Enter... ", what);
    char line[64];
    if (!fgets(line, sizeof line, stdin)) {
        fprintf(stderr, "\npose-bridge %s: no input; mapping unchanged\n", command);
        return -1;
    }
    pb_update skip;
    while (pb_source_read(src, &skip, 0) == 1) {
        /* drop samples queued while the operator moved the joint */
    }
    return 0;
}

static int calibrate_neutral(pb_source *src, const calib_args *a, const pb_cli_calibrate_kind *k)
{
    pb_error err;
    pb_mapping *map = NULL;
    if (pb_mapping_load(a->map, &map, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge %s: %s\n", k->command, err.message);
        return 1;
    }
    int rc = 1, written = 0;
    double *raw = calloc(map->channel_count > 0 ? (size_t)map->channel_count : 1, sizeof *raw);
    if (!raw || reach_posture(src, a, 0, "the mannequin in the neutral posture (standing, arms at the sides)",
                              k->command) < 0)
        goto done;
    if (pb_calibrate_measure_entries(src, map, a->samples, 2000, raw, &err) != POSE_OK ||
        pb_calibrate_write_neutral(a->map, map, raw, &written, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge %s: %s\n", k->command, err.message);
        goto done;
    }
    if (a->json) {
        printf("{\"map\":");
        pb_cli_json_string(stdout, a->map);
        printf(",\"neutral\":[");
    }
    for (int i = 0; i < map->channel_count; i++) {
        const pb_map_channel *m = &map->channels[i];
        const char *ch = m->channel[0] ? m->channel : "(usage)";
        if (a->json) {
            printf("%s{\"entry\":%d,\"channel\":", i ? "," : "", i);
            pb_cli_json_string(stdout, ch);
            printf(isfinite(raw[i]) ? ",\"raw\":%.9g}" : ",\"raw\":null}", raw[i]);
        } else if (isfinite(raw[i])) {
            printf("  %-20s %s: neutral reads %.4f\n", ch, m->joint, raw[i]);
        } else {
            printf("  %-20s %s: not in the source, unchanged\n", ch, m->joint);
        }
    }
    if (a->json)
        printf("],\"written\":%d}\n", written);
    else
        printf("%s: %d of %d entries read 0 degrees in the neutral posture\n", a->map, written, map->channel_count);
    rc = 0;
done:
    free(raw);
    pb_mapping_free(map);
    return rc;
}

static int find_channel(const pb_source *src, const char *name, uint32_t usage, int usage_index)
{
    int seen = 0;
    for (size_t i = 0; i < src->channel_count; i++) {
        if (name[0] ? strcmp(src->channels[i].name, name) == 0
                    : src->channels[i].usage == usage && seen++ == usage_index)
            return (int)i;
    }
    return -1;
}

static int calibrate_one(pb_source *src, const calib_args *a, const pb_cli_calibrate_kind *k)
{
    pb_error err;
    char chname[64];
    uint32_t usage_id;
    int usage_index;
    if (pb_calibrate_entry(a->map, a->name, a->entry, chname, sizeof chname, &usage_id, &usage_index, &err) !=
        POSE_OK) {
        fprintf(stderr, "pose-bridge %s: %s\n", k->command, err.message);
        return 1;
    }
    int ch = find_channel(src, chname, usage_id, usage_index);
    if (ch < 0) {
        fprintf(stderr, "pose-bridge %s: %s has no channel %s\n", k->command, a->spec,
                chname[0] ? chname : "with that usage");
        return 1;
    }
    double raw[2];
    for (int i = 0; i < 2; i++) {
        char what[128];
        snprintf(what, sizeof what, "%s at %g degrees", src->channels[ch].name, a->angle[i]);
        if (reach_posture(src, a, i, what, k->command) < 0)
            return 1;
        if (pb_calibrate_measure(src, (uint32_t)ch, a->samples, 2000, &raw[i], &err) != POSE_OK) {
            fprintf(stderr, "pose-bridge %s: %s\n", k->command, err.message);
            return 1;
        }
        if (!a->json)
            fprintf(stderr, "  %s = %.4f %s at %g degrees\n", src->channels[ch].name, raw[i], src->channels[ch].unit,
                    a->angle[i]);
    }
    if (pb_calibrate_write(a->map, a->name, a->entry, raw, a->angle, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge %s: %s\n", k->command, err.message);
        return 1;
    }
    if (a->json) {
        printf("{\"map\":");
        pb_cli_json_string(stdout, a->map);
        printf(",\"channel\":");
        pb_cli_json_string(stdout, src->channels[ch].name);
        printf(",\"raw\":[%.9g,%.9g],\"deg\":[%.9g,%.9g]}\n", raw[0], raw[1], a->angle[0], a->angle[1]);
    } else {
        printf("%s: %s calibrated: raw %.4f -> %g deg, raw %.4f -> %g deg\n", a->map, src->channels[ch].name, raw[0],
               a->angle[0], raw[1], a->angle[1]);
    }
    return 0;
}

int pb_cli_calibrate(int argc, char **argv, const pb_cli_calibrate_kind *k)
{
    calib_args a;
    int rc = parse_args(argc, argv, k, &a);
    if (rc)
        return rc == 1 ? 0 : rc;
    pb_error err;
    pb_source *src = NULL;
    if (k->open(a.spec, a.map, a.have_at, &src, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge %s: %s\n", k->command, err.message);
        return 1;
    }
    rc = a.neutral ? calibrate_neutral(src, &a, k) : calibrate_one(src, &a, k);
    pb_source_destroy(src);
    return rc;
}
