/* SPDX-License-Identifier: Apache-2.0
 * Clinical angles through libpose on a body baked by pose-bake from the
 * bundled anatomy (the shared body_rig_bake fixture, argv[1]): the rig
 * carries the bake's neutral posture and axes, and pose_set_neutral /
 * pose_set_joint_clinical pose it the way a goniometer reads: limbs hanging,
 * palms to the thighs, abduction 90 the T-pose, flexion forward and up,
 * seated with hip and knee at 90; elbows flex about the fitted hinge. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <pose/pose.h>

#include "clinical_checks.h"

static const char *g_path;
static pose_rig *g_rig;
static pose_state *g_st;

static int joint_of(const char *name)
{
    int j = pose_rig_find_joint(g_rig, name);
    assert_true(j >= 0);
    return j;
}

static void api_rest(void *ctx)
{
    (void)ctx;
    assert_int_equal(pose_reset(g_st), POSE_OK);
}

static void api_neutral(void *ctx)
{
    (void)ctx;
    assert_int_equal(pose_set_neutral(g_st), POSE_OK);
}

static void api_set(void *ctx, const char *joint, float flex, float abd, float rot)
{
    (void)ctx;
    const float deg[3] = {flex, abd, rot};
    assert_int_equal(pose_set_joint_clinical(g_st, joint_of(joint), deg), POSE_OK);
}

static void api_where(void *ctx, const char *joint, double xyz[3])
{
    (void)ctx;
    pose_transform w;
    assert_int_equal(pose_apply(g_st), POSE_OK);
    assert_int_equal(pose_joint_world(g_st, joint_of(joint), &w), POSE_OK);
    for (int k = 0; k < 3; k++)
        xyz[k] = w.translation[k];
}

static const posture_api g_api = {NULL, api_rest, api_neutral, api_set, api_where};

static int setup(void **state)
{
    (void)state;
    if (pose_rig_load(g_path, &g_rig) != POSE_OK) {
        fprintf(stderr, "%s\n", pose_last_error());
        return -1;
    }
    return pose_state_create(g_rig, &g_st) == POSE_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    pose_state_free(g_st);
    pose_rig_free(g_rig);
    return 0;
}

/* Every joint but the root has clinical data, with the template's names and
 * AAOS ranges; the metadata says the bake computed them. */
static void test_rig_carries_clinical_data(void **state)
{
    (void)state;
    for (int j = 0; j < (int)pose_rig_joint_count(g_rig); j++) {
        pose_joint_info info;
        pose_joint_clinical c;
        assert_int_equal(pose_rig_joint_info(g_rig, j, &info), POSE_OK);
        pose_status s = pose_rig_joint_clinical(g_rig, j, &c);
        assert_int_equal(s, info.parent < 0 ? POSE_ERR_UNSUPPORTED : POSE_OK);
    }
    pose_joint_clinical c;
    assert_int_equal(pose_rig_joint_clinical(g_rig, joint_of("elbow_l"), &c), POSE_OK);
    assert_string_equal(c.names[2], "pronation");
    assert_true(c.limit_min_deg[0] == 0.0f && c.limit_max_deg[0] == 150.0f);
    assert_non_null(strstr(pose_rig_metadata(g_rig), "neutral posture and clinical axes for 18 joints"));
}

static void test_postures(void **state)
{
    (void)state;
    clinical_check_postures(&g_api);
}

static void rotate(const float q[4], const double v[3], double out[3])
{
    /* v' = v + 2 w (u x v) + 2 u x (u x v), q = (u, w) */
    double u[3] = {q[0], q[1], q[2]}, w = q[3];
    double c1[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    double c2[3] = {u[1] * c1[2] - u[2] * c1[1], u[2] * c1[0] - u[0] * c1[2], u[0] * c1[1] - u[1] * c1[0]};
    for (int k = 0; k < 3; k++)
        out[k] = v[k] + 2 * w * c1[k] + 2 * c2[k];
}

static void forearm(int elbow, int wrist, double v[3])
{
    pose_transform e, w;
    assert_int_equal(pose_apply(g_st), POSE_OK);
    assert_int_equal(pose_joint_world(g_st, elbow, &e), POSE_OK);
    assert_int_equal(pose_joint_world(g_st, wrist, &w), POSE_OK);
    for (int k = 0; k < 3; k++)
        v[k] = w.translation[k] - e.translation[k];
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The elbow flexes about the hinge axis fitted to the bones: the rest
 * frame's y (rig_fit.h). Flexing 100 degrees from neutral turns the forearm
 * by 100 degrees about that axis as the humerus carries it. */
static void test_elbow_flexes_about_the_fitted_hinge(void **state)
{
    (void)state;
    static const char *names[2][3] = {{"shoulder_r", "elbow_r", "wrist_r"}, {"shoulder_l", "elbow_l", "wrist_l"}};
    for (int s = 0; s < 2; s++) {
        int sh = joint_of(names[s][0]), el = joint_of(names[s][1]), wr = joint_of(names[s][2]);
        pose_joint_clinical c;
        assert_int_equal(pose_rig_joint_clinical(g_rig, el, &c), POSE_OK);
        printf("  %s flexion axis in its rest frame: %.6f %.6f %.6f\n", names[s][1], c.axes[0][0],
               c.axes[0][1], c.axes[0][2]);
        assert_true(fabsf(c.axes[0][0]) < 1e-5f && fabsf(c.axes[0][2]) < 1e-5f);
        assert_true(fabsf(c.axes[0][1] - 1.0f) < 1e-5f); /* +y flexes (templates/README.md) */

        /* The hinge in model space: the shoulder's world rotation times the
         * rest frames' relative rotation, applied to y. */
        pose_joint_info ish, iel;
        assert_int_equal(pose_rig_joint_info(g_rig, sh, &ish), POSE_OK);
        assert_int_equal(pose_rig_joint_info(g_rig, el, &iel), POSE_OK);
        assert_int_equal(pose_set_neutral(g_st), POSE_OK);
        double v0[3], v1[3], h[3], y[3] = {0, 1, 0}, t[3];
        forearm(el, wr, v0);
        pose_transform wsh;
        assert_int_equal(pose_joint_world(g_st, sh, &wsh), POSE_OK);
        const float *qs = ish.rest_model.rotation;
        const float qs_inv[4] = {-qs[0], -qs[1], -qs[2], qs[3]};
        rotate(iel.rest_model.rotation, y, t); /* the fitted hinge at rest, model space */
        rotate(qs_inv, t, h);                  /* into the shoulder's frame */
        rotate(wsh.rotation, h, t);            /* carried by the neutral shoulder */
        memcpy(h, t, sizeof h);
        api_set(NULL, names[s][1], 100, 0, 0);
        forearm(el, wr, v1);
        double p0[3], p1[3], a0 = dot3(v0, h), a1 = dot3(v1, h);
        for (int k = 0; k < 3; k++) {
            p0[k] = v0[k] - a0 * h[k];
            p1[k] = v1[k] - a1 * h[k];
        }
        double cr[3] = {p0[1] * p1[2] - p0[2] * p1[1], p0[2] * p1[0] - p0[0] * p1[2], p0[0] * p1[1] - p0[1] * p1[0]};
        double turn = atan2(dot3(cr, h), dot3(p0, p1)) * 57.29577951308232;
        printf("  %s flexion 100: the forearm turned %.2f deg about the fitted hinge, %.2f mm along it\n",
               names[s][1], turn, (a1 - a0) * 1e3);
        assert_true(fabs(a1 - a0) < 1e-4);
        assert_true(fabs(turn - 100.0) < 0.1);
    }
}

/* Neutral forearm: the palm faces the thigh. The index and little finger
 * metacarpals span the palm: the index one lies in front of the other and
 * level with it across the body (at rest, palm down, they are level
 * vertically). */
static void test_palms_to_the_thighs(void **state)
{
    (void)state;
    assert_int_equal(pose_set_neutral(g_st), POSE_OK);
    assert_int_equal(pose_apply(g_st), POSE_OK);
    static const char *pairs[2][2] = {{"r_2mc", "r_5mc"}, {"l_2mc", "l_5mc"}};
    for (int s = 0; s < 2; s++) {
        double c[2][3] = {{0}};
        for (int b = 0; b < 2; b++) {
            int t = pose_rig_find_tissue(g_rig, pairs[s][b]);
            assert_true(t >= 0);
            size_t n;
            const float *p = pose_tissue_positions(g_st, t, &n);
            for (size_t v = 0; v < n; v++)
                for (int k = 0; k < 3; k++)
                    c[b][k] += p[3 * v + k] / (double)n;
        }
        double dx = c[0][0] - c[1][0], dy = c[0][1] - c[1][1];
        double turned = atan2(fabs(dy), dx) * 57.29577951308232;
        printf("  %s - %s: %+.3f %+.3f %+.3f m: the palm is %.1f deg from facing the thigh\n", pairs[s][0],
               pairs[s][1], dx, dy, c[0][2] - c[1][2], turned);
        assert_true(dx > 0.025);
        assert_true(turned < 15);
    }
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s BAKED.rig\n", argv[0]);
        return 2;
    }
    g_path = argv[1];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rig_carries_clinical_data),
        cmocka_unit_test(test_postures),
        cmocka_unit_test(test_elbow_flexes_about_the_fitted_hinge),
        cmocka_unit_test(test_palms_to_the_thighs),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
