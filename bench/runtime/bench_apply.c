/* SPDX-License-Identifier: Apache-2.0 */
/*
 * bench_apply: frames per second of pose_apply on synthetic rigs (the bar,
 * a medium body, a body at the paper's scale), for each skinning method and
 * 1 and 2 threads, next to the bytes the kernels must move per frame and a
 * STREAM triad measured in the same run with the same thread count:
 *   bound = triad bytes/s / bytes per frame (fps if memory were the only limit)
 *   ratio = fps / bound.
 * With --passes, also the mean time of each pass of a frame (skinning,
 * transfer with normals, triangle normals of flat tets), run as pose_apply
 * runs them, to see where a frame goes.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_common.h"
#include "pose/pose.h"
#include "pose_synth.h"
#include "rt_skin.h"
#include "state_internal.h"

typedef struct options {
    int json;
    double seconds;      /* timed run per configuration */
    const char *rigs;    /* comma list: small,medium,body */
    int max_threads;
    int passes;          /* also time each pass of pose_apply */
} options;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: bench_apply [--json] [--seconds S] [--rigs small,medium,body] [--threads N]\n"
            "                   [--passes]\n"
            "  Frames per second of pose_apply per rig, method and thread count (1..N,\n"
            "  default 2), bytes per frame, STREAM triad bandwidth and achieved/bound.\n"
            "  --seconds S   timed run per configuration (default 1.0)\n"
            "  --json        one JSON object on stdout instead of the table\n"
            "  --passes      also the mean ms of pose_apply and of each of its passes:\n"
            "                skin, transfer (with normals), fix (triangle normals of flat tets)\n"
            "  POSE_KERNELS=generic in the environment times the generic kernels.\n");
}

static int parse(int argc, char **argv, options *o)
{
    *o = (options){0, 1.0, "small,medium,body", 2, 0};
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            usage(stdout);
            exit(0);
        } else if (!strcmp(argv[i], "--json")) {
            o->json = 1;
        } else if (!strcmp(argv[i], "--seconds") && i + 1 < argc) {
            o->seconds = atof(argv[++i]);
        } else if (!strcmp(argv[i], "--rigs") && i + 1 < argc) {
            o->rigs = argv[++i];
        } else if (!strcmp(argv[i], "--passes")) {
            o->passes = 1;
        } else if (!strcmp(argv[i], "--threads") && i + 1 < argc) {
            o->max_threads = atoi(argv[++i]);
        } else {
            fprintf(stderr, "bench_apply: unknown argument '%s'\n", argv[i]);
            usage(stderr);
            return -1;
        }
    }
    if (o->seconds <= 0.0 || o->max_threads < 1 || o->max_threads > 64) {
        fprintf(stderr, "bench_apply: --seconds must be > 0 and --threads in 1..64\n");
        return -1;
    }
    return 0;
}

static void progress(const char *what)
{
    if (bench_progress_enabled())
        fprintf(stderr, "\r\033[K%s", what);
}

static pose_status make_rig(const char *name, pose_rig **rig)
{
    pose_synth_rig *syn = NULL;
    pose_status s;
    if (!strcmp(name, "small"))
        s = pose_synth_bar(NULL, &syn);
    else if (!strcmp(name, "medium"))
        s = pose_synth_medium(&syn);
    else if (!strcmp(name, "body"))
        s = pose_synth_body(NULL, &syn);
    else
        return POSE_ERR_INVALID_ARGUMENT;
    if (s == POSE_OK)
        s = pose_rig_create(pose_synth_desc(syn), NULL, rig);
    pose_synth_free(syn);
    return s;
}

/* A pose that keeps every joint moving, so no frame is the rest pose. */
static void set_frame_pose(pose_state *st, size_t joints, int frame)
{
    for (size_t j = 0; j < joints; j++) {
        const float deg[3] = {(float)((frame * 3 + (int)j * 7) % 60) - 30.0f,
                              (float)((frame * 5 + (int)j * 11) % 40) - 20.0f,
                              (float)((frame * 2 + (int)j * 13) % 90) - 45.0f};
        pose_set_joint_euler(st, (int)j, deg, POSE_EULER_ZXY);
    }
}

/* Mean seconds of pose_apply (out[3]) and of each of its passes (out[0..2])
 * over `frames` posed frames: pose_apply is timed, then its passes run
 * again, each timed (same machine state, so the shares compare). */
static void time_passes(pose_state *st, size_t joints, int frames, double out[4])
{
    const size_t blocks = st->rt->skin.block_count + st->rt->transfer.block_count;
    const int serial = blocks < POSE__SERIAL_BLOCKS;
    /* pose_apply's own passes (sdk/src/state.c), for --passes */
    const pose__task_fn fns[3] = {pose__state_skin_task, pose__state_transfer_task,
                                  pose__state_fix_normals_task};
    out[0] = out[1] = out[2] = out[3] = 0.0;
    for (int f = 0; f < frames; f++) {
        set_frame_pose(st, joints, f);
        const double a0 = bench_now();
        pose_apply(st);
        out[3] += bench_now() - a0;
        for (int p = 0; p < 3; p++) {
            double t0 = bench_now();
            if (serial)
                fns[p](st, 0, 1);
            else
                pose__pool_run(st->pool, fns[p], st);
            out[p] += bench_now() - t0;
        }
    }
    for (int p = 0; p < 4; p++)
        out[p] /= frames;
}

typedef struct result {
    const char *rig;
    const char *method;
    int threads;
    double fps, cpu_fps, bytes, triad, bound, ratio;
    double pass_s[4]; /* --passes: skin, transfer, fix, whole pose_apply */
    size_t tet_vertices, tets, tissue_vertices;
} result;

static const char *const k_methods[3] = {"LBS", "DQS", "CoR"};

int main(int argc, char **argv)
{
    options o;
    if (parse(argc, argv, &o) < 0)
        return 2;
    result res[64];
    int nres = 0;
    double triad[65] = {0};
    char rigs[256];
    snprintf(rigs, sizeof rigs, "%s", o.rigs);
    for (char *save = NULL, *name = strtok_r(rigs, ",", &save); name;
         name = strtok_r(NULL, ",", &save)) {
        char line[128];
        snprintf(line, sizeof line, "generating rig '%s'...", name);
        progress(line);
        pose_rig *rig = NULL;
        pose_status s = make_rig(name, &rig);
        if (s != POSE_OK) {
            fprintf(stderr, "\nbench_apply: rig '%s': %s %s\n", name, pose_status_string(s),
                    pose_last_error());
            return 1;
        }
        pose_tet_info ti;
        pose_rig_tet_info(rig, &ti);
        size_t tissue = 0;
        for (size_t t = 0; t < pose_rig_tissue_count(rig); t++) {
            pose_tissue_info info;
            pose_rig_tissue_info(rig, (int)t, &info);
            tissue += info.vertex_count;
        }
        for (int threads = 1; threads <= o.max_threads; threads++) {
            /* bandwidth now, with this thread count: the machine may be shared */
            progress("measuring triad bandwidth...");
            triad[threads] = bench_triad_bytes_per_s((unsigned)threads, (size_t)1 << 24, 5);
            for (int m = 0; m < 3 && nres < 64; m++) {
                if (m == POSE_COR && !ti.cor)
                    continue;
                snprintf(line, sizeof line, "%s %s %d thread(s)...", name, k_methods[m], threads);
                progress(line);
                pose_state_options so = {.threads = threads, .method = (pose_method)m};
                pose_state *st;
                if ((s = pose_state_create_ex(rig, &so, &st)) != POSE_OK) {
                    fprintf(stderr, "\nbench_apply: %s\n", pose_last_error());
                    return 1;
                }
                size_t nj = pose_rig_joint_count(rig);
                for (int f = 0; f < 5; f++) { /* warm up caches and workers */
                    set_frame_pose(st, nj, f);
                    pose_apply(st);
                }
                int frames = 0;
                double c0 = bench_cpu_seconds();
                double t0 = bench_now(), t = t0;
                while (t - t0 < o.seconds) {
                    set_frame_pose(st, nj, frames);
                    pose_apply(st);
                    frames++;
                    t = bench_now();
                }
                double cpu = bench_cpu_seconds() - c0;
                result *r = &res[nres++];
                r->rig = name;
                r->method = k_methods[m];
                r->threads = threads;
                r->fps = frames / (t - t0);
                /* on a shared machine: the rate if our threads had the cores to themselves */
                r->cpu_fps = cpu > 0.0 ? frames * threads / cpu : 0.0;
                r->bytes = (double)pose__state_frame_bytes(st);
                r->triad = triad[threads];
                r->bound = r->triad / r->bytes;
                r->ratio = r->fps / r->bound;
                r->tet_vertices = ti.vertex_count;
                r->tets = ti.tet_count;
                r->tissue_vertices = tissue;
                if (o.passes)
                    time_passes(st, nj, frames < 20 ? 20 : frames > 2000 ? 2000 : frames,
                                r->pass_s);
                pose_state_free(st);
            }
        }
        pose_rig_free(rig);
    }
    progress("");
    if (o.json) {
        printf("{\"kernels\": \"%s\", \"results\": [", pose__kernels_variant());
        for (int i = 0; i < nres; i++) {
            const result *r = &res[i];
            printf("%s\n  {\"rig\": \"%s\", \"method\": \"%s\", \"threads\": %d, "
                   "\"tet_vertices\": %zu, \"tets\": %zu, \"tissue_vertices\": %zu, "
                   "\"fps\": %.1f, \"fps_per_cpu_time\": %.1f, \"bytes_per_frame\": %.0f, \"triad_bytes_per_s\": %.0f, "
                   "\"bound_fps\": %.1f, \"ratio\": %.3f",
                   i ? "," : "", r->rig, r->method, r->threads, r->tet_vertices, r->tets,
                   r->tissue_vertices, r->fps, r->cpu_fps, r->bytes, r->triad, r->bound, r->ratio);
            if (o.passes)
                printf(", \"pass_ms\": {\"apply\": %.4f, \"skin\": %.4f, \"transfer\": %.4f, "
                       "\"fix\": %.4f}",
                       1e3 * r->pass_s[3], 1e3 * r->pass_s[0], 1e3 * r->pass_s[1],
                       1e3 * r->pass_s[2]);
            printf("}");
        }
        printf("\n]}\n");
        return 0;
    }
    printf("pose_apply (kernels: %s)\n", pose__kernels_variant());
    printf("%-7s %-4s %3s %9s %10s %9s %9s %10s %11s %7s\n", "rig", "meth", "thr", "tet_vert",
           "tiss_vert", "fps", "cpu_fps", "MB/frame", "triad GB/s", "ratio");
    for (int i = 0; i < nres; i++) {
        const result *r = &res[i];
        printf("%-7s %-4s %3d %9zu %10zu %9.1f %9.1f %10.2f %11.2f %6.0f%%\n", r->rig, r->method,
               r->threads, r->tet_vertices, r->tissue_vertices, r->fps, r->cpu_fps, r->bytes / 1e6,
               r->triad / 1e9, 100.0 * r->ratio);
    }
    if (o.passes) {
        printf("\nmean ms of pose_apply and of its passes, timed in turn over the same frames\n"
               "(other = apply - passes: FK, palette, hand-offs; noisy on a shared machine)\n");
        printf("%-7s %-4s %3s %9s %9s %9s %9s %9s\n", "rig", "meth", "thr", "apply", "skin",
               "transfer", "fix", "other");
        for (int i = 0; i < nres; i++) {
            const result *r = &res[i];
            const double frame = 1e3 * r->pass_s[3];
            const double sum = 1e3 * (r->pass_s[0] + r->pass_s[1] + r->pass_s[2]);
            printf("%-7s %-4s %3d %9.4f %9.4f %9.4f %9.4f %9.4f\n", r->rig, r->method, r->threads,
                   frame, 1e3 * r->pass_s[0], 1e3 * r->pass_s[1], 1e3 * r->pass_s[2],
                   frame - sum);
        }
    }
    printf("ratio = fps / (triad bytes/s / bytes per frame): the share of the memory-bound\n"
           "frame rate reached. Bytes count each streamed array once (reads + writes).\n"
           "cpu_fps = frames * threads / process CPU time: the rate on cores not shared\n"
           "with other processes (wall-clock fps is lower on a busy machine).\n");
    return 0;
}
