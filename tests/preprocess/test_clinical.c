/* SPDX-License-Identifier: Apache-2.0
 * The bake's neutral posture and clinical axes on the bundled anatomy,
 * checked with forward kinematics written out from pose.h's convention
 * (local = R(a0,f) R(a1,b) R(a2,r) N relative to the rest frame; W_j =
 * W_parent rest_local_j local_j): the limbs hang in the neutral posture,
 * abduction 90 is the T-pose, flexion swings forward, hinges keep their
 * fitted axes; and a template that contradicts the bones is refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clinical_checks.h"
#include "clinical_fit.h"
#include "mesh_io.h"

static const double DEG = 3.14159265358979323846 / 180.0;

typedef struct body {
    pp_template t;
    pp_fit_joint *fits;
    pp_clinical_joint *clin;
    double local[64][3][3]; /* current local rotation per joint */
} body;

static body g_body;

static void mat_mul(const double a[3][3], const double b[3][3], double r[3][3])
{
    double t[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            t[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
    memcpy(r, t, sizeof t);
}

static void mat_of_quat(const float q[4], double m[3][3])
{
    double x = q[0], y = q[1], z = q[2], w = q[3];
    m[0][0] = 1 - 2 * (y * y + z * z), m[0][1] = 2 * (x * y - z * w), m[0][2] = 2 * (x * z + y * w);
    m[1][0] = 2 * (x * y + z * w), m[1][1] = 1 - 2 * (x * x + z * z), m[1][2] = 2 * (y * z - x * w);
    m[2][0] = 2 * (x * z - y * w), m[2][1] = 2 * (y * z + x * w), m[2][2] = 1 - 2 * (x * x + y * y);
}

static void mat_axis_angle(const float a[3], double deg, double m[3][3])
{
    double c = cos(deg * DEG), s = sin(deg * DEG), t = 1 - c, x = a[0], y = a[1], z = a[2];
    m[0][0] = t * x * x + c, m[0][1] = t * x * y - s * z, m[0][2] = t * x * z + s * y;
    m[1][0] = t * x * y + s * z, m[1][1] = t * y * y + c, m[1][2] = t * y * z - s * x;
    m[2][0] = t * x * z - s * y, m[2][1] = t * y * z + s * x, m[2][2] = t * z * z + c;
}

static void set_identity(double m[3][3])
{
    memset(m, 0, 9 * sizeof(double));
    m[0][0] = m[1][1] = m[2][2] = 1;
}

static int joint_of(const char *name)
{
    int j = pp_template_find_joint(&g_body.t, name);
    assert_true(j >= 0);
    return j;
}

static void api_rest(void *ctx)
{
    body *b = ctx;
    for (size_t j = 0; j < b->t.joint_count; j++)
        set_identity(b->local[j]);
}

static void api_set(void *ctx, const char *joint, float flex, float abd, float rot)
{
    body *b = ctx;
    int j = joint_of(joint);
    const pose_joint_clinical *c = &b->clin[j].c;
    assert_true(c->flags & POSE_CLINICAL_DEFINED);
    double r0[3][3], r1[3][3], r2[3][3], n[3][3];
    mat_axis_angle(c->axes[0], flex, r0);
    mat_axis_angle(c->axes[1], abd, r1);
    mat_axis_angle(c->axes[2], rot, r2);
    mat_of_quat(c->neutral, n);
    mat_mul(r2, n, n);
    mat_mul(r1, n, n);
    mat_mul(r0, n, b->local[j]);
}

static void api_neutral(void *ctx)
{
    body *b = ctx;
    api_rest(ctx);
    for (size_t j = 0; j < b->t.joint_count; j++)
        if (b->clin[j].c.flags & POSE_CLINICAL_DEFINED)
            api_set(ctx, b->t.joints[j].name, 0, 0, 0);
}

/* Forward kinematics: W_j = W_p Q_p^T Q_j L_j, x_j = x_p + W_p Q_p^T (c_j - c_p). */
static void api_where(void *ctx, const char *joint, double xyz[3])
{
    body *b = ctx;
    int target = joint_of(joint);
    double W[64][3][3], X[64][3];
    for (int j = 0; j <= target; j++) {
        const pp_fit_joint *f = &b->fits[j];
        int p = b->t.joints[j].parent;
        if (p < 0) {
            mat_mul(f->frame, b->local[j], W[j]);
            memcpy(X[j], f->centre, sizeof X[j]);
            continue;
        }
        double Wp_QpT[3][3], QpT[3][3];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                QpT[r][c] = b->fits[p].frame[c][r];
        mat_mul(W[p], QpT, Wp_QpT);
        mat_mul(Wp_QpT, f->frame, W[j]);
        mat_mul(W[j], b->local[j], W[j]);
        for (int r = 0; r < 3; r++) {
            X[j][r] = X[p][r];
            for (int c = 0; c < 3; c++)
                X[j][r] += Wp_QpT[r][c] * (f->centre[c] - b->fits[p].centre[c]);
        }
    }
    memcpy(xyz, X[target], sizeof X[target]);
}

static const posture_api g_api = {&g_body, api_rest, api_neutral, api_set, api_where};

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Fit the full-body template to the bundled bones, then the clinical data. */
static int setup(void **state)
{
    (void)state;
    const char *data = getenv("POSE_DATA_DIR");
    if (!data)
        return -1;
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/../preprocess/templates/full_body.json", data);
    if (pp_template_load(path, &g_body.t, err, sizeof err) < 0 || g_body.t.joint_count > 64) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    snprintf(path, sizeof path, "%s/anatomy/bones", data);
    DIR *d = opendir(path);
    if (!d)
        return -1;
    char *files[256];
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d)) && n < 256)
        if (strstr(e->d_name, ".obj")) {
            files[n] = malloc(strlen(path) + strlen(e->d_name) + 2);
            sprintf(files[n++], "%s/%s", path, e->d_name);
        }
    closedir(d);
    qsort(files, n, sizeof *files, cmp_str);
    pp_mesh *bones = calloc(n, sizeof *bones);
    int rc = 0;
    for (size_t i = 0; i < n && rc >= 0; i++)
        rc = pp_mesh_load(files[i], &bones[i], err, sizeof err);
    g_body.fits = calloc(g_body.t.joint_count, sizeof *g_body.fits);
    g_body.clin = calloc(g_body.t.joint_count, sizeof *g_body.clin);
    if (rc >= 0)
        rc = pp_rig_fit(&g_body.t, bones, n, g_body.fits, err, sizeof err);
    if (rc >= 0)
        rc = pp_clinical_fit(&g_body.t, g_body.fits, g_body.clin, err, sizeof err);
    if (rc < 0)
        fprintf(stderr, "%s\n", err);
    for (size_t i = 0; i < n; i++) {
        pp_mesh_free(&bones[i]);
        free(files[i]);
    }
    free(bones);
    return rc < 0 ? -1 : 0;
}

static int teardown(void **state)
{
    (void)state;
    pp_template_free(&g_body.t);
    free(g_body.fits);
    free(g_body.clin);
    return 0;
}

/* Every joint but the root has clinical data; axes unit and orthogonal;
 * the neutral offsets are what the T-pose implies. */
static void test_axes_and_offsets(void **state)
{
    (void)state;
    for (size_t j = 0; j < g_body.t.joint_count; j++) {
        const pp_clinical_joint *c = &g_body.clin[j];
        if (g_body.t.joints[j].parent < 0) {
            assert_int_equal(c->c.flags, 0);
            continue;
        }
        assert_int_equal(c->c.flags, POSE_CLINICAL_DEFINED);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                double d = 0;
                for (int k = 0; k < 3; k++)
                    d += (double)c->c.axes[a][k] * c->c.axes[b][k];
                assert_true(fabs(d - (a == b)) < 1e-5);
            }
        printf("  %-10s neutral offset %5.1f deg\n", g_body.t.joints[j].name, c->neutral_deg);
    }
    /* The T-pose arms hang ~80 degrees lower in the neutral posture; legs
     * and trunk already stand. */
    assert_true(g_body.clin[joint_of("shoulder_r")].neutral_deg > 75);
    assert_true(g_body.clin[joint_of("shoulder_l")].neutral_deg > 75);
    assert_true(g_body.clin[joint_of("hip_r")].neutral_deg < 5);
    assert_true(g_body.clin[joint_of("knee_l")].neutral_deg < 5);
    assert_true(g_body.clin[joint_of("lumbar")].neutral_deg == 0);
}

/* Hinges flex about the axis fitted to the bones: the rest frame's y. */
static void test_hinge_axes_from_the_bones(void **state)
{
    (void)state;
    static const char *hinges[] = {"elbow_r", "elbow_l", "knee_r", "knee_l", "ankle_r", "ankle_l"};
    for (size_t i = 0; i < sizeof hinges / sizeof hinges[0]; i++) {
        const float *a = g_body.clin[joint_of(hinges[i])].c.axes[0];
        assert_true(fabs(a[0]) < 1e-6 && fabs(a[2]) < 1e-6 && fabs(fabs(a[1]) - 1) < 1e-6);
    }
    /* +y flexes elbow and knee, and plantar-flexes the ankle (templates/README.md). */
    assert_true(g_body.clin[joint_of("elbow_r")].c.axes[0][1] > 0);
    assert_true(g_body.clin[joint_of("knee_l")].c.axes[0][1] > 0);
    assert_true(g_body.clin[joint_of("ankle_r")].c.axes[0][1] < 0);
}

static void test_postures(void **state)
{
    (void)state;
    clinical_check_postures(&g_api);
}

/* With the elbow flexed 90 the forearm points forward; internal rotation
 * of the shoulder swings it towards the belly (+Y on the right, -Y on the
 * left). */
static void test_rotation_signs(void **state)
{
    (void)state;
    static const char *sh[2] = {"shoulder_r", "shoulder_l"}, *el[2] = {"elbow_r", "elbow_l"},
                      *wr[2] = {"wrist_r", "wrist_l"};
    for (int s = 0; s < 2; s++) {
        api_neutral(&g_body);
        api_set(&g_body, el[s], 90, 0, 0);
        api_set(&g_body, sh[s], 0, 0, 45);
        double e[3], w[3];
        api_where(&g_body, el[s], e);
        api_where(&g_body, wr[s], w);
        double medial = s == 0 ? w[1] - e[1] : e[1] - w[1];
        printf("  %s internal rotation 45 with elbow flexion 90: wrist %.3f m medial of the elbow\n",
               sh[s], medial);
        assert_true(medial > 0.1);
    }
}

/* A template whose flexion axis runs along the segment is refused, naming the joint. */
static void test_contradicting_template(void **state)
{
    (void)state;
    pp_clinical_joint *tmp = calloc(g_body.t.joint_count, sizeof *tmp);
    pp_template_clinical *k = &g_body.t.joints[joint_of("shoulder_r")].clinical;
    pp_template_clinical keep = *k;
    k->flexion[0] = 0, k->flexion[1] = 0, k->flexion[2] = -1;
    char err[512];
    assert_int_equal(pp_clinical_fit(&g_body.t, g_body.fits, tmp, err, sizeof err), POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(err, "joint 'shoulder_r'"));
    *k = keep;
    k = &g_body.t.joints[joint_of("knee_r")].clinical;
    keep = *k;
    k->flexion[0] = 1, k->flexion[1] = 0, k->flexion[2] = 0; /* not the fitted hinge */
    assert_int_equal(pp_clinical_fit(&g_body.t, g_body.fits, tmp, err, sizeof err), POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(err, "joint 'knee_r': the fitted hinge axis"));
    *k = keep;
    assert_int_equal(pp_clinical_fit(&g_body.t, g_body.fits, tmp, err, sizeof err), POSE_OK);
    free(tmp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_axes_and_offsets),
        cmocka_unit_test(test_hinge_axes_from_the_bones),
        cmocka_unit_test(test_postures),
        cmocka_unit_test(test_rotation_signs),
        cmocka_unit_test(test_contradicting_template),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
