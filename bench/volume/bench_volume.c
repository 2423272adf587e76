/* SPDX-License-Identifier: Apache-2.0
 * bench_volume: frames per second of pose_volume_sample (intensities and
 * labels) on
 *   - a synthetic volume: 512 x 512 x 400 voxels of 1 mm, a lattice rig of
 *     32 x 32 x 25 cubes (6 tets each) with two joints, the arm bent 30 deg;
 *   - a baked CT when --rig, --ct and --labels are given (the bake's grid
 *     convention: model space = NIfTI world in metres), hip_l flexed 45 deg,
 *     then the same with the whole body moved 1 mm (no tet where it rests:
 *     the sampler's rest cover saves nothing, the worst case).
 * Each line prints ms per frame, fps, the bytes a frame moves
 * (pose_volume_sample_bytes), the STREAM triad of the same run and thread
 * count, and the ratio achieved/bound (bound = triad / bytes). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <pose/pose.h>
#include <pose/volume.h>

#include "bench_common.h"
#ifdef POSE_BENCH_NIFTI
#include "vol_nifti.h"
#endif

typedef struct result {
    const char *name;
    size_t voxels, tets;
    double ms, cpu_ms, bytes;
} result;

/* Wall ms per frame; *cpu_ms: process CPU ms per frame (all threads; on a
 * loaded machine wall time counts other processes' turns too). */
static double time_frames(pose_volume_sampler *s, pose_state *st, float *vi, uint16_t *vl,
                          double seconds, double *cpu_ms)
{
    pose_volume_sample(s, st, vi, vl); /* warm-up */
    int frames = 0;
    double t0 = bench_now(), c0 = bench_cpu_seconds(), t;
    do {
        if (pose_volume_sample(s, st, vi, vl) != POSE_OK) {
            fprintf(stderr, "bench_volume: %s\n", pose_last_error());
            exit(1);
        }
        frames++;
        t = bench_now() - t0;
    } while (t < seconds || frames < 3);
    *cpu_ms = 1e3 * (bench_cpu_seconds() - c0) / frames;
    return 1e3 * t / frames;
}

static pose_rig *lattice_rig(int cx, int cy, int cz, float cell, const float origin[3])
{
    size_t nv = (size_t)(cx + 1) * (cy + 1) * (cz + 1), nt = (size_t)6 * cx * cy * cz;
    float *pos = malloc(3 * nv * sizeof *pos), *w = malloc(nv * sizeof *w);
    uint32_t *tets = malloc(4 * nt * sizeof *tets);
    uint16_t *tl = calloc(nt, sizeof *tl), *wj = malloc(nv * sizeof *wj);
#define VID(i, j, k) ((uint32_t)(((size_t)(k) * (cy + 1) + (j)) * (cx + 1) + (i)))
    float mid = origin[0] + 0.5f * cell * cx;
    for (int k = 0; k <= cz; k++)
        for (int j = 0; j <= cy; j++)
            for (int i = 0; i <= cx; i++) {
                uint32_t v = VID(i, j, k);
                pos[3 * v] = origin[0] + cell * i;
                pos[3 * v + 1] = origin[1] + cell * j;
                pos[3 * v + 2] = origin[2] + cell * k;
                wj[v] = pos[3 * v] < mid ? 0 : 1;
                w[v] = 1.0f;
            }
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    size_t t = 0;
    for (int k = 0; k < cz; k++)
        for (int j = 0; j < cy; j++)
            for (int i = 0; i < cx; i++)
                for (int p = 0; p < 6; p++, t++) {
                    int c[3] = {i, j, k};
                    tets[4 * t] = VID(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; s++) {
                        c[perm[p][s]]++;
                        tets[4 * t + 1 + s] = VID(c[0], c[1], c[2]);
                    }
                }
#undef VID
    pose_joint_desc joints[2] = {
        {.name = "base", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, 0, 0}}},
        {.name = "arm", .parent = 0, .rest_model = {{0, 0, 0, 1}, {mid, origin[1], origin[2]}}},
    };
    pose_rig_desc d = {.joint_count = 2, .joints = joints, .tet_vertex_count = nv,
                       .tet_positions = pos, .tet_count = nt, .tets = tets, .tet_labels = tl,
                       .influences = 1, .weight_joints = wj, .weights = w};
    pose_rig *rig = NULL;
    if (pose_rig_create(&d, NULL, &rig) != POSE_OK)
        fprintf(stderr, "bench_volume: %s\n", pose_last_error());
    free(pos), free(w), free(tets), free(tl), free(wj);
    return rig;
}

static int synthetic(int threads, double seconds, int scale, result *r)
{
    /* scale 1: 512 x 512 x 400 voxels of 1 mm; scale s: 1/s the voxels per
     * axis, s mm each (the same body and rig). */
    const uint32_t nx = 512 / scale, ny = 512 / scale, nz = 400 / scale;
    const float h = 0.001f * scale, o[3] = {0.016f, 0.016f, 0.01f};
    pose_rig *rig = lattice_rig(30, 30, 23, 0.016f, o);
    if (!rig)
        return -1;
    size_t n = (size_t)nx * ny * nz;
    float *ct = malloc(n * sizeof *ct), *vi = malloc(n * sizeof *vi);
    uint16_t *lab = malloc(n * sizeof *lab), *vl = malloc(n * sizeof *vl);
    if (!ct || !vi || !lab || !vl)
        return -1;
    for (size_t v = 0; v < n; v++) {
        ct[v] = (float)((v * 2654435761u) % 2000) - 1000.0f;
        lab[v] = (uint16_t)(v % 7);
    }
    pose_volume_desc rest = {{nx, ny, nz, {{h, 0, 0, 0}, {0, h, 0, 0}, {0, 0, h, 0}}}, ct, lab, -1000.0f, 0};
    pose_state_options so = {.size = sizeof so, .threads = threads};
    pose_state *st;
    pose_volume_sampler *s;
    if (pose_state_create_ex(rig, &so, &st) != POSE_OK ||
        pose_volume_sampler_create(rig, &rest, NULL, threads, NULL, &s) != POSE_OK) {
        fprintf(stderr, "bench_volume: %s\n", pose_last_error());
        return -1;
    }
    float a = 30.0f * 3.14159265f / 180.0f;
    const float q[4] = {0, sinf(a / 2), 0, cosf(a / 2)};
    pose_set_joint(st, 1, q);
    pose_apply(st);
    pose_tet_info ti;
    pose_rig_tet_info(rig, &ti);
    static char name[64];
    snprintf(name, sizeof name, "synthetic %ux%ux%u", nx, ny, nz);
    *r = (result){name, n, ti.tet_count, 0, 0, (double)pose_volume_sample_bytes(s, 1, 1)};
    r->ms = time_frames(s, st, vi, vl, seconds, &r->cpu_ms);
    pose_volume_sampler_free(s);
    pose_state_free(st);
    pose_rig_free(rig);
    free(ct), free(vi), free(lab), free(vl);
    return 0;
}

#ifdef POSE_BENCH_NIFTI
static int baked_ct(const char *rig_path, const char *ct_path, const char *seg_path, int threads,
                    double seconds, result r[2])
{
    char err[512];
    pv_image ct, seg;
    if (pv_nifti_read(ct_path, &ct, err, sizeof err) || pv_nifti_read(seg_path, &seg, err, sizeof err)) {
        fprintf(stderr, "bench_volume: %s\n", err);
        return -1;
    }
    pose_rig *rig;
    if (pose_rig_load(rig_path, &rig) != POSE_OK) {
        fprintf(stderr, "bench_volume: %s\n", pose_last_error());
        return -1;
    }
    size_t n = pv_image_voxels(&ct);
    uint16_t *lab = malloc(n * sizeof *lab), *vl = malloc(n * sizeof *vl);
    float *vi = malloc(n * sizeof *vi);
    for (size_t v = 0; v < n; v++)
        lab[v] = (uint16_t)seg.data[v];
    pose_volume_grid g = {(uint32_t)ct.nx, (uint32_t)ct.ny, (uint32_t)ct.nz, {{0}}};
    double m[3][4];
    pv_image_model_affine(&ct, m);
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 4; c++)
            g.affine[a][c] = (float)m[a][c];
    pose_volume_desc rest = {g, ct.data, lab, -1000.0f, 0};
    pose_state_options so = {.size = sizeof so, .threads = threads};
    pose_state *st;
    pose_volume_sampler *s;
    if (pose_state_create_ex(rig, &so, &st) != POSE_OK ||
        pose_volume_sampler_create(rig, &rest, NULL, threads, NULL, &s) != POSE_OK) {
        fprintf(stderr, "bench_volume: %s\n", pose_last_error());
        return -1;
    }
    int hip = pose_rig_find_joint(rig, "hip_l");
    if (hip >= 0) {
        const float deg[3] = {45.0f, 0, 0};
        pose_set_joint_clinical(st, hip, deg);
    }
    pose_apply(st);
    pose_tet_info ti;
    pose_rig_tet_info(rig, &ti);
    r[0] = (result){"CT (hip_l 45 deg)", n, ti.tet_count, 0, 0,
                    (double)pose_volume_sample_bytes(s, 1, 1)};
    r[0].ms = time_frames(s, st, vi, vl, seconds, &r[0].cpu_ms);
    /* The same with the whole body moved 1 mm: no tet lies where it rests,
     * so the rest cover copies nothing and every tet is rasterized. */
    const float shift[3] = {0.001f, 0.0f, 0.0f};
    pose_set_root(st, shift, NULL);
    pose_apply(st);
    r[1] = r[0];
    r[1].name = "CT, every tet moved";
    r[1].ms = time_frames(s, st, vi, vl, seconds, &r[1].cpu_ms);
    pose_volume_sampler_free(s);
    pose_state_free(st);
    pose_rig_free(rig);
    pv_image_free(&ct), pv_image_free(&seg);
    free(lab), free(vl), free(vi);
    return 0;
}
#endif

int main(int argc, char **argv)
{
    int threads = 2;
    double seconds = 2.0;
    const char *rig = NULL, *ct = NULL, *labels = NULL;
    int skip_synthetic = 0, scale = 1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--seconds") && i + 1 < argc)
            seconds = atof(argv[++i]);
        else if (!strcmp(argv[i], "--rig") && i + 1 < argc)
            rig = argv[++i];
        else if (!strcmp(argv[i], "--ct") && i + 1 < argc)
            ct = argv[++i];
        else if (!strcmp(argv[i], "--labels") && i + 1 < argc)
            labels = argv[++i];
        else if (!strcmp(argv[i], "--scale") && i + 1 < argc)
            scale = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--no-synthetic"))
            skip_synthetic = 1;
        else {
            fprintf(stderr,
                    "usage: volume [--threads N] [--seconds S] [--scale S] [--no-synthetic]\n"
                    "              [--rig CT.rig --ct CT.nii.gz --labels SEG.nii.gz]\n");
            return !strcmp(argv[i], "--help") ? 0 : 2;
        }
    }
    if (threads < 1 || threads > 64 || !(seconds > 0) || scale < 1 || scale > 16) {
        fprintf(stderr, "bench_volume: --threads 1..64, --seconds > 0, --scale 1..16\n");
        return 2;
    }
    result res[3];
    int nres = 0;
    if (!skip_synthetic && synthetic(threads, seconds, scale, &res[nres]) == 0)
        nres++;
    if (rig && ct && labels) {
#ifdef POSE_BENCH_NIFTI
        if (baked_ct(rig, ct, labels, threads, seconds, &res[nres]) == 0)
            nres += 2;
#else
        fprintf(stderr, "bench_volume: built without NIfTI (libnifti2-dev)\n");
#endif
    }
    double triad = bench_triad_bytes_per_s((unsigned)threads, (size_t)1 << 24, 5);
    printf("pose_volume_sample, intensities + labels, %d thread(s); triad %.2f GB/s\n", threads,
           triad / 1e9);
    printf("%-24s %11s %8s %9s %8s %11s %9s %7s\n", "volume", "voxels", "tets", "ms/frame",
           "fps", "cpu_ms/thr", "MB/frame", "ratio");
    for (int i = 0; i < nres; i++) {
        double fps = 1e3 / res[i].ms, bound = triad / res[i].bytes;
        printf("%-24s %11zu %8zu %9.2f %8.1f %11.2f %9.1f %6.0f%%\n", res[i].name,
               res[i].voxels, res[i].tets, res[i].ms, fps, res[i].cpu_ms / threads,
               res[i].bytes / 1e6, 100.0 * fps / bound);
    }
    printf("(cpu_ms/thr: process CPU time per frame / threads, the wall time an idle machine "
           "would show; load average now decides the rest)\n");
    return nres > 0 ? 0 : 1;
}
