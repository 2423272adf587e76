/* SPDX-License-Identifier: Apache-2.0 */
/* pose_state API on hand-made bars: invalid input, rest pose, rigid motion,
 * hierarchy, Euler orders, limits, transfer, threads, allocation. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fixture.h"
#include "pose/pose.h"
#include "test_math.h"

static const pose_method k_methods[3] = {POSE_LBS, POSE_DQS, POSE_COR};

/* ---- allocation counting */
typedef struct counter {
    int allocs, frees, misaligned;
} counter;

static void *count_alloc(size_t size, size_t align, void *user)
{
    counter *c = user;
    c->allocs++;
    void *p = NULL;
    if (posix_memalign(&p, align < sizeof(void *) ? sizeof(void *) : align, size) != 0)
        return NULL;
    if (((uintptr_t)p & 63u) != 0 && align >= 64)
        c->misaligned++;
    if (align < 64)
        c->misaligned++;
    return p;
}

static void count_free(void *p, void *user)
{
    ((counter *)user)->frees++;
    free(p);
}

static void test_invalid_input(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    o.with_cor = 0;
    pose_rig *rig = fx_bar(&o);
    pose_state *st = (pose_state *)&o; /* must be overwritten with NULL */
    assert_int_equal(pose_state_create(NULL, &st), POSE_ERR_INVALID_ARGUMENT);
    assert_null(st);
    assert_int_equal(pose_state_create(rig, NULL), POSE_ERR_INVALID_ARGUMENT);
    pose_state_options bad = {.threads = -1};
    assert_int_equal(pose_state_create_ex(rig, &bad, &st), POSE_ERR_INVALID_ARGUMENT);
    pose_state_options half = {.allocator = {.alloc = NULL, .free = count_free}};
    assert_int_equal(pose_state_create_ex(rig, &half, &st), POSE_ERR_INVALID_ARGUMENT);
    pose_state_options cor = {.method = POSE_COR};
    assert_int_equal(pose_state_create_ex(rig, &cor, &st), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);

    const float nanq[4] = {NAN, 0, 0, 1}, zero[4] = {0, 0, 0, 0}, id[4] = {0, 0, 0, 1};
    const float deg[3] = {10, 20, 30}, infdeg[3] = {INFINITY, 0, 0};
    assert_int_equal(pose_set_joint(NULL, 0, id), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint(st, -1, id), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint(st, 2, id), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "out of range"));
    assert_int_equal(pose_set_joint(st, 0, NULL), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint(st, 0, nanq), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint(st, 0, zero), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint_euler(st, 0, deg, (pose_euler_order)6), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint_euler(st, 0, infdeg, POSE_EULER_XYZ), POSE_ERR_INVALID_ARGUMENT);
    float q[4];
    assert_int_equal(pose_get_joint(st, 5, q), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_root(st, NULL, zero), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_method(st, (pose_method)7), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_method(st, POSE_COR), POSE_ERR_UNSUPPORTED);
    assert_non_null(strstr(pose_last_error(), "centres of rotation"));
    assert_int_equal(pose_get_method(st), POSE_LBS);
    assert_int_equal(pose_set_threads(st, -2), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_apply(NULL), POSE_ERR_INVALID_ARGUMENT);
    pose_transform w;
    assert_int_equal(pose_joint_world(st, 2, &w), POSE_ERR_INVALID_ARGUMENT);
    size_t n = 99;
    assert_null(pose_tissue_positions(st, 2, &n));
    assert_null(pose_tissue_normals(st, -1, &n));
    assert_null(pose_tet_positions(NULL, &n));
    /* a failed call changed nothing */
    assert_int_equal(pose_get_joint(st, 0, q), POSE_OK);
    assert_memory_equal(q, id, sizeof id);
    pose_state_free(st);
    pose_state_free(NULL);
    pose_rig_free(rig);
}

static void assert_rest(pose_state *st, const pose_rig *rig)
{
    pose_tet_info ti;
    assert_int_equal(pose_rig_tet_info(rig, &ti), POSE_OK);
    size_t n;
    const float *tp = pose_tet_positions(st, &n);
    assert_int_equal(n, ti.vertex_count);
    assert_memory_equal(tp, ti.rest_positions, 3 * n * sizeof(float)); /* bit for bit */
    for (int t = 0; t < (int)pose_rig_tissue_count(rig); t++) {
        pose_tissue_info info;
        assert_int_equal(pose_rig_tissue_info(rig, t, &info), POSE_OK);
        const float *p = pose_tissue_positions(st, t, &n);
        assert_int_equal(n, info.vertex_count);
        for (size_t i = 0; i < 3 * n; i++)
            assert_true(fabsf(p[i] - info.rest_positions[i]) <= 1e-6f * (1.0f + fabsf(p[i])));
    }
}

static void test_rest_pose_exact(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    pose_rig *rig = fx_bar(&o);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_rest(st, rig); /* before the first apply */
    size_t n;
    const float *n0 = pose_tissue_normals(st, 0, &n);
    float *rest_n = malloc(3 * n * sizeof(float));
    memcpy(rest_n, n0, 3 * n * sizeof(float));
    /* the bar's corner normals point out diagonally */
    assert_near(rest_n[0], -1.0f / sqrtf(3.0f), 1e-6f);
    for (int m = 0; m < 3; m++) {
        assert_int_equal(pose_set_method(st, k_methods[m]), POSE_OK);
        assert_int_equal(pose_apply(st), POSE_OK);
        assert_rest(st, rig);
        const float *nn = pose_tissue_normals(st, 0, &n);
        for (size_t i = 0; i < 3 * n; i++)
            assert_near(nn[i], rest_n[i], 1e-4f);
    }
    /* and again after posing and resetting */
    const float deg[3] = {20, -35, 50};
    assert_int_equal(pose_set_joint_euler(st, 1, deg, POSE_EULER_ZXY), POSE_OK);
    const float root_t[3] = {1, 2, 3}, root_q[4] = {0, 0.6f, 0, 0.8f};
    assert_int_equal(pose_set_root(st, root_t, root_q), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    assert_int_equal(pose_reset(st), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    assert_rest(st, rig);
    free(rest_n);
    pose_state_free(st);
    pose_rig_free(rig);
}

/* A rotation of joint 1 moves points in its exclusive region rigidly about
 * its rest origin, for every method; normals rotate with them. */
static void test_rigid_bone_motion(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    o.inner_points = 400;
    pose_rig *rig = fx_bar(&o);
    pose_joint_info ji;
    assert_int_equal(pose_rig_joint_info(rig, 1, &ji), POSE_OK);
    double local[4];
    dq_axis(local, 0.3, -1.0, 0.5, 70.0);
    const float qf[4] = {(float)local[0], (float)local[1], (float)local[2], (float)local[3]};
    /* model-space rotation Q q Q* about the joint's rest origin */
    double Q[4] = {ji.rest_model.rotation[0], ji.rest_model.rotation[1],
                   ji.rest_model.rotation[2], ji.rest_model.rotation[3]};
    double Qc[4] = {-Q[0], -Q[1], -Q[2], Q[3]}, tmp[4], R[4];
    dq_mul(tmp, Q, local);
    dq_mul(R, tmp, Qc);
    const double c[3] = {ji.rest_model.translation[0], ji.rest_model.translation[1],
                         ji.rest_model.translation[2]};
    pose_tissue_info inner, skin;
    pose_rig_tissue_info(rig, 1, &inner);
    pose_rig_tissue_info(rig, 0, &skin);
    for (int m = 0; m < 3; m++) {
        pose_state *st;
        pose_state_options opt = {.method = k_methods[m], .threads = 2};
        assert_int_equal(pose_state_create_ex(rig, &opt, &st), POSE_OK);
        assert_int_equal(pose_set_joint(st, 1, qf), POSE_OK);
        assert_int_equal(pose_apply(st), POSE_OK);
        size_t n;
        const float *p = pose_tissue_positions(st, 1, &n);
        int checked = 0;
        double worst = 0.0;
        for (size_t i = 0; i < n; i++) {
            const float *r = inner.rest_positions + 3 * i;
            if (r[0] <= 3.0f)
                continue; /* only the cube weighted by joint 1 alone */
            double d[3] = {r[0] - c[0], r[1] - c[1], r[2] - c[2]}, e[3];
            dq_rot(e, R, d);
            double err = 0, mag = 0;
            for (int k = 0; k < 3; k++) {
                e[k] += c[k];
                err += (p[3 * i + k] - e[k]) * (p[3 * i + k] - e[k]);
                mag += e[k] * e[k];
            }
            worst = fmax(worst, sqrt(err / mag));
            checked++;
        }
        assert_true(checked > 20);
        if (worst >= 1e-5)
            print_error("method %d: relative error %.3g\n", m, worst);
        assert_true(worst < 1e-5);
        /* skin normals at the far end rotate like the bone */
        const float *nn = pose_tissue_normals(st, 0, &n);
        const float *n_rest = NULL;
        pose_state *rest;
        assert_int_equal(pose_state_create(rig, &rest), POSE_OK);
        n_rest = pose_tissue_normals(rest, 0, &n);
        for (size_t i = 0; i < n; i++) {
            if (skin.rest_positions[3 * i] < 4.0f)
                continue;
            double a[3] = {n_rest[3 * i], n_rest[3 * i + 1], n_rest[3 * i + 2]}, b[3];
            dq_rot(b, R, a);
            for (int k = 0; k < 3; k++)
                assert_near(nn[3 * i + k], b[k], 2e-4);
        }
        pose_state_free(rest);
        pose_state_free(st);
    }
    pose_rig_free(rig);
}

/* World frames compose through the chain: world_j = world_parent o rest_local_j o q_j. */
static void test_world_transforms_compose(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    o.cubes = 6;
    o.joints = 3;
    pose_rig *rig = fx_bar(&o);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    double q[3][4];
    dq_axis(q[0], 0, 0, 1, 25);
    dq_axis(q[1], 1, 1, 0, -40);
    dq_axis(q[2], 0.2, 1, -0.3, 65);
    for (int j = 0; j < 3; j++) {
        const float f[4] = {(float)q[j][0], (float)q[j][1], (float)q[j][2], (float)q[j][3]};
        assert_int_equal(pose_set_joint(st, j, f), POSE_OK);
    }
    double rq[4];
    dq_axis(rq, 1, 0, 0, 90);
    const float root_t[3] = {0.5f, -2.0f, 3.0f};
    const float root_q[4] = {(float)rq[0], (float)rq[1], (float)rq[2], (float)rq[3]};
    assert_int_equal(pose_set_root(st, root_t, root_q), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);

    dx world[3], root = {{rq[0], rq[1], rq[2], rq[3]}, {0.5, -2.0, 3.0}};
    for (int j = 0; j < 3; j++) {
        pose_joint_info ji;
        assert_int_equal(pose_rig_joint_info(rig, j, &ji), POSE_OK);
        dx local = {{ji.rest_local.rotation[0], ji.rest_local.rotation[1],
                     ji.rest_local.rotation[2], ji.rest_local.rotation[3]},
                    {ji.rest_local.translation[0], ji.rest_local.translation[1],
                     ji.rest_local.translation[2]}};
        dx rot = {{q[j][0], q[j][1], q[j][2], q[j][3]}, {0, 0, 0}};
        dx parent = ji.parent < 0 ? root : world[ji.parent];
        dx a = dx_compose(&parent, &local);
        world[j] = dx_compose(&a, &rot);
        pose_transform w;
        assert_int_equal(pose_joint_world(st, j, &w), POSE_OK);
        assert_true(dq_dist(world[j].q, w.rotation) < 2e-6);
        for (int k = 0; k < 3; k++)
            assert_near(w.translation[k], world[j].t[k], 2e-5);
    }
    /* the last joint's own frame origin moved with it */
    pose_state_free(st);
    pose_rig_free(rig);
}

/* Euler angles in any order agree with the product of axis quaternions. */
static void test_euler_orders(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    pose_rig *rig = fx_bar(&o);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    static const int axes[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    const float deg[3] = {-37.0f, 61.0f, 128.0f};
    for (int order = 0; order < 6; order++) {
        double r[4] = {0, 0, 0, 1};
        for (int s = 0; s < 3; s++) {
            int a = axes[order][s];
            double q[4];
            dq_axis(q, a == 0, a == 1, a == 2, deg[a]);
            dq_mul(r, r, q);
        }
        float got[4];
        assert_int_equal(pose_set_joint_euler(st, 0, deg, (pose_euler_order)order), POSE_OK);
        assert_int_equal(pose_get_joint(st, 0, got), POSE_OK);
        assert_true(dq_dist(r, got) < 1e-6);
    }
    /* orders really differ */
    float a[4], b[4];
    pose_set_joint_euler(st, 0, deg, POSE_EULER_XYZ);
    pose_get_joint(st, 0, a);
    pose_set_joint_euler(st, 0, deg, POSE_EULER_ZYX);
    pose_get_joint(st, 0, b);
    double ad[4] = {a[0], a[1], a[2], a[3]};
    assert_true(dq_dist(ad, b) > 0.1);
    pose_state_free(st);
    pose_rig_free(rig);
}

/* A bend past 90 degrees about the middle axis of the limits' order is read
 * as a bend (the decomposition's other triple), not as the two other axes
 * turned by 180 and clamped; excess within float noise is no clamp. */
static void test_limits_bend_past_90(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    o.limit_joint = 1;
    o.limit_order = POSE_EULER_XYZ; /* y is the middle axis */
    o.limit_flags = POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z;
    o.limit_min[0] = -5.0f, o.limit_max[0] = 5.0f;
    o.limit_min[1] = 0.0f, o.limit_max[1] = 150.0f;
    o.limit_min[2] = -5.0f, o.limit_max[2] = 5.0f;
    pose_rig *rig = fx_bar(&o);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    const float h = 0.5f * 120.0f * 3.14159265f / 180.0f;
    const float bend[4] = {0.0f, sinf(h), 0.0f, cosf(h)};
    assert_int_equal(pose_set_joint(st, 1, bend), POSE_OK);
    float got[4];
    pose_get_joint(st, 1, got);
    double bd[4] = {bend[0], bend[1], bend[2], bend[3]};
    assert_true(dq_dist(bd, got) < 1e-6);
    const float straight[3] = {0.0f, -0.0005f, 0.0f};
    assert_int_equal(pose_set_joint_euler(st, 1, straight, POSE_EULER_XYZ), POSE_OK);
    const float past[3] = {0.0f, 160.0f, 0.0f};
    assert_int_equal(pose_set_joint_euler(st, 1, past, POSE_EULER_XYZ), POSE_CLAMPED);
    assert_non_null(strstr(pose_last_error(), "clamped to 150.00"));
    pose_state_free(st);
    pose_rig_free(rig);
}

/* Limits clamp requests (Euler in the limits' order and quaternions decomposed
 * in it) for every order, name the axis, and leave in-range requests alone. */
static void test_limits_clamp(void **unused)
{
    (void)unused;
    static const int axes[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int order = 0; order < 6; order++) {
        fx_options o = fx_defaults();
        o.limit_joint = 1;
        o.limit_order = (pose_euler_order)order;
        int first = axes[order][0];
        o.limit_flags = 1u << first;
        o.limit_min[first] = -10.0f;
        o.limit_max[first] = 45.0f;
        pose_rig *rig = fx_bar(&o);
        pose_state *st;
        assert_int_equal(pose_state_create(rig, &st), POSE_OK);
        float in_range[3] = {20.0f, 30.0f, -40.0f};
        in_range[first] = 30.0f;
        assert_int_equal(pose_set_joint_euler(st, 1, in_range, (pose_euler_order)order), POSE_OK);
        float over[3] = {20.0f, 30.0f, -40.0f};
        over[first] = 80.0f;
        assert_int_equal(pose_set_joint_euler(st, 1, over, (pose_euler_order)order), POSE_CLAMPED);
        char axis[4] = {' ', "xyz"[first], ' ', 0};
        assert_non_null(strstr(pose_last_error(), axis));
        assert_non_null(strstr(pose_last_error(), "80.00 clamped to 45.00"));
        float got[4], want[4];
        pose_get_joint(st, 1, got);
        float clamped[3] = {20.0f, 30.0f, -40.0f};
        clamped[first] = 45.0f;
        pose_set_joint_euler(st, 0, clamped, (pose_euler_order)order); /* joint 0: no limits */
        pose_get_joint(st, 0, want);
        double wd[4] = {want[0], want[1], want[2], want[3]};
        assert_true(dq_dist(wd, got) < 1e-6);
        /* the same rotation given as a quaternion is decomposed and clamped alike */
        pose_set_joint_euler(st, 0, over, (pose_euler_order)order);
        float q_over[4];
        pose_get_joint(st, 0, q_over);
        assert_int_equal(pose_set_joint(st, 1, q_over), POSE_CLAMPED);
        pose_get_joint(st, 1, got);
        assert_true(dq_dist(wd, got) < 1e-5);
        /* below the minimum; Euler in another order still clamps */
        float under[3] = {0, 0, 0};
        under[first] = -60.0f;
        pose_set_joint_euler(st, 0, under, (pose_euler_order)order);
        pose_get_joint(st, 0, q_over);
        assert_int_equal(pose_set_joint(st, 1, q_over), POSE_CLAMPED);
        assert_non_null(strstr(pose_last_error(), "clamped to -10.00"));
        pose_state_free(st);
        pose_rig_free(rig);
    }
}

/* Tissue vertices sitting on tet vertices follow the skinned tet vertices exactly. */
static void test_transfer_on_tet_vertices(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    pose_rig *rig = fx_bar(&o);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    const float deg[3] = {30, 45, -20};
    pose_set_joint_euler(st, 1, deg, POSE_EULER_XYZ);
    const float deg0[3] = {0, 0, 15};
    pose_set_joint_euler(st, 0, deg0, POSE_EULER_XYZ);
    for (int m = 0; m < 3; m++) {
        pose_set_method(st, k_methods[m]);
        assert_int_equal(pose_apply(st), POSE_OK);
        size_t nt, ns;
        const float *tp = pose_tet_positions(st, &nt);
        const float *sp = pose_tissue_positions(st, 0, &ns);
        assert_int_equal(nt, ns);
        assert_memory_equal(tp, sp, 3 * nt * sizeof(float));
        /* and the pose did move them */
        pose_tet_info ti;
        pose_rig_tet_info(rig, &ti);
        assert_true(fabsf(tp[3 * (nt - 1)] - ti.rest_positions[3 * (nt - 1)]) > 0.1f);
    }
    pose_state_free(st);
    pose_rig_free(rig);
}

/* Equal results for 1, 2 and 3 threads (bit for bit), every method. The rig
 * is big enough (> 2048 blocks of 8 vertices) for pose_apply to use its
 * workers rather than running small meshes on the caller. */
static void test_threads_identical(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    o.cubes = 200;
    o.joints = 5;
    o.inner_points = 20000;
    pose_rig *rig = fx_bar(&o);
    size_t nt, ns, ni;
    float *ref[3] = {NULL, NULL, NULL};
    for (int m = 0; m < 3; m++) {
        for (int threads = 1; threads <= 3; threads++) {
            pose_state *st;
            pose_state_options opt = {.threads = threads, .method = k_methods[m]};
            assert_int_equal(pose_state_create_ex(rig, &opt, &st), POSE_OK);
            for (int j = 0; j < 5; j++) {
                const float deg[3] = {10.0f * j, -25.0f + 7 * j, 40.0f - 3 * j};
                pose_set_joint_euler(st, j, deg, POSE_EULER_YZX);
            }
            assert_int_equal(pose_apply(st), POSE_OK);
            const float *tp = pose_tet_positions(st, &nt);
            const float *sp = pose_tissue_positions(st, 1, &ni);
            const float *sn = pose_tissue_normals(st, 0, &ns);
            if (threads == 1) {
                ref[0] = malloc(3 * nt * sizeof(float));
                ref[1] = malloc(3 * ni * sizeof(float));
                ref[2] = malloc(3 * ns * sizeof(float));
                memcpy(ref[0], tp, 3 * nt * sizeof(float));
                memcpy(ref[1], sp, 3 * ni * sizeof(float));
                memcpy(ref[2], sn, 3 * ns * sizeof(float));
            } else {
                assert_memory_equal(ref[0], tp, 3 * nt * sizeof(float));
                assert_memory_equal(ref[1], sp, 3 * ni * sizeof(float));
                assert_memory_equal(ref[2], sn, 3 * ns * sizeof(float));
            }
            /* changing the thread count of a live state keeps results */
            assert_int_equal(pose_set_threads(st, 4 - threads), POSE_OK);
            assert_int_equal(pose_apply(st), POSE_OK);
            assert_memory_equal(ref[0], pose_tet_positions(st, &nt), 3 * nt * sizeof(float));
            pose_state_free(st);
        }
        for (int k = 0; k < 3; k++) {
            free(ref[k]);
            ref[k] = NULL;
        }
    }
    pose_rig_free(rig);
}

static void test_apply_allocates_nothing(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    pose_rig *rig = fx_bar(&o);
    counter c = {0, 0, 0};
    pose_state_options opt = {.allocator = {count_alloc, count_free, &c}, .threads = 2};
    pose_state *st;
    assert_int_equal(pose_state_create_ex(rig, &opt, &st), POSE_OK);
    int after_create = c.allocs;
    assert_true(after_create >= 1);
    assert_int_equal(c.misaligned, 0); /* every buffer 64-byte aligned */
    for (int m = 0; m < 3; m++) {
        pose_set_method(st, k_methods[m]);
        const float deg[3] = {10.0f * m, 20, 30};
        pose_set_joint_euler(st, 1, deg, POSE_EULER_XYZ);
        assert_int_equal(pose_apply(st), POSE_OK);
    }
    assert_int_equal(c.allocs, after_create);
    assert_int_equal(c.frees, 0);
    pose_state_free(st);
    assert_int_equal(c.frees, c.allocs);
    pose_rig_free(rig);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_invalid_input),
        cmocka_unit_test(test_rest_pose_exact),
        cmocka_unit_test(test_rigid_bone_motion),
        cmocka_unit_test(test_world_transforms_compose),
        cmocka_unit_test(test_euler_orders),
        cmocka_unit_test(test_limits_clamp),
        cmocka_unit_test(test_limits_bend_past_90),
        cmocka_unit_test(test_transfer_on_tet_vertices),
        cmocka_unit_test(test_threads_identical),
        cmocka_unit_test(test_apply_allocates_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
