/* SPDX-License-Identifier: Apache-2.0
 * Acceptance on the bundled CT (issue 11): a coarse pose-bake --labels of
 * data/volume (the fixture volume_ct_bake), then pose_volume_sample:
 *   - the hips' joint centres within 5 mm of the femoral heads' spheres
 *     (the bake's --report);
 *   - at rest the image comes back (labels Dice 1 inside the body);
 *   - hip_l flexed 45 deg: pelvis labels (hip bones, sacrum, L1-L5) and
 *     femur_right Dice >= 0.97 against rest; femur_left's voxel count
 *     within 3 % of rest, its principal axis turned 45 +- 4 deg, its mean
 *     HU within 30 HU of rest; no new holes (uncovered voxels enclosed by
 *     the body);
 *   - the same bytes on 1 and 3 threads.
 * argv[1]: the baked rig; argv[2]: its JSON report. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <pose/pose.h>
#include <pose/volume.h>

#include "vol_nifti.h"

#define UNCOVERED 65535 /* label background: voxels no posed tet covers */

static const char *g_rig, *g_report;

typedef struct ct_fixture {
    pose_rig *rig;
    pv_image ct, seg;
    uint16_t *labels;
    pose_volume_desc rest;
    size_t n;
} ct_fixture;

static int setup(void **state)
{
    ct_fixture *f = calloc(1, sizeof *f);
    char p[1024], err[512];
    const char *d = getenv("POSE_DATA_DIR");
    snprintf(p, sizeof p, "%s/volume/example_ct.nii.gz", d ? d : "data");
    if (pv_nifti_read(p, &f->ct, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    snprintf(p, sizeof p, "%s/volume/example_seg.nii.gz", d ? d : "data");
    if (pv_nifti_read(p, &f->seg, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    if (pose_rig_load(g_rig, &f->rig) != POSE_OK) {
        fprintf(stderr, "%s\n", pose_last_error());
        return -1;
    }
    f->n = pv_image_voxels(&f->ct);
    f->labels = malloc(f->n * sizeof *f->labels);
    for (size_t v = 0; v < f->n; v++)
        f->labels[v] = (uint16_t)f->seg.data[v];
    double m[3][4];
    pv_image_model_affine(&f->ct, m);
    pose_volume_grid g = {(uint32_t)f->ct.nx, (uint32_t)f->ct.ny, (uint32_t)f->ct.nz, {{0}}};
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 4; c++)
            g.affine[a][c] = (float)m[a][c];
    f->rest = (pose_volume_desc){g, f->ct.data, f->labels, -1024.0f, UNCOVERED};
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    ct_fixture *f = *state;
    pose_rig_free(f->rig);
    pv_image_free(&f->ct);
    pv_image_free(&f->seg);
    free(f->labels);
    free(f);
    return 0;
}

static void test_hip_centres_on_the_femoral_heads(void **state)
{
    (void)state;
    FILE *fp = fopen(g_report, "rb");
    assert_non_null(fp);
    static char text[1 << 20];
    size_t len = fread(text, 1, sizeof text - 1, fp);
    fclose(fp);
    text[len] = '\0';
    cJSON *root = cJSON_Parse(text);
    assert_non_null(root);
    const cJSON *heads = cJSON_GetObjectItem(cJSON_GetObjectItem(root, "volume"), "femoral_heads");
    assert_int_equal(cJSON_GetArraySize(heads), 2);
    const cJSON *h;
    cJSON_ArrayForEach(h, heads)
    {
        double dmm = cJSON_GetNumberValue(cJSON_GetObjectItem(h, "joint_to_sphere_mm"));
        double r = cJSON_GetNumberValue(cJSON_GetObjectItem(h, "radius_mm"));
        printf("%s: joint centre %.2f mm from the femoral head sphere (r %.1f mm)\n",
               cJSON_GetStringValue(cJSON_GetObjectItem(h, "joint")), dmm, r);
        assert_true(dmm < 5.0);
        assert_true(r > 15.0 && r < 30.0); /* an adult femoral head */
    }
    cJSON_Delete(root);
}

/* The bake stored the scan in the rig (the volumes section): the same
 * labels and HU, on the scan's grid in model space. */
static void test_rig_holds_the_scan(void **state)
{
    ct_fixture *f = *state;
    assert_int_equal(pose_rig_volume_count(f->rig), 1);
    pose_rig_volume v;
    assert_int_equal(pose_rig_get_volume(f->rig, 0, &v), POSE_OK);
    assert_string_equal(v.name, "scan");
    assert_int_equal(v.grid.nx, f->rest.grid.nx);
    assert_int_equal(v.grid.ny, f->rest.grid.ny);
    assert_int_equal(v.grid.nz, f->rest.grid.nz);
    assert_memory_equal(v.grid.affine, f->rest.grid.affine, sizeof v.grid.affine);
    assert_non_null(v.intensity);
    assert_non_null(v.labels);
    assert_memory_equal(v.labels, f->labels, f->n * sizeof *f->labels);
    assert_memory_equal(v.intensity, f->ct.data, f->n * sizeof *f->ct.data);
}

static pose_state *posed(const ct_fixture *f, float hip_l_flexion)
{
    pose_state *st;
    assert_int_equal(pose_state_create(f->rig, &st), POSE_OK);
    if (hip_l_flexion != 0.0f) {
        int j = pose_rig_find_joint(f->rig, "hip_l");
        assert_true(j >= 0);
        const float deg[3] = {hip_l_flexion, 0, 0};
        assert_int_equal(pose_set_joint_clinical(st, j, deg), POSE_OK);
    }
    assert_int_equal(pose_apply(st), POSE_OK);
    return st;
}

/* The flexed thigh leaves the scan's field of view (the distal femur turns
 * out of its last slices): the flex test samples onto the rest grid grown
 * by PAD voxels on every side, a caller-chosen output grid. */
#define PAD 24

static pose_volume_grid padded(const ct_fixture *f)
{
    pose_volume_grid g = f->rest.grid;
    g.nx += 2 * PAD, g.ny += 2 * PAD, g.nz += 2 * PAD;
    for (int a = 0; a < 3; a++)
        g.affine[a][3] -= PAD * (g.affine[a][0] + g.affine[a][1] + g.affine[a][2]);
    return g;
}

static void sample_on(const ct_fixture *f, pose_state *st, int threads, const pose_volume_grid *g,
                      float *vi, uint16_t *vl)
{
    pose_volume_sampler *s;
    assert_int_equal(pose_volume_sampler_create(f->rig, &f->rest, g, threads, NULL, &s), POSE_OK);
    assert_int_equal(pose_volume_sample(s, st, vi, vl), POSE_OK);
    pose_volume_sampler_free(s);
}

static void sample(const ct_fixture *f, pose_state *st, int threads, float *vi, uint16_t *vl)
{
    pose_volume_sampler *s;
    assert_int_equal(pose_volume_sampler_create(f->rig, &f->rest, NULL, threads, NULL, &s), POSE_OK);
    assert_int_equal(pose_volume_sample(s, st, vi, vl), POSE_OK);
    pose_volume_sampler_free(s);
}

static double dice(const uint16_t *a, const uint16_t *b, size_t n, uint16_t l)
{
    size_t na = 0, nb = 0, both = 0;
    for (size_t v = 0; v < n; v++) {
        na += a[v] == l;
        nb += b[v] == l;
        both += a[v] == l && b[v] == l;
    }
    return na + nb ? 2.0 * both / (double)(na + nb) : 1.0;
}

/* Uncovered voxels that the border cannot reach through uncovered voxels. */
static size_t holes(const uint16_t *lab, int nx, int ny, int nz)
{
    size_t n = (size_t)nx * ny * nz, count = 0, head = 0, tail = 0;
    uint8_t *seen = calloc(n, 1);
    size_t *q = malloc(n * sizeof *q);
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                size_t v = ((size_t)k * ny + j) * nx + i;
                if ((i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1) &&
                    lab[v] == UNCOVERED)
                    seen[v] = 1, q[tail++] = v;
            }
    while (head < tail) {
        size_t v = q[head++];
        int i = (int)(v % nx), j = (int)(v / nx % ny), k = (int)(v / ((size_t)nx * ny));
        const int d[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        for (int e = 0; e < 6; e++) {
            int a = i + d[e][0], b = j + d[e][1], c = k + d[e][2];
            if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || c >= nz)
                continue;
            size_t w = ((size_t)c * ny + b) * nx + a;
            if (!seen[w] && lab[w] == UNCOVERED)
                seen[w] = 1, q[tail++] = w;
        }
    }
    for (size_t v = 0; v < n; v++) {
        count += lab[v] == UNCOVERED && !seen[v];
    }
    free(seen), free(q);
    return count;
}

/* Voxel count, mean HU and principal axis (model space) of label l on grid g. */
static size_t stats(const pose_volume_grid *g, const uint16_t *lab, const float *hu, uint16_t l,
                    double *mean_hu, double axis[3])
{
    double s[3] = {0}, ss[3][3] = {{0}}, h = 0;
    size_t cnt = 0;
    for (uint32_t k = 0; k < g->nz; k++)
        for (uint32_t j = 0; j < g->ny; j++)
            for (uint32_t i = 0; i < g->nx; i++) {
                size_t v = ((size_t)k * g->ny + j) * g->nx + i;
                if (lab[v] != l)
                    continue;
                double p[3];
                for (int a = 0; a < 3; a++)
                    p[a] = g->affine[a][0] * i + g->affine[a][1] * j + g->affine[a][2] * k +
                           g->affine[a][3];
                for (int a = 0; a < 3; a++) {
                    s[a] += p[a];
                    for (int b = 0; b < 3; b++)
                        ss[a][b] += p[a] * p[b];
                }
                h += hu[v];
                cnt++;
            }
    double c[3][3];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            c[a][b] = ss[a][b] / cnt - s[a] * s[b] / ((double)cnt * cnt);
    /* Power iteration for the largest eigenvector. */
    double x[3] = {0.3, 0.4, 0.8};
    for (int it = 0; it < 200; it++) {
        double y[3] = {0};
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                y[a] += c[a][b] * x[b];
        double l2 = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
        for (int a = 0; a < 3; a++)
            x[a] = y[a] / l2;
    }
    memcpy(axis, x, sizeof x);
    *mean_hu = h / (double)cnt;
    return cnt;
}

/* Angle between two axes seen along the hip's flexion axis (model y, the
 * left-right line): how far the segment turned about the hip. The in-view
 * proximal femur's principal axis runs partly along the neck, so its full
 * 3-D angle understates a flexion; its sagittal projection turns by it. */
static double sagittal_angle(const double a[3], const double b[3])
{
    double la = sqrt(a[0] * a[0] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[2] * b[2]);
    double c = fabs(a[0] * b[0] + a[2] * b[2]) / (la * lb);
    return acos(c < 1.0 ? c : 1.0) * 180.0 / 3.14159265358979;
}

static void test_rest_comes_back(void **state)
{
    ct_fixture *f = *state;
    pose_state *st = posed(f, 0.0f);
    float *vi = malloc(f->n * sizeof *vi);
    uint16_t *vl = malloc(f->n * sizeof *vl);
    sample(f, st, 2, vi, vl);
    size_t covered = 0, same = 0, off = 0;
    double worst = 0;
    for (size_t v = 0; v < f->n; v++) {
        if (vl[v] == UNCOVERED)
            continue;
        covered++;
        same += vl[v] == f->labels[v];
        worst = fmax(worst, fabs(vi[v] - f->ct.data[v]));
        off += fabs(vi[v] - f->ct.data[v]) > 0.01;
    }
    printf("rest: %zu voxels covered by the tets, labels equal on %.4f %%, HU equal but on %zu "
           "(mesh cracks filled from their neighbours; max |dHU| %.3g)\n",
           covered, 100.0 * same / covered, off, worst);
    assert_true(covered > 700000);
    assert_true(same == covered);
    assert_true(off <= 20);
    free(vi), free(vl);
    pose_state_free(st);
}

static void test_flex_hip_l_45(void **state)
{
    ct_fixture *f = *state;
    pose_state *rest = posed(f, 0.0f), *st = posed(f, 45.0f);
    const pose_volume_grid g = padded(f);
    const size_t n = (size_t)g.nx * g.ny * g.nz;
    float *ri = malloc(n * sizeof *ri), *pi = malloc(n * sizeof *pi);
    uint16_t *rl = malloc(n * sizeof *rl), *pl = malloc(n * sizeof *pl);
    sample_on(f, rest, 2, &g, ri, rl);
    sample_on(f, st, 2, &g, pi, pl);
    /* Pelvis and the other leg stay. */
    static const struct {
        uint16_t id;
        const char *name;
    } fixed[] = {{90, "hip_left"}, {91, "hip_right"}, {92, "sacrum"}, {18, "vertebrae_L5"},
                 {19, "vertebrae_L4"}, {20, "vertebrae_L3"}, {21, "vertebrae_L2"},
                 {22, "vertebrae_L1"}, {89, "femur_right"}};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++) {
        double d = dice(rl, pl, n, fixed[i].id);
        printf("  %-14s Dice %.4f\n", fixed[i].name, d);
        assert_true(d >= 0.97);
    }
    double hu_r, hu_p, ax_r[3], ax_p[3];
    size_t n_r = stats(&g, rl, ri, 88, &hu_r, ax_r), n_p = stats(&g, pl, pi, 88, &hu_p, ax_p);
    double ang = sagittal_angle(ax_r, ax_p);
    double d3 = acos(fmin(1.0, fabs(ax_r[0] * ax_p[0] + ax_r[1] * ax_p[1] + ax_r[2] * ax_p[2]))) *
                180.0 / 3.14159265358979;
    double dice_l = dice(rl, pl, n, 88);
    size_t h_r = holes(rl, (int)g.nx, (int)g.ny, (int)g.nz);
    size_t h_p = holes(pl, (int)g.nx, (int)g.ny, (int)g.nz);
    printf("femur_left: %zu -> %zu voxels (%+.2f %%), principal axis turned %.1f deg about the "
           "hip (%.1f deg in 3-D), mean HU %.1f -> %.1f, Dice against rest %.3f\n"
           "holes (uncovered voxels enclosed by the body): rest %zu, posed %zu\n",
           n_r, n_p, 100.0 * ((double)n_p - (double)n_r) / (double)n_r, ang, d3, hu_r, hu_p,
           dice_l, h_r, h_p);
    assert_true(fabs((double)n_p - (double)n_r) <= 0.03 * (double)n_r);
    assert_true(fabs(ang - 45.0) <= 4.0);
    assert_true(fabs(hu_p - hu_r) <= 30.0);
    assert_true(dice_l < 0.8); /* it moved (the head turns in place, the neck and shaft swing) */
    assert_true(h_p <= h_r);

    /* The same bytes on 1 and 3 threads. */
    float *vi = malloc(n * sizeof *vi);
    uint16_t *vl = malloc(n * sizeof *vl);
    for (int t = 1; t <= 3; t += 2) {
        sample_on(f, st, t, &g, vi, vl);
        assert_memory_equal(vi, pi, n * sizeof *vi);
        assert_memory_equal(vl, pl, n * sizeof *vl);
    }
    free(vi), free(vl), free(ri), free(pi), free(rl), free(pl);
    pose_state_free(rest);
    pose_state_free(st);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_volume_ct RIG REPORT.json\n");
        return 2;
    }
    g_rig = argv[1];
    g_report = argv[2];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hip_centres_on_the_femoral_heads),
        cmocka_unit_test(test_rig_holds_the_scan),
        cmocka_unit_test(test_rest_comes_back),
        cmocka_unit_test(test_flex_hip_l_45),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
