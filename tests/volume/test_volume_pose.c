/* SPDX-License-Identifier: Apache-2.0
 * pose/volume.h on a synthetic rig: a lattice box of tets (8^3 cubes, six
 * tets each) in a 40^3 image of 5 mm voxels, two joints (the base holds
 * x < 0, the arm x >= 0). The rest intensity is linear in space, so the
 * trilinear samples of any posed voxel are known exactly: f(preimage). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <pose/pose.h>
#include <pose/volume.h>

#include "rt_skin.h" /* pose__kernels_force_generic, pose__kernels_variant */

#define N 40          /* voxels per axis */
#define H 0.005f      /* voxel edge, m */
#define C0 (-0.0975f) /* centre of voxel 0 */
#define CELLS 8
#define CELL 0.02f
#define L0 4          /* the lattice starts at voxel centre 4 and ends at 36 */

typedef struct fixture {
    pose_rig *rig;
    float *intensity;
    uint16_t *labels;
    pose_volume_desc rest;
} fixture;

static float f_lin(float x, float y, float z) { return 1000.0f * x - 400.0f * y + 250.0f * z + 40.0f; }

static uint16_t lab_of(int i, int j, int k) { return (uint16_t)(1 + i / 10 + 4 * (j / 10) + 16 * (k / 10)); }

static int vid(int i, int j, int k) { return (k * (CELLS + 1) + j) * (CELLS + 1) + i; }

static int setup(void **state)
{
    fixture *fx = calloc(1, sizeof *fx);
    const int nv = (CELLS + 1) * (CELLS + 1) * (CELLS + 1), nt = 6 * CELLS * CELLS * CELLS;
    float *pos = malloc(3 * (size_t)nv * sizeof *pos);
    uint32_t *tets = malloc(4 * (size_t)nt * sizeof *tets);
    uint16_t *tl = calloc((size_t)nt, sizeof *tl);
    uint16_t *wj = malloc((size_t)nv * sizeof *wj);
    float *w = malloc((size_t)nv * sizeof *w);
    float o = C0 + L0 * H;
    for (int k = 0; k <= CELLS; k++)
        for (int j = 0; j <= CELLS; j++)
            for (int i = 0; i <= CELLS; i++) {
                int v = vid(i, j, k);
                pos[3 * v] = o + CELL * i, pos[3 * v + 1] = o + CELL * j, pos[3 * v + 2] = o + CELL * k;
                wj[v] = pos[3 * v] < 0.0f ? 0 : 1;
                w[v] = 1.0f;
            }
    /* Kuhn subdivision: six tets around the cube's main diagonal (conforming). */
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int t = 0;
    for (int k = 0; k < CELLS; k++)
        for (int j = 0; j < CELLS; j++)
            for (int i = 0; i < CELLS; i++)
                for (int p = 0; p < 6; p++) {
                    int c[3] = {i, j, k};
                    tets[4 * t] = (uint32_t)vid(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; s++) {
                        c[perm[p][s]]++;
                        tets[4 * t + 1 + s] = (uint32_t)vid(c[0], c[1], c[2]);
                    }
                    t++;
                }
    pose_joint_desc joints[2] = {
        {.name = "base", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, 0, 0}}},
        {.name = "arm", .parent = 0, .rest_model = {{0, 0, 0, 1}, {0.0f, 0, 0}}},
    };
    pose_rig_desc d = {.joint_count = 2, .joints = joints, .tet_vertex_count = (size_t)nv,
                       .tet_positions = pos, .tet_count = (size_t)nt, .tets = tets,
                       .tet_labels = tl, .influences = 1, .weight_joints = wj, .weights = w};
    if (pose_rig_create(&d, NULL, &fx->rig) != POSE_OK) {
        fprintf(stderr, "%s\n", pose_last_error());
        return -1;
    }
    free(pos), free(tets), free(tl), free(wj), free(w);
    fx->intensity = malloc((size_t)N * N * N * sizeof *fx->intensity);
    fx->labels = malloc((size_t)N * N * N * sizeof *fx->labels);
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                size_t v = ((size_t)k * N + j) * N + i;
                fx->intensity[v] = f_lin(C0 + H * i, C0 + H * j, C0 + H * k);
                fx->labels[v] = lab_of(i, j, k);
            }
    pose_volume_grid g = {N, N, N, {{H, 0, 0, C0}, {0, H, 0, C0}, {0, 0, H, C0}}};
    fx->rest = (pose_volume_desc){g, fx->intensity, fx->labels, -1000.0f, 0};
    *state = fx;
    return 0;
}

static int teardown(void **state)
{
    fixture *fx = *state;
    pose_rig_free(fx->rig);
    free(fx->intensity);
    free(fx->labels);
    free(fx);
    return 0;
}

static int inside_lattice(int i, int j, int k)
{
    return i >= L0 && i <= L0 + 32 && j >= L0 && j <= L0 + 32 && k >= L0 && k <= L0 + 32;
}

static void sample(const fixture *fx, pose_state *st, int threads, float *vi, uint16_t *vl)
{
    pose_volume_sampler *s = NULL;
    assert_int_equal(pose_volume_sampler_create(fx->rig, &fx->rest, NULL, threads, NULL, &s), POSE_OK);
    assert_int_equal(pose_volume_sample(s, st, vi, vl), POSE_OK);
    pose_volume_sampler_free(s);
}

/* At rest: the image comes back where the body is (also on the lattice's
 * faces, where voxel centres sit exactly), background elsewhere. */
static void test_rest_is_identity(void **state)
{
    fixture *fx = *state;
    pose_state *st;
    assert_int_equal(pose_state_create(fx->rig, &st), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    float *vi = malloc((size_t)N * N * N * sizeof *vi);
    uint16_t *vl = malloc((size_t)N * N * N * sizeof *vl);
    sample(fx, st, 2, vi, vl);
    size_t inside = 0;
    double worst = 0;
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                size_t v = ((size_t)k * N + j) * N + i;
                if (inside_lattice(i, j, k)) {
                    inside++;
                    assert_int_equal(vl[v], fx->labels[v]);
                    worst = fmax(worst, fabs(vi[v] - fx->intensity[v]));
                } else {
                    assert_int_equal(vl[v], 0);
                    assert_true(vi[v] == -1000.0f);
                }
            }
    printf("rest: %zu voxels inside, max |HU error| %.2e\n", inside, worst);
    assert_int_equal(inside, 33 * 33 * 33);
    assert_true(worst < 1e-2);
    free(vi), free(vl);
    pose_state_free(st);
}

/* The whole body turned 90 degrees about z (the base, about the origin):
 * voxel centres map onto voxel centres, so labels move exactly, and the
 * linear intensity is f(R^-1 x) everywhere inside. */
static void test_rigid_turn(void **state)
{
    fixture *fx = *state;
    pose_state *st;
    assert_int_equal(pose_state_create(fx->rig, &st), POSE_OK);
    const float s = sqrtf(0.5f), q[4] = {0, 0, s, s};
    assert_int_equal(pose_set_joint(st, 0, q), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    float *vi = malloc((size_t)N * N * N * sizeof *vi);
    uint16_t *vl = malloc((size_t)N * N * N * sizeof *vl);
    sample(fx, st, 3, vi, vl);
    size_t inside = 0;
    double worst = 0;
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                size_t v = ((size_t)k * N + j) * N + i;
                /* x = R p: p = R^-1 x = (y, -x, z); index: i' = j, j' = N - 1 - i. */
                int pi = j, pj = N - 1 - i, pk = k;
                if (!inside_lattice(pi, pj, pk)) {
                    assert_int_equal(vl[v], 0);
                    continue;
                }
                inside++;
                assert_int_equal(vl[v], lab_of(pi, pj, pk));
                float want = f_lin(C0 + H * pi, C0 + H * pj, C0 + H * pk);
                worst = fmax(worst, fabs(vi[v] - want));
            }
    printf("turned: %zu voxels inside, max |HU error| %.2e\n", inside, worst);
    assert_int_equal(inside, 33 * 33 * 33);
    assert_true(worst < 1e-2);
    free(vi), free(vl);
    pose_state_free(st);
}

/* The arm bent 35 degrees about y (tets stretch and fold at x = 0), posed. */
#define BENT_DEG 35.0f
static pose_state *bent_arm(const fixture *fx)
{
    pose_state *st;
    assert_int_equal(pose_state_create(fx->rig, &st), POSE_OK);
    float a = BENT_DEG * 3.14159265f / 180.0f;
    const float q[4] = {0, sinf(a / 2), 0, cosf(a / 2)};
    assert_int_equal(pose_set_joint(st, 1, q), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    return st;
}

/* The arm bent 35 degrees about y (tets stretch and fold at x = 0): the
 * same bytes for 1, 2, 3 and 7 threads; rigid arm voxels sample
 * f(R^-1 x) exactly. */
static void test_threads_identical(void **state)
{
    fixture *fx = *state;
    pose_state *st = bent_arm(fx);
    const float a = BENT_DEG * 3.14159265f / 180.0f;
    size_t n = (size_t)N * N * N;
    float *ref_i = malloc(n * sizeof *ref_i), *vi = malloc(n * sizeof *vi);
    uint16_t *ref_l = malloc(n * sizeof *ref_l), *vl = malloc(n * sizeof *vl);
    sample(fx, st, 1, ref_i, ref_l);
    const int counts[3] = {2, 3, 7};
    for (int c = 0; c < 3; c++) {
        memset(vi, 0, n * sizeof *vi);
        memset(vl, 0, n * sizeof *vl);
        sample(fx, st, counts[c], vi, vl);
        assert_memory_equal(vi, ref_i, n * sizeof *vi);
        assert_memory_equal(vl, ref_l, n * sizeof *vl);
    }
    /* Voxels of the arm well inside (x > 2 cm, preimage inside the rest
     * arm): f of the rotated-back point. */
    size_t checked = 0;
    double worst = 0;
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                float x = C0 + H * i, y = C0 + H * j, z = C0 + H * k;
                /* R^-1 about y: p = (c x - s z, y, s x + c z) */
                float px = cosf(a) * x - sinf(a) * z, pz = sinf(a) * x + cosf(a) * z;
                float lo = C0 + L0 * H + 1e-3f, hi = C0 + (L0 + 32) * H - 1e-3f;
                if (px < 0.02f || px > hi || y < lo || y > hi || pz < lo || pz > hi)
                    continue;
                size_t v = ((size_t)k * N + j) * N + i;
                worst = fmax(worst, fabs(ref_i[v] - f_lin(px, y, pz)));
                checked++;
            }
    printf("bent arm: %zu voxels checked, max |HU error| %.2e\n", checked, worst);
    assert_true(checked > 5000);
    assert_true(worst < 0.05);
    free(ref_i), free(vi), free(ref_l), free(vl);
    pose_state_free(st);
}

/* A box of the fixture's image, voxels o .. o + n - 1 per axis, as an
 * image of its own (arrays the caller frees). */
static pose_volume_desc crop(const fixture *fx, const int o[3], const uint32_t n[3])
{
    size_t count = (size_t)n[0] * n[1] * n[2];
    float *vi = malloc(count * sizeof *vi);
    uint16_t *vl = malloc(count * sizeof *vl);
    for (uint32_t k = 0; k < n[2]; k++)
        for (uint32_t j = 0; j < n[1]; j++)
            for (uint32_t i = 0; i < n[0]; i++) {
                size_t from = ((size_t)(k + o[2]) * N + (j + o[1])) * N + (i + o[0]);
                size_t to = ((size_t)k * n[1] + j) * n[0] + i;
                vi[to] = fx->intensity[from], vl[to] = fx->labels[from];
            }
    pose_volume_grid g = {n[0], n[1], n[2], {{H, 0, 0, C0 + H * o[0]}, {0, H, 0, C0 + H * o[1]},
                                             {0, 0, H, C0 + H * o[2]}}};
    return (pose_volume_desc){g, vi, vl, -1000.0f, 0};
}

/* The generic and the AVX2 rasterizer and gather (the latter where the CPU
 * has it) give the same bytes on the bent arm, with both outputs, and each
 * output alone (the generic gather then): on the whole image, on a crop
 * the lattice overhangs on every side (preimages clamped within half a
 * voxel, background beyond), and on one slice (no neighbour along z). */
static void test_variants_identical(void **state)
{
    fixture *fx = *state;
    pose_state *st = bent_arm(fx);
    const pose_volume_grid *out = &fx->rest.grid;
    size_t n = (size_t)N * N * N;
    float *gi = malloc(n * sizeof *gi), *vi = malloc(n * sizeof *vi);
    uint16_t *gl = malloc(n * sizeof *gl), *vl = malloc(n * sizeof *vl);
    const int o_crop[3] = {6, 7, 6}, o_slice[3] = {0, 0, 20};
    const uint32_t n_crop[3] = {28, 27, 29}, n_slice[3] = {N, N, 1};
    pose_volume_desc rests[3] = {fx->rest, crop(fx, o_crop, n_crop), crop(fx, o_slice, n_slice)};
    for (int r = 0; r < 3; r++) {
        pose_volume_sampler *s;
        pose__kernels_force_generic(1);
        assert_int_equal(pose_volume_sampler_create(fx->rig, &rests[r], out, 2, NULL, &s), POSE_OK);
        assert_int_equal(pose_volume_sample(s, st, gi, gl), POSE_OK);
        pose_volume_sampler_free(s);
        pose__kernels_force_generic(0);
        printf("variants, image %d: generic against %s\n", r, pose__kernels_variant());
        assert_int_equal(pose_volume_sampler_create(fx->rig, &rests[r], out, 2, NULL, &s), POSE_OK);
        assert_int_equal(pose_volume_sample(s, st, vi, vl), POSE_OK);
        assert_memory_equal(vi, gi, n * sizeof *vi);
        assert_memory_equal(vl, gl, n * sizeof *vl);
        memset(vi, 0, n * sizeof *vi);
        memset(vl, 0, n * sizeof *vl);
        assert_int_equal(pose_volume_sample(s, st, vi, NULL), POSE_OK);
        assert_int_equal(pose_volume_sample(s, st, NULL, vl), POSE_OK);
        assert_memory_equal(vi, gi, n * sizeof *vi);
        assert_memory_equal(vl, gl, n * sizeof *vl);
        pose_volume_sampler_free(s);
        /* background outside the body and where a preimage leaves the image */
        size_t background = 0;
        for (size_t v = 0; v < n; v++)
            background += gl[v] == 0 && gi[v] == -1000.0f;
        printf("  %zu background voxels\n", background);
        assert_true(background > n / 4);
    }
    free((void *)rests[1].intensity), free((void *)rests[1].labels);
    free((void *)rests[2].intensity), free((void *)rests[2].labels);
    free(gi), free(vi), free(gl), free(vl);
    pose_state_free(st);
}

/* The rest cover (the output grid is the rest grid): the base's tets lie
 * where they rest, so the sampler copies their voxels instead of
 * rasterizing them, after the arm's. Against a grid one plane taller (the
 * same lattice, so no cover: every tet rasterized), the bent arm gives the
 * same bytes except where the turned arm folds into the base's rest
 * space: there the arm shows (rigid arm voxels: f(R^-1 x)), not the base. */
static void test_rest_cover(void **state)
{
    fixture *fx = *state;
    pose_state *st = bent_arm(fx);
    const float a = BENT_DEG * 3.14159265f / 180.0f;
    const size_t n = (size_t)N * N * N;
    float *ci = malloc(n * sizeof *ci), *ri = malloc((n + N * N) * sizeof *ri);
    uint16_t *cl = malloc(n * sizeof *cl), *rl = malloc((n + N * N) * sizeof *rl);
    sample(fx, st, 2, ci, cl);
    pose_volume_grid taller = fx->rest.grid;
    taller.nz = N + 1;
    pose_volume_sampler *s;
    assert_int_equal(pose_volume_sampler_create(fx->rig, &fx->rest, &taller, 2, NULL, &s), POSE_OK);
    assert_int_equal(pose_volume_sample(s, st, ri, rl), POSE_OK);
    pose_volume_sampler_free(s);
    size_t same = 0, folded = 0, base = 0;
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                const size_t v = ((size_t)k * N + j) * N + i;
                const float x = C0 + H * i, y = C0 + H * j, z = C0 + H * k;
                if (x < -0.01f && cl[v] == fx->labels[v])
                    base += ci[v] == fx->intensity[v]; /* copied as it is */
                if (ci[v] == ri[v] && cl[v] == rl[v]) {
                    same++;
                    continue;
                }
                /* a voxel of the base's rest space the arm turned into */
                folded++;
                assert_true(x < 0.0f);
                const float px = cosf(a) * x - sinf(a) * z, pz = sinf(a) * x + cosf(a) * z;
                if (px > 0.02f && inside_lattice(i, j, k))
                    assert_true(fabs(ci[v] - f_lin(px, y, pz)) < 0.05);
            }
    printf("rest cover: %zu voxels the same bytes, %zu where the arm folds into the base; "
           "%zu base voxels copied\n", same, folded, base);
    assert_true(folded > 0 && folded < n / 50);
    assert_true(base > 10000);
    free(ci), free(ri), free(cl), free(rl);
    pose_state_free(st);
}

/* An output grid of its own: 2.5 mm voxels over the middle 10 cm. */
static void test_output_grid(void **state)
{
    fixture *fx = *state;
    pose_state *st;
    assert_int_equal(pose_state_create(fx->rig, &st), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    pose_volume_grid g = {40, 40, 40, {{0.0025f, 0, 0, -0.05f}, {0, 0.0025f, 0, -0.05f}, {0, 0, 0.0025f, -0.05f}}};
    pose_volume_sampler *s;
    assert_int_equal(pose_volume_sampler_create(fx->rig, &fx->rest, &g, 2, NULL, &s), POSE_OK);
    assert_int_equal(pose_volume_sampler_grid(s)->nx, 40);
    float *vi = malloc(40 * 40 * 40 * sizeof *vi);
    assert_int_equal(pose_volume_sample(s, st, vi, NULL), POSE_OK);
    double worst = 0;
    for (int k = 0; k < 40; k++)
        for (int j = 0; j < 40; j++)
            for (int i = 0; i < 40; i++)
                worst = fmax(worst, fabs(vi[(k * 40 + j) * 40 + i] -
                                         f_lin(-0.05f + 0.0025f * i, -0.05f + 0.0025f * j,
                                               -0.05f + 0.0025f * k)));
    printf("2.5 mm output grid: max |HU error| %.2e\n", worst);
    assert_true(worst < 1e-2);
    assert_true(pose_volume_sample_bytes(s, 1, 0) > 40 * 40 * 40 * 4);
    free(vi);
    pose_volume_sampler_free(s);
    pose_state_free(st);
}

static void test_errors(void **state)
{
    fixture *fx = *state;
    pose_volume_sampler *s = (void *)1;
    pose_volume_desc bad = fx->rest;
    bad.grid.nx = 0;
    assert_int_equal(pose_volume_sampler_create(fx->rig, &bad, NULL, 1, NULL, &s), POSE_ERR_INVALID_ARGUMENT);
    assert_null(s);
    assert_non_null(strstr(pose_last_error(), "rest grid"));
    bad = fx->rest;
    bad.grid.affine[2][2] = 0;
    assert_int_equal(pose_volume_sampler_create(fx->rig, &bad, NULL, 1, NULL, &s), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "singular"));
    bad = fx->rest;
    bad.intensity = NULL, bad.labels = NULL;
    assert_int_equal(pose_volume_sampler_create(fx->rig, &bad, NULL, 1, NULL, &s), POSE_ERR_INVALID_ARGUMENT);
    bad = fx->rest;
    bad.labels = NULL;
    assert_int_equal(pose_volume_sampler_create(fx->rig, &bad, NULL, 1, NULL, &s), POSE_OK);
    pose_state *st;
    assert_int_equal(pose_state_create(fx->rig, &st), POSE_OK);
    uint16_t one;
    assert_int_equal(pose_volume_sample(s, st, NULL, &one), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "labels"));
    pose_volume_sampler_free(s);
    pose_state_free(st);
    pose_volume_sampler_free(NULL);
}

/* Rest images stored in the rig (the volumes section): written, loaded
 * (copied and borrowed), the same bytes; sampled from the loaded rig;
 * a damaged record refused naming the section. */
static void test_rig_volumes(void **state)
{
    fixture *fx = *state;
    pose_tet_info ti;
    assert_int_equal(pose_rig_tet_info(fx->rig, &ti), POSE_OK);
    assert_int_equal(pose_rig_volume_count(fx->rig), 0);
    /* Rebuild the fixture's description with the image attached. */
    pose_joint_desc joints[2] = {
        {.name = "base", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, 0, 0}}},
        {.name = "arm", .parent = 0, .rest_model = {{0, 0, 0, 1}, {0.0f, 0, 0}}},
    };
    const pose_rig_volume vols[2] = {{"ct", fx->rest.grid, fx->intensity, fx->labels},
                                     {"labels_only", fx->rest.grid, NULL, fx->labels}};
    pose_rig_desc d = {.joint_count = 2, .joints = joints, .tet_vertex_count = ti.vertex_count,
                       .tet_positions = ti.rest_positions, .tet_count = ti.tet_count,
                       .tets = ti.tets, .tet_labels = ti.labels, .influences = ti.influences,
                       .weight_joints = ti.weight_joints, .weights = ti.weights,
                       .volume_count = 2, .volumes = vols};
    void *buf;
    size_t size;
    assert_int_equal(pose_rig_write_memory(&d, NULL, &buf, &size), POSE_OK);
    pose_rig *rig;
    assert_int_equal(pose_rig_load_memory(buf, size, NULL, &rig), POSE_OK);
    assert_int_equal(pose_rig_volume_count(rig), 2);
    pose_rig_volume v;
    assert_int_equal(pose_rig_get_volume(rig, 0, &v), POSE_OK);
    assert_string_equal(v.name, "ct");
    assert_int_equal(v.grid.nx, N);
    assert_memory_equal(v.grid.affine, fx->rest.grid.affine, sizeof v.grid.affine);
    assert_memory_equal(v.intensity, fx->intensity, (size_t)N * N * N * sizeof(float));
    assert_memory_equal(v.labels, fx->labels, (size_t)N * N * N * sizeof(uint16_t));
    assert_int_equal(pose_rig_get_volume(rig, 1, &v), POSE_OK);
    assert_null(v.intensity);
    assert_memory_equal(v.labels, fx->labels, (size_t)N * N * N * sizeof(uint16_t));
    assert_int_equal(pose_rig_get_volume(rig, 2, &v), POSE_ERR_INVALID_ARGUMENT);
    /* Posing the stored image gives what posing the caller's gives. */
    assert_int_equal(pose_rig_get_volume(rig, 0, &v), POSE_OK);
    pose_volume_desc rd = {v.grid, v.intensity, v.labels, -1000.0f, 0};
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    pose_volume_sampler *s;
    assert_int_equal(pose_volume_sampler_create(rig, &rd, NULL, 2, NULL, &s), POSE_OK);
    uint16_t *vl = malloc((size_t)N * N * N * sizeof *vl);
    assert_int_equal(pose_volume_sample(s, st, NULL, vl), POSE_OK);
    assert_int_equal(vl[((size_t)20 * N + 20) * N + 20], fx->labels[((size_t)20 * N + 20) * N + 20]);
    free(vl);
    pose_volume_sampler_free(s);
    pose_state_free(st);
    pose_rig_free(rig);
    /* A damaged record: flags 0 (the section's CRC is skipped to reach the check). */
    uint8_t *b = buf;
    size_t at = 0;
    for (size_t i = 0; i + 64 < size; i += 64)
        if (memcmp(b + i, "labels_only", 12) == 0)
            at = i;
    assert_true(at > 0);
    memset(b + at + 76, 0, 4);
    pose_load_options lo = {.size = sizeof lo, .flags = POSE_LOAD_SKIP_CRC};
    assert_int_equal(pose_rig_load_memory(buf, size, &lo, &rig), POSE_ERR_INVALID_DATA);
    printf("%s\n", pose_last_error());
    assert_non_null(strstr(pose_last_error(), "section 'volumes'"));
    assert_non_null(strstr(pose_last_error(), "labels_only"));
    free(buf);
    /* Descriptions are checked before writing. */
    pose_rig_volume bad = vols[0];
    bad.grid.affine[1][1] = 0;
    d.volumes = &bad, d.volume_count = 1;
    assert_int_equal(pose_rig_write_memory(&d, NULL, &buf, &size), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "singular"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rest_is_identity),  cmocka_unit_test(test_rigid_turn),
        cmocka_unit_test(test_threads_identical), cmocka_unit_test(test_variants_identical),
        cmocka_unit_test(test_rest_cover),
        cmocka_unit_test(test_output_grid),       cmocka_unit_test(test_errors),
        cmocka_unit_test(test_rig_volumes),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
