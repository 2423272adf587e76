/* SPDX-License-Identifier: Apache-2.0 */
/* pose-synth: write a synthetic rig file and print what it holds. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "pose_cli.h"
#include "pose_synth.h"

static void usage(FILE *f)
{
    fputs("usage: pose-synth bar|medium|body -o FILE.rig [options]\n"
          "\n"
          "Writes a synthetic rig file (format version 1) and prints its counts.\n"
          "  bar     the test object: N bones along X in a cylinder of soft tissue,\n"
          "          skin and bone surfaces embedded in the tet mesh (exact CoR)\n"
          "  medium  body layout (spine, head, arms, legs) at ~50 k tets (exact CoR)\n"
          "  body    body layout at ~3.5 M tets, ~800 k tet vertices, ~1.3 M tissue\n"
          "          vertices (CoR APPROXIMATED by clustering; labelled in the rig)\n"
          "\n"
          "options:\n"
          "  -o, --output FILE   rig file to write (required)\n"
          "  --bones N           bar: number of bones (default 4)\n"
          "  --tets N            body: target tet count (default 3500000)\n"
          "  --cor MODE          exact | clustered | none (default: exact for bar and\n"
          "                      medium, clustered for body)\n"
          "  --json              print the summary as JSON on stdout\n"
          "  -h, --help          this text\n",
          f);
}

/* Writes s as a JSON string literal. */
static void json_string(const char *s)
{
    putchar('"');
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            printf("\\%c", c);
        else if (c < 0x20)
            printf("\\u%04x", c);
        else
            putchar(c);
    }
    putchar('"');
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Progress on a terminal: "stage NN% (ETA s)", one line per stage. */
typedef struct progress_state {
    const char *stage;
    double start;
} progress_state;

static void on_progress(const char *stage, double fraction, void *user)
{
    progress_state *p = user;
    double t = now();
    if (!p->stage || strcmp(p->stage, stage) != 0) {
        p->stage = stage;
        p->start = t;
    }
    double eta = fraction > 0.0 ? (t - p->start) * (1.0 - fraction) / fraction : 0.0;
    fprintf(stderr, "\rpose-synth: %-5s %3.0f%% (ETA %.0f s)   ", stage, 100.0 * fraction, eta);
    if (fraction >= 1.0)
        fputc('\n', stderr);
}

static const char *cor_name(pose_synth_cor_mode m)
{
    switch (m) {
    case POSE_SYNTH_COR_EXACT: return "exact";
    case POSE_SYNTH_COR_CLUSTERED: return "clustered (approximation)";
    case POSE_SYNTH_COR_NONE: return "none";
    default: return "auto";
    }
}

int main(int argc, char **argv)
{
    const char *kind = NULL, *path = NULL;
    int bones = 0, json = 0;
    long long tets = 0;
    pose_synth_cor_mode cor = POSE_SYNTH_COR_AUTO;
    enum { OPT_BONES = POSE_CLI_LONG_ONLY, OPT_TETS, OPT_COR, OPT_JSON };
    static const struct option options[] = {
        {"output", required_argument, NULL, 'o'}, {"bones", required_argument, NULL, OPT_BONES},
        {"tets", required_argument, NULL, OPT_TETS}, {"cor", required_argument, NULL, OPT_COR},
        {"json", no_argument, NULL, OPT_JSON},      {"help", no_argument, NULL, 'h'},
        {0}};
    pose_cli cli;
    pose_cli_begin(&cli, "pose-synth", argc, argv, options);
    long n;
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;) {
        switch (c) {
        case 'h':
            usage(stdout);
            return 0;
        case OPT_JSON:
            json = 1;
            break;
        case 'o':
            path = cli.value;
            break;
        case OPT_BONES:
            if (pose_cli_long(&cli, 1, 64, &n) < 0)
                return 2;
            bones = (int)n;
            break;
        case OPT_TETS:
            if (pose_cli_long(&cli, 1000, 1000000000, &n) < 0)
                return 2;
            tets = n;
            break;
        case OPT_COR:
            cor = !strcmp(cli.value, "exact") ? POSE_SYNTH_COR_EXACT
                : !strcmp(cli.value, "clustered") ? POSE_SYNTH_COR_CLUSTERED
                : !strcmp(cli.value, "none") ? POSE_SYNTH_COR_NONE : POSE_SYNTH_COR_AUTO;
            if (cor == POSE_SYNTH_COR_AUTO) {
                pose_cli_error(&cli, "--cor must be exact, clustered or none");
                return 2;
            }
            break;
        case POSE_CLI_ARGUMENT:
            if (kind) {
                pose_cli_error(&cli, "unexpected argument '%s'", cli.value);
                return 2;
            }
            kind = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    }
    if (!kind || !path) {
        usage(stderr);
        return 2;
    }
    if ((bones && strcmp(kind, "bar") != 0) || (tets && strcmp(kind, "body") != 0)) {
        fprintf(stderr, "pose-synth: --bones applies to bar, --tets to body\n");
        return 2;
    }
    int progress = isatty(STDERR_FILENO);
    if (progress)
        fprintf(stderr, "pose-synth: generating %s rig\n", kind);
    double t0 = now();
    pose_synth_rig *rig = NULL;
    pose_status st;
    progress_state prog = {NULL, 0.0};
    pose_synth_progress_fn report = progress ? on_progress : NULL;
    if (!strcmp(kind, "bar")) {
        pose_synth_bar_options o = {.bones = bones, .cor = cor, .progress = report,
                                    .progress_user = &prog};
        st = pose_synth_bar(&o, &rig);
    } else if (!strcmp(kind, "medium") && cor == POSE_SYNTH_COR_AUTO) {
        st = pose_synth_medium(&rig);
    } else if (!strcmp(kind, "medium") || !strcmp(kind, "body")) {
        pose_synth_body_options o = {.cor = cor, .progress = report, .progress_user = &prog};
        o.target_tets = !strcmp(kind, "medium") ? 50000 : (size_t)tets;
        if (!strcmp(kind, "medium"))
            o.target_tissue_vertices = 18500;
        st = pose_synth_body(&o, &rig);
    } else {
        fprintf(stderr, "pose-synth: unknown rig kind '%s' (bar, medium or body)\n", kind);
        return 2;
    }
    if (st != POSE_OK) {
        fprintf(stderr, "pose-synth: generating %s failed: %s\n", kind, pose_status_string(st));
        return 1;
    }
    double t1 = now();
    if (progress)
        fprintf(stderr, "pose-synth: writing %s\n", path);
    const pose_rig_desc *d = pose_synth_desc(rig);
    st = pose_rig_write_file(d, path);
    if (st != POSE_OK) {
        fprintf(stderr, "pose-synth: %s\n", pose_last_error());
        pose_synth_free(rig);
        return 1;
    }
    double t2 = now();
    size_t tv = 0, tt = 0;
    for (size_t i = 0; i < d->tissue_count; i++) {
        tv += d->tissues[i].vertex_count;
        tt += d->tissues[i].triangle_count;
    }
    struct stat sb;
    long long bytes = stat(path, &sb) == 0 ? (long long)sb.st_size : -1;
    const char *cm = cor_name(pose_synth_cor(rig));
    if (json) {
        printf("{\"kind\": ");
        json_string(kind);
        printf(", \"file\": ");
        json_string(path);
        printf(", \"bytes\": %lld, \"joints\": %zu, \"tet_vertices\": %zu, \"tets\": %zu, "
               "\"influences\": %u, \"tissues\": %zu, \"tissue_vertices\": %zu, "
               "\"tissue_triangles\": %zu, \"cor\": \"%s\", \"cor_approximate\": %s, "
               "\"generate_seconds\": %.3f, \"write_seconds\": %.3f}\n",
               bytes, d->joint_count, d->tet_vertex_count, d->tet_count, d->influences,
               d->tissue_count, tv, tt, cm,
               pose_synth_cor(rig) == POSE_SYNTH_COR_CLUSTERED ? "true" : "false", t1 - t0,
               t2 - t1);
    } else {
        printf("%s rig written to %s (%lld bytes)\n"
               "  joints           %zu\n"
               "  tet vertices     %zu\n"
               "  tets             %zu\n"
               "  influences (K)   %u\n"
               "  tissues          %zu (%zu vertices, %zu triangles)\n"
               "  CoR centres      %s\n"
               "  generated in %.2f s, written in %.2f s\n",
               kind, path, bytes, d->joint_count, d->tet_vertex_count, d->tet_count,
               d->influences, d->tissue_count, tv, tt, cm, t1 - t0, t2 - t1);
    }
    pose_synth_free(rig);
    return 0;
}
