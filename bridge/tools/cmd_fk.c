/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge fk: world positions of every joint and end site of a BVH or
 * ASF/AMC clip at chosen frames, in the file's length unit. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mocap.h"
#include "pose_bridge_cli.h"
#include "pose_cli.h"

static void help(FILE *f)
{
    fprintf(f, "usage: pose-bridge fk FILE [--skeleton ASF] [--frames 0,1,100] [--json]\n"
               "  FILE        a .bvh file, or an .amc file (its ASF: --skeleton, or NN.asf beside NN_MM.amc)\n"
               "  --frames    comma-separated frame indices (0-based; default 0)\n"
               "  --json      machine-readable output\n"
               "Prints the world position of every joint and end site at each frame,\n"
               "in the file's units (CMU: multiply by 0.056444 for metres).\n");
}

static int parse_frames(const char *s, long **out, size_t *count)
{
    size_t n = 1;
    for (const char *p = s; *p; p++)
        n += *p == ',';
    long *v = malloc(n * sizeof *v);
    if (!v)
        return -1;
    const char *p = s;
    for (size_t i = 0; i < n; i++) {
        char *e;
        v[i] = strtol(p, &e, 10);
        if (e == p || v[i] < 0 || (*e != ',' && *e != '\0')) {
            free(v);
            return -1;
        }
        p = e + (*e == ',');
    }
    *out = v;
    *count = n;
    return 0;
}

static int run(int argc, char **argv)
{
    enum { OPT_SKELETON = POSE_CLI_LONG_ONLY, OPT_FRAMES, OPT_JSON };
    static const struct option options[] = {
        {"skeleton", required_argument, NULL, OPT_SKELETON}, {"frames", required_argument, NULL, OPT_FRAMES},
        {"json", no_argument, NULL, OPT_JSON},               {"help", no_argument, NULL, 'h'},
        {0}};
    const char *file = NULL, *skeleton = NULL, *frames_arg = "0";
    int json = 0;
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge fk", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            help(stdout);
            return 0;
        case OPT_SKELETON:
            skeleton = cli.value;
            break;
        case OPT_FRAMES:
            frames_arg = cli.value;
            break;
        case OPT_JSON:
            json = 1;
            break;
        case POSE_CLI_ARGUMENT:
            if (file) {
                pose_cli_error(&cli, "unexpected argument '%s' (one clip only)", cli.value);
                return 2;
            }
            file = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    if (!file) {
        pose_cli_error(&cli, "no clip given");
        return 2;
    }
    long *frames;
    size_t nf;
    if (parse_frames(frames_arg, &frames, &nf) != 0) {
        fprintf(stderr, "pose-bridge fk: --frames wants comma-separated non-negative integers\n");
        return 2;
    }
    pb_clip *clip;
    pb_error err;
    if (pb_clip_load(file, skeleton, &clip, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge fk: %s\n", err.message);
        free(frames);
        return 1;
    }
    int rc = 0;
    if (clip->frame_count == 0) /* an ASF alone: a skeleton, its motion is in an AMC file */
        fprintf(stderr, "pose-bridge fk: %s is a skeleton without motion: give the AMC file "
                        "(pose-bridge fk TAKE.amc --skeleton %s)\n", file, file);
    for (size_t i = 0; clip->frame_count && i < nf; i++)
        if ((size_t)frames[i] >= clip->frame_count) {
            fprintf(stderr, "pose-bridge fk: frame %ld is out of range (the clip has %zu frames)\n", frames[i],
                    clip->frame_count);
            rc = 1;
        }
    size_t J = (size_t)clip->joint_count;
    rc |= clip->frame_count == 0;
    double *scratch = malloc(J * 7 * sizeof *scratch);
    double (*wq)[4] = malloc(J * sizeof *wq);
    double (*wp)[3] = malloc(J * sizeof *wp);
    if (!rc && (!scratch || !wq || !wp)) {
        fprintf(stderr, "pose-bridge fk: out of memory\n");
        rc = 1;
    }
    if (!rc && json) {
        printf("{\"file\": ");
        pb_cli_json_string(stdout, file);
        printf(", \"format\": \"%s\", \"frame_count\": %zu, \"frame_time\": %.9g, \"length_unit\": %.9g,\n"
               " \"joints\": [",
               clip->format, clip->frame_count, clip->frame_time, clip->length_unit);
        for (size_t j = 0; j < J; j++) {
            printf("%s{\"name\": ", j ? ", " : "");
            pb_cli_json_string(stdout, clip->joints[j].name);
            printf(", \"parent\": %d, \"end_site\": %s}", clip->joints[j].parent,
                   clip->joints[j].is_end ? "true" : "false");
        }
        printf("],\n \"frames\": [");
    }
    for (size_t i = 0; !rc && i < nf; i++) {
        pb_clip_fk(clip, pb_clip_frame(clip, (size_t)frames[i]), scratch, wq, wp);
        if (json) {
            printf("%s\n  {\"frame\": %ld, \"positions\": [", i ? "," : "", frames[i]);
            for (size_t j = 0; j < J; j++)
                printf("%s[%.6f, %.6f, %.6f]", j ? ", " : "", wp[j][0], wp[j][1], wp[j][2]);
            printf("]}");
        } else {
            printf("frame %ld (t = %.4f s)\n", frames[i], (double)frames[i] * clip->frame_time);
            for (size_t j = 0; j < J; j++)
                printf("  %-24s %12.5f %12.5f %12.5f\n", clip->joints[j].name, wp[j][0], wp[j][1], wp[j][2]);
        }
    }
    if (!rc && json)
        printf("\n ]}\n");
    free(scratch);
    free(wq);
    free(wp);
    free(frames);
    pb_clip_free(clip);
    return rc;
}

const pb_command pb_cmd_fk = {"fk", "world positions of every joint of a BVH or ASF/AMC clip", run};
