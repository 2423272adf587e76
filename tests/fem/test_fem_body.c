/* SPDX-License-Identifier: Apache-2.0 */
/* POSE_FEM on the body baked from the bundled anatomy (full_body template):
 * skin volume against rest at the issue's five postures, CoR vs FEM
 * (|dV| <= 0.3 % with FEM); bones rigid; the same result for any thread
 * count. The rig comes from the fem_body_bake fixture (POSE_FEM_RIG). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fem_body_rig.h"
#include "fem_postures.h"
#include "fem_volume.h"
#include "pose/pose.h"

static pose_rig *g_rig;
static int g_skin = -1;
static double g_rest_volume;

static void set_posture(pose_state *st, const fx_posture *p)
{
    assert_int_equal(pose_reset(st), POSE_OK);
    for (int s = 0; s < 2; s++) {
        int j = pose_rig_find_joint(g_rig, p->joints[s]);
        assert_true(j >= 0);
        assert_true(pose_set_joint_clinical(st, j, p->deg) >= 0);
    }
}

static double skin_volume(const pose_state *st)
{
    pose_tissue_info info;
    assert_int_equal(pose_rig_tissue_info(g_rig, g_skin, &info), POSE_OK);
    size_t n;
    const float *pos = pose_tissue_positions(st, g_skin, &n);
    return fx_mesh_volume(pos, info.triangles, info.triangle_count);
}

static int setup(void **state)
{
    (void)state;
    if (!(g_rig = fem_body_rig_load()))
        return -1;
    for (size_t t = 0; t < pose_rig_tissue_count(g_rig); t++) {
        pose_tissue_info info;
        pose_rig_tissue_info(g_rig, (int)t, &info);
        if (info.kind == POSE_TISSUE_SKIN)
            g_skin = (int)t;
    }
    if (g_skin < 0)
        return -1;
    pose_tissue_info info;
    pose_rig_tissue_info(g_rig, g_skin, &info);
    g_rest_volume = fx_mesh_volume(info.rest_positions, info.triangles, info.triangle_count);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    pose_rig_free(g_rig);
    return 0;
}

/* Skin volume at each posture: FEM within 0.3 % of rest. Skinning's
 * changes are printed beside it (what the refinement corrects). */
static void test_volume(void **state)
{
    (void)state;
    assert_true(pose_rig_has_fem(g_rig));
    pose_tet_info tet;
    assert_int_equal(pose_rig_tet_info(g_rig, &tet), POSE_OK);
    const pose_method skinning = tet.cor ? POSE_COR : POSE_DQS;
    pose_state_options so = {.size = sizeof so, .threads = 2};
    pose_state *sk, *fem;
    assert_int_equal(pose_state_create_ex(g_rig, &so, &sk), POSE_OK);
    assert_int_equal(pose_state_create_ex(g_rig, &so, &fem), POSE_OK);
    assert_int_equal(pose_set_method(sk, skinning), POSE_OK);
    assert_int_equal(pose_set_method(fem, POSE_FEM), POSE_OK);
    printf("skin at rest: %.3f L; %zu tet vertices, %zu tets\n", g_rest_volume * 1e3,
           tet.vertex_count, tet.tet_count);
    double worst = 0.0;
    for (size_t i = 0; i < FX_POSTURES; i++) {
        set_posture(sk, &fx_postures[i]);
        set_posture(fem, &fx_postures[i]);
        assert_int_equal(pose_apply(sk), POSE_OK);
        assert_int_equal(pose_apply(fem), POSE_OK);
        double vs = skin_volume(sk), vf = skin_volume(fem);
        double ds = (vs - g_rest_volume) / g_rest_volume, df = (vf - g_rest_volume) / g_rest_volume;
        pose_fem_stats fs = {.size = sizeof fs};
        assert_int_equal(pose_get_fem_stats(fem, &fs), POSE_OK);
        printf("%-22s %s %+7.3f L (%+6.2f %%)   FEM %+7.3f L (%+6.2f %%)   %d outer, %d CG, "
               "residual %.3g\n",
               fx_postures[i].name, skinning == POSE_COR ? "CoR" : "DQS",
               (vs - g_rest_volume) * 1e3, 100 * ds, (vf - g_rest_volume) * 1e3, 100 * df,
               fs.outer_iterations, fs.cg_iterations, fs.residual);
        if (fabs(df) > worst)
            worst = fabs(df);
    }
    printf("largest FEM volume change: %.3f %%\n", 100 * worst);
    assert_true(worst <= 0.003);
    pose_state_free(sk);
    pose_state_free(fem);
}

/* Joint j's rigid motion applied to rest point p. */
static void rigid(const pose_transform *rest, const pose_transform *world, const float *p, double out[3])
{
    const float qi[4] = {-rest->rotation[0], -rest->rotation[1], -rest->rotation[2],
                         rest->rotation[3]};
    double d[3] = {(double)p[0] - rest->translation[0], (double)p[1] - rest->translation[1],
                   (double)p[2] - rest->translation[2]};
    double l[3];
    fx_rotate(qi, d, l);
    fx_rotate(world->rotation, l, out);
    for (int a = 0; a < 3; a++)
        out[a] += world->translation[a];
}

/* Bones are rigid: every vertex of one bone's tets (not shared with
 * another bone's), and every vertex of every bone tissue (embedded partly
 * in soft tets, which the refinement moves), stays within 0.1 mm of the
 * bone's rigid motion (the joint's world frame times the inverse of its
 * rest frame). */
static void test_bones_rigid(void **state)
{
    (void)state;
    pose_tet_info tet;
    assert_int_equal(pose_rig_tet_info(g_rig, &tet), POSE_OK);
    /* per vertex: the bone label of its bone tets; 0 none, -1 two bones
     * (skinning blends those, as any method does) */
    int *bone = calloc(tet.vertex_count, sizeof(int));
    assert_non_null(bone);
    for (size_t t = 0; t < tet.tet_count; t++)
        for (int c = 0; c < 4 && tet.labels[t] > 0; c++) {
            int *b = &bone[tet.tets[4 * t + (size_t)c]];
            int l = tet.labels[t];
            *b = *b == 0 ? l : (*b != l ? -1 : *b);
        }
    pose_state *st;
    assert_int_equal(pose_state_create(g_rig, &st), POSE_OK);
    assert_int_equal(pose_set_method(st, POSE_FEM), POSE_OK);
    size_t nj = pose_rig_joint_count(g_rig);
    pose_joint_info *ji = calloc(nj, sizeof *ji);
    pose_transform *w = calloc(nj, sizeof *w);
    assert_true(ji && w);
    for (size_t j = 0; j < nj; j++)
        assert_int_equal(pose_rig_joint_info(g_rig, (int)j, &ji[j]), POSE_OK);
    double worst = 0.0, surface = 0.0;
    size_t held = 0;
    for (size_t i = 0; i < FX_POSTURES; i++) {
        set_posture(st, &fx_postures[i]);
        assert_int_equal(pose_apply(st), POSE_OK);
        for (size_t j = 0; j < nj; j++)
            assert_int_equal(pose_joint_world(st, (int)j, &w[j]), POSE_OK);
        const float *x = pose_tet_positions(st, NULL);
        for (size_t v = 0; v < tet.vertex_count; v++) {
            if (bone[v] <= 0)
                continue;
            size_t j = (size_t)bone[v] - 1;
            double r[3];
            rigid(&ji[j].rest_model, &w[j], tet.rest_positions + 3 * v, r);
            double e = sqrt((r[0] - x[3 * v]) * (r[0] - x[3 * v]) + (r[1] - x[3 * v + 1]) * (r[1] - x[3 * v + 1]) +
                            (r[2] - x[3 * v + 2]) * (r[2] - x[3 * v + 2]));
            if (e > worst)
                worst = e;
            held += i == 0;
        }
        double d = fx_bone_deviation(g_rig, st);
        assert_true(d >= 0.0);
        if (d > surface)
            surface = d;
    }
    printf("bones: %zu tet vertices of one bone's tets, largest deviation from its rigid motion "
           "%.4f mm; bone tissues (embedded partly in soft tets): %.4f mm\n",
           held, worst * 1e3, surface * 1e3);
    assert_true(held > 0);
    assert_true(worst <= 1e-4);
    assert_true(surface <= 1e-4);
    free(ji);
    free(w);
    free(bone);
    pose_state_free(st);
}

/* Bone tissues move rigidly with the skinning methods too: the transfer
 * would carry the vertices the bake embedded in soft tets, or in the next
 * bone's, with the tissue around them (the femoral heads 32 mm off their
 * femur at hip flexion 90 with LBS, DQS and CoR alike). */
static void test_bones_rigid_every_method(void **state)
{
    (void)state;
    pose_tet_info tet;
    assert_int_equal(pose_rig_tet_info(g_rig, &tet), POSE_OK);
    const pose_method methods[3] = {POSE_LBS, POSE_DQS, POSE_COR};
    pose_state *st;
    assert_int_equal(pose_state_create(g_rig, &st), POSE_OK);
    for (int m = 0; m < (tet.cor ? 3 : 2); m++) {
        assert_int_equal(pose_set_method(st, methods[m]), POSE_OK);
        double worst = 0.0;
        for (size_t i = 0; i < FX_POSTURES; i++) {
            set_posture(st, &fx_postures[i]);
            assert_int_equal(pose_apply(st), POSE_OK);
            const double d = fx_bone_deviation(g_rig, st);
            assert_true(d >= 0.0);
            worst = d > worst ? d : worst;
        }
        printf("method %d: bone tissues within %.4f mm of their rigid motion\n", (int)methods[m],
               worst * 1e3);
        assert_true(worst <= 1e-4);
    }
    pose_state_free(st);
}

/* Every tissue's positions and normals, one after another, into out (st
 * NULL: only count); returns the floats written. */
static size_t tissue_outputs(const pose_state *st, float *out)
{
    size_t at = 0;
    for (size_t t = 0; t < pose_rig_tissue_count(g_rig); t++) {
        pose_tissue_info info;
        assert_int_equal(pose_rig_tissue_info(g_rig, (int)t, &info), POSE_OK);
        const size_t n = info.vertex_count;
        if (st) {
            memcpy(out + at, pose_tissue_positions(st, (int)t, NULL), 3 * n * sizeof(float));
            memcpy(out + at + 3 * n, pose_tissue_normals(st, (int)t, NULL), 3 * n * sizeof(float));
        }
        at += 6 * n;
    }
    return at;
}

/* 1, 2 and 3 threads: the same bits, tet mesh and tissues. */
static void test_threads(void **state)
{
    (void)state;
    pose_tet_info tet;
    assert_int_equal(pose_rig_tet_info(g_rig, &tet), POSE_OK);
    const size_t nx = 3 * tet.vertex_count, nt = tissue_outputs(NULL, NULL);
    float *ref = malloc((nx + 2 * nt) * sizeof(float));
    assert_non_null(ref);
    float *ref_tissues = ref + nx, *tissues = ref_tissues + nt;
    for (int threads = 1; threads <= 3; threads++) {
        pose_state_options so = {.size = sizeof so, .threads = threads, .method = POSE_FEM};
        pose_state *st;
        assert_int_equal(pose_state_create_ex(g_rig, &so, &st), POSE_OK);
        set_posture(st, &fx_postures[0]);
        assert_int_equal(pose_apply(st), POSE_OK);
        set_posture(st, &fx_postures[4]);
        assert_int_equal(pose_apply(st), POSE_OK);
        const float *x = pose_tet_positions(st, NULL);
        if (threads == 1) {
            memcpy(ref, x, nx * sizeof(float));
            tissue_outputs(st, ref_tissues);
        } else {
            assert_memory_equal(ref, x, nx * sizeof(float));
            tissue_outputs(st, tissues);
            assert_memory_equal(ref_tissues, tissues, nt * sizeof(float));
        }
        pose_state_free(st);
    }
    free(ref);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_volume),
        cmocka_unit_test(test_bones_rigid),
        cmocka_unit_test(test_bones_rigid_every_method),
        cmocka_unit_test(test_threads),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
