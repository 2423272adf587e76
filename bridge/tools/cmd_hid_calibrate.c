/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge hid-calibrate: two-point calibration of one mapping entry.
 * Hold the joint at the first angle, press Enter, hold it at the second,
 * press Enter: the channel's mean over a few reports at each position
 * becomes {"raw": [r0, r1], "deg": [a0, a1]} in the mapping file. */
#include <stdlib.h>
#include <string.h>

#include "hid_calibrate.h"
#include "hid_open.h"
#include "pose_bridge_cli.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: pose-bridge hid-calibrate SOURCE --map MAP.json (--channel NAME | --entry N)\n"
               "                                [--angles A0,A1] [--samples N] [--at T0,T1] [--json]\n"
               "Hold the joint at A0 degrees (default 0), press Enter; hold it at A1 (default 90), press\n"
               "Enter. The channel's mean over N reports (default 50) at each position is written into\n"
               "the entry's \"calibration\". --at T0,T1 (recordings only) measures at recorded times\n"
               "instead of waiting for Enter.\n");
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

static int run(int argc, char **argv)
{
    if (pb_cli_wants_help(argc, argv)) {
        usage(stdout);
        return 0;
    }
    const char *spec = NULL, *map = NULL, *name = NULL;
    int entry = -1, samples = 50, json = 0, have_at = 0;
    double angle[2] = {0, 90}, at[2] = {0, 0};
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--map") == 0 && i + 1 < argc)
            map = argv[++i];
        else if (strcmp(argv[i], "--channel") == 0 && i + 1 < argc)
            name = argv[++i];
        else if (strcmp(argv[i], "--entry") == 0 && i + 1 < argc)
            entry = atoi(argv[++i]);
        else if (strcmp(argv[i], "--samples") == 0 && i + 1 < argc)
            samples = atoi(argv[++i]);
        else if (strcmp(argv[i], "--angles") == 0 && i + 1 < argc) {
            if (sscanf(argv[++i], "%lf,%lf", &angle[0], &angle[1]) != 2) {
                fprintf(stderr, "pose-bridge hid-calibrate: --angles wants A0,A1\n");
                return 2;
            }
        } else if (strcmp(argv[i], "--at") == 0 && i + 1 < argc) {
            if (sscanf(argv[++i], "%lf,%lf", &at[0], &at[1]) != 2) {
                fprintf(stderr, "pose-bridge hid-calibrate: --at wants T0,T1 in seconds\n");
                return 2;
            }
            have_at = 1;
        } else if (strcmp(argv[i], "--json") == 0)
            json = 1;
        else if (argv[i][0] != '-' && !spec)
            spec = argv[i];
        else {
            fprintf(stderr, "pose-bridge hid-calibrate: unexpected argument '%s'\n", argv[i]);
            usage(stderr);
            return 2;
        }
    }
    if (!spec || !map || (!name && entry < 0) || samples < 1 || angle[0] == angle[1]) {
        usage(stderr);
        return 2;
    }
    pb_error err;
    char chname[64];
    uint32_t usage_id;
    int usage_index;
    if (pb_calibrate_entry(map, name, entry, chname, sizeof chname, &usage_id, &usage_index, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge hid-calibrate: %s\n", err.message);
        return 1;
    }
    pb_hid_replay_options opt = {.as_fast_as_possible = have_at};
    pb_source *src;
    if (pb_hid_open(spec, &opt, &src, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge hid-calibrate: %s\n", err.message);
        return 1;
    }
    int rc = 1;
    int ch = find_channel(src, chname, usage_id, usage_index);
    double raw[2];
    if (ch < 0) {
        fprintf(stderr, "pose-bridge hid-calibrate: %s has no channel %s\n", spec, chname[0] ? chname : "with that usage");
        goto done;
    }
    if (have_at && !src->ops->seek) {
        fprintf(stderr, "pose-bridge hid-calibrate: --at needs a recording\n");
        goto done;
    }
    for (int k = 0; k < 2; k++) {
        if (have_at) {
            if (pb_source_seek(src, (int64_t)(at[k] * 1e9)) != 0) {
                fprintf(stderr, "pose-bridge hid-calibrate: cannot seek to %g s\n", at[k]);
                goto done;
            }
        } else {
            fprintf(stderr, "Hold %s at %g degrees and press Enter... ", src->channels[ch].name, angle[k]);
            char line[64];
            if (!fgets(line, sizeof line, stdin)) {
                fprintf(stderr, "\npose-bridge hid-calibrate: no input; mapping unchanged\n");
                goto done;
            }
            pb_update skip;
            while (pb_source_read(src, &skip, 0) == 1) {
                /* drop reports queued while the user moved the joint */
            }
        }
        if (pb_calibrate_measure(src, (uint32_t)ch, samples, 2000, &raw[k], &err) != POSE_OK) {
            fprintf(stderr, "pose-bridge hid-calibrate: %s\n", err.message);
            goto done;
        }
        if (!json)
            fprintf(stderr, "  %s = %.4f %s at %g degrees\n", src->channels[ch].name, raw[k], src->channels[ch].unit,
                    angle[k]);
    }
    if (pb_calibrate_write(map, name, entry, raw, angle, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge hid-calibrate: %s\n", err.message);
        goto done;
    }
    if (json) {
        printf("{\"map\":");
        pb_cli_json_string(stdout, map);
        printf(",\"channel\":");
        pb_cli_json_string(stdout, src->channels[ch].name);
        printf(",\"raw\":[%.9g,%.9g],\"deg\":[%.9g,%.9g]}\n", raw[0], raw[1], angle[0], angle[1]);
    } else {
        printf("%s: %s calibrated: raw %.4f -> %g deg, raw %.4f -> %g deg\n", map, src->channels[ch].name, raw[0],
               angle[0], raw[1], angle[1]);
    }
    rc = 0;
done:
    pb_source_destroy(src);
    return rc;
}

const pb_command pb_cmd_hid_calibrate = {"hid-calibrate", "two-point calibration of a mapping entry from a HID source", run};
