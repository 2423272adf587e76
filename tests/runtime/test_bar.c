/* SPDX-License-Identifier: Apache-2.0 */
/* The paper's four-bone bar (pose_synth_bar): LBS collapses under a twist
 * while DQS and CoR keep the cross-section; under a bend CoR keeps the
 * enclosed volume better than LBS. Prints the figures. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "pose/pose.h"
#include "pose_synth.h"
#include "test_math.h"

static pose_rig *g_rig;
static int g_skin = -1;

static int setup(void **unused)
{
    (void)unused;
    pose_synth_rig *syn = NULL;
    if (pose_synth_bar(NULL, &syn) != POSE_OK)
        return -1;
    pose_status s = pose_rig_create(pose_synth_desc(syn), NULL, &g_rig);
    pose_synth_free(syn);
    if (s != POSE_OK)
        return -1;
    for (int t = 0; t < (int)pose_rig_tissue_count(g_rig); t++) {
        pose_tissue_info info;
        pose_rig_tissue_info(g_rig, t, &info);
        if (info.kind == POSE_TISSUE_SKIN)
            g_skin = t;
    }
    return g_skin >= 0 ? 0 : -1;
}

static int teardown(void **unused)
{
    (void)unused;
    pose_rig_free(g_rig);
    return 0;
}

/* Area of the skin ring closest to x (in the plane x = const after a twist
 * about x): vertices of the ring sorted by their rest angle. */
static double ring_area(const float *rest, const float *pos, size_t n, double x)
{
    double best = 1e30;
    for (size_t i = 0; i < n; i++)
        best = fmin(best, fabs(rest[3 * i] - x));
    enum { MAX_RING = 512 };
    size_t idx[MAX_RING], m = 0;
    double ang[MAX_RING];
    for (size_t i = 0; i < n && m < MAX_RING; i++)
        if (fabs(fabs(rest[3 * i] - x) - best) < 1e-6) {
            idx[m] = i;
            ang[m] = atan2(rest[3 * i + 2], rest[3 * i + 1]);
            m++;
        }
    for (size_t a = 1; a < m; a++) /* insertion sort by angle */
        for (size_t b = a; b > 0 && ang[b - 1] > ang[b]; b--) {
            double t = ang[b]; ang[b] = ang[b - 1]; ang[b - 1] = t;
            size_t u = idx[b]; idx[b] = idx[b - 1]; idx[b - 1] = u;
        }
    double area = 0;
    for (size_t k = 0; k < m; k++) {
        const float *p = pos + 3 * idx[k], *q = pos + 3 * idx[(k + 1) % m];
        area += 0.5 * ((double)p[1] * q[2] - (double)q[1] * p[2]);
    }
    return m >= 3 ? fabs(area) : 0.0;
}

static double enclosed_volume(const float *p, const uint32_t *tri, size_t nt)
{
    double v = 0;
    for (size_t f = 0; f < nt; f++) {
        const float *a = p + 3 * tri[3 * f], *b = p + 3 * tri[3 * f + 1], *c = p + 3 * tri[3 * f + 2];
        v += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) +
              a[1] * ((double)b[2] * c[0] - (double)b[0] * c[2]) +
              a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) / 6.0;
    }
    return v;
}

/* Angle statistics between the runtime's normals and area-weighted normals
 * recomputed from the deformed triangles. */
static void compare_normals(const float *p, const float *n, const uint32_t *tri, size_t nt,
                            size_t nv, double *mean_deg, double *max_deg, double *over20)
{
    double *acc = calloc(3 * nv, sizeof(double));
    for (size_t f = 0; f < nt; f++) {
        const float *a = p + 3 * tri[3 * f], *b = p + 3 * tri[3 * f + 1], *c = p + 3 * tri[3 * f + 2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double x[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++)
                acc[3 * tri[3 * f + k] + d] += x[d];
    }
    double sum = 0, worst = 0;
    size_t over = 0;
    for (size_t i = 0; i < nv; i++) {
        double *r = acc + 3 * i, l = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        double d = (r[0] * n[3 * i] + r[1] * n[3 * i + 1] + r[2] * n[3 * i + 2]) / l;
        double ang = acos(fmin(1.0, fmax(-1.0, d))) * 57.29577951308232;
        sum += ang;
        worst = fmax(worst, ang);
        if (ang > 20.0)
            over++;
    }
    free(acc);
    *mean_deg = sum / (double)nv;
    *max_deg = worst;
    *over20 = (double)over / (double)nv;
}

static const char *const k_name[3] = {"LBS", "DQS", "CoR"};

/* 135 deg twist of joint 2 about the bar axis: the worst ring area ratio. */
static void test_twist_135_cross_section(void **unused)
{
    (void)unused;
    pose_tissue_info skin;
    pose_rig_tissue_info(g_rig, g_skin, &skin);
    pose_joint_info j2;
    pose_rig_joint_info(g_rig, 2, &j2);
    double worst[3];
    for (int m = 0; m < 3; m++) {
        pose_state *st;
        pose_state_options opt = {.method = (pose_method)m};
        assert_int_equal(pose_state_create_ex(g_rig, &opt, &st), POSE_OK);
        double q[4];
        dq_axis(q, 1, 0, 0, 135.0);
        /* the joint's local frame may be rotated: express the model-space x axis in it */
        double rc[4] = {-j2.rest_model.rotation[0], -j2.rest_model.rotation[1],
                        -j2.rest_model.rotation[2], j2.rest_model.rotation[3]}, ax[3];
        const double xaxis[3] = {1, 0, 0};
        dq_rot(ax, rc, xaxis);
        dq_axis(q, ax[0], ax[1], ax[2], 135.0);
        const float qf[4] = {(float)q[0], (float)q[1], (float)q[2], (float)q[3]};
        assert_true(pose_set_joint(st, 2, qf) >= 0);
        assert_int_equal(pose_apply(st), POSE_OK);
        size_t n;
        const float *p = pose_tissue_positions(st, g_skin, &n);
        worst[m] = 1e30;
        double x0 = j2.rest_model.translation[0];
        for (double x = x0 - 0.5; x <= x0 + 0.5; x += 0.02) {
            double a0 = ring_area(skin.rest_positions, skin.rest_positions, n, x);
            double a1 = ring_area(skin.rest_positions, p, n, x);
            if (a0 > 0)
                worst[m] = fmin(worst[m], a1 / a0);
        }
        print_message("twist 135 deg, %s: smallest cross-section %.1f %% of rest\n", k_name[m],
                      100.0 * worst[m]);
        pose_state_free(st);
    }
    assert_true(worst[0] < 0.6);          /* LBS: candy wrapper */
    assert_true(worst[1] > 0.95 && worst[1] < 1.05);
    assert_true(worst[2] > 0.95 && worst[2] < 1.05);
}

/* 100 deg bend of joint 2 about an axis across the bar: volume change. */
static void test_bend_100_volume(void **unused)
{
    (void)unused;
    pose_tissue_info skin;
    pose_rig_tissue_info(g_rig, g_skin, &skin);
    double v0 = enclosed_volume(skin.rest_positions, skin.triangles, skin.triangle_count);
    assert_true(fabs(v0) > 0);
    pose_joint_info j2;
    pose_rig_joint_info(g_rig, 2, &j2);
    double change[3];
    for (int m = 0; m < 3; m++) {
        pose_state *st;
        pose_state_options opt = {.method = (pose_method)m};
        assert_int_equal(pose_state_create_ex(g_rig, &opt, &st), POSE_OK);
        double rc[4] = {-j2.rest_model.rotation[0], -j2.rest_model.rotation[1],
                        -j2.rest_model.rotation[2], j2.rest_model.rotation[3]}, ax[3], q[4];
        const double z[3] = {0, 0, 1};
        dq_rot(ax, rc, z);
        dq_axis(q, ax[0], ax[1], ax[2], 100.0);
        const float qf[4] = {(float)q[0], (float)q[1], (float)q[2], (float)q[3]};
        assert_true(pose_set_joint(st, 2, qf) >= 0);
        assert_int_equal(pose_apply(st), POSE_OK);
        size_t n;
        const float *p = pose_tissue_positions(st, g_skin, &n);
        double v = enclosed_volume(p, skin.triangles, skin.triangle_count);
        change[m] = v / v0 - 1.0;
        print_message("bend 100 deg, %s: enclosed volume %+.2f %%\n", k_name[m], 100.0 * change[m]);
        /* normals from the tets' deformation agree with the deformed surface,
         * except where the crease squashes tets flat or inside out */
        double mean_deg, max_deg, over20;
        compare_normals(p, pose_tissue_normals(st, g_skin, &n), skin.triangles,
                        skin.triangle_count, n, &mean_deg, &max_deg, &over20);
        print_message("bend 100 deg, %s: normals vs deformed triangles: mean %.2f deg, "
                      "%.1f %% over 20 deg (max %.1f, in the crease)\n",
                      k_name[m], mean_deg, 100.0 * over20, max_deg);
        assert_true(mean_deg < 2.5);
        assert_true(over20 < 0.03);
        pose_state_free(st);
    }
    assert_true(fabs(change[0]) > 0.005);            /* LBS visibly loses volume */
    assert_true(fabs(change[2]) < fabs(change[0]));  /* CoR keeps more of it */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_twist_135_cross_section),
        cmocka_unit_test(test_bend_100_volume),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
