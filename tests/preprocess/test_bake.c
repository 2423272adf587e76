/* SPDX-License-Identifier: Apache-2.0
 * The whole pipeline on the shared anatomy model at a reduced resolution:
 * the rig loads, the fitted joints sit where the source model puts them,
 * and bending the right knee moves the tibia rigidly, leaves the left leg
 * alone and keeps the skin attached. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <cjson/cJSON.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_pipeline.h"

static char g_rig[1024];
static char g_data[1024];

typedef struct names {
    char **v;
    size_t n;
} names;

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static names bone_files(const char *dir)
{
    names r = {calloc(256, sizeof(char *)), 0};
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d)) && r.n < 256) {
        size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 4, ".obj") != 0)
            continue;
        r.v[r.n] = malloc(strlen(dir) + len + 2);
        sprintf(r.v[r.n++], "%s/%s", dir, e->d_name);
    }
    closedir(d);
    qsort(r.v, r.n, sizeof *r.v, cmp_str);
    return r;
}

static void names_free(names *n)
{
    for (size_t i = 0; i < n->n; i++)
        free(n->v[i]);
    free(n->v);
}

static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    assert_int_equal(fread(buf, 1, (size_t)n, f), (size_t)n);
    buf[n] = 0;
    fclose(f);
    return buf;
}

/* Bake the shared body at `mm` into POSE_TEST_TMP/<name>. */
static int bake_body(double mm, const char *name, char *rig, size_t rig_len, pp_bake_report *rep)
{
    const char *data = getenv("POSE_DATA_DIR"), *tmp = getenv("POSE_TEST_TMP");
    if (!data || !tmp)
        return -1;
    snprintf(g_data, sizeof g_data, "%s", data);
    snprintf(rig, rig_len, "%s/%s", tmp, name);
    char skin[1024], bones_dir[1024], tmpl[1024];
    snprintf(skin, sizeof skin, "%s/anatomy/skin.obj", data);
    snprintf(bones_dir, sizeof bones_dir, "%s/anatomy/bones", data);
    snprintf(tmpl, sizeof tmpl, "%s/../preprocess/templates/full_body.json", data);
    names b = bone_files(bones_dir);
    pp_bake_options o = {.skin_path = skin,
                         .bone_paths = (const char *const *)b.v,
                         .bone_count = b.n,
                         .template_path = tmpl,
                         .output_path = rig,
                         .resolution_mm = mm,
                         .threads = 2};
    char err[1024];
    int rc = pp_bake(&o, rep, err, sizeof err);
    names_free(&b);
    if (rc < 0) {
        fprintf(stderr, "bake at %g mm failed: %s\n", mm, err);
        return -1;
    }
    return 0;
}

/* Bake once for all tests (group setup). */
static pp_bake_report g_rep;
static int bake_setup(void **state)
{
    (void)state;
    return bake_body(12, "body.rig", g_rig, sizeof g_rig, &g_rep);
}

static int bake_teardown(void **state)
{
    (void)state;
    pp_bake_report_free(&g_rep);
    return 0;
}

static void test_report_checks(void **state)
{
    (void)state;
    assert_int_equal(g_rep.tmpl.joint_count, 19);
    assert_true(g_rep.quality.tet_count > 10000);
    assert_int_equal(g_rep.quality.inverted_count, 0);
    /* Partition of unity on the raw solution; bounds before clamping: the
     * snapped mesh has obtuse tets (their positive Laplacian entries are
     * lumped onto the diagonal, weights_matrix.h), and without that the
     * raw weights reached -0.07..1.07 at 10 mm. */
    assert_true(g_rep.weights.max_sum_error < 1e-9);
    assert_true(g_rep.weights.clipped_entries > 0);
    assert_true(g_rep.weights.min_weight >= -1e-3 && g_rep.weights.max_weight <= 1 + 1e-3);
    assert_int_equal(g_rep.weights.empty_joints, 0);
    assert_int_equal(g_rep.mapping.vertices, 13388 + 144436);
    /* The tet mesh encloses the skin (one cell layer more, snapped inward):
     * before, 64 % of the skin vertices lay outside it, up to 8 mm at 10 mm
     * cells; now 0.4 %, under 3 mm at 12 mm. */
    assert_true(g_rep.mapping.outside < 13388 / 50);
    assert_true(g_rep.mapping.max_distance < 0.004);
    assert_true(g_rep.cor.vertices_with_cor > 1000);
}

/* hip, knee, ankle, shoulder, elbow centres within 15 mm of the MJCF
 * anchors in skeleton_hint.json. */
static void test_joint_centres_match_hints(void **state)
{
    (void)state;
    char path[1100];
    snprintf(path, sizeof path, "%s/anatomy/skeleton_hint.json", g_data);
    char *text = read_text(path);
    cJSON *root = cJSON_Parse(text);
    assert_non_null(root);
    const cJSON *centres = cJSON_GetObjectItemCaseSensitive(root, "joint_centres");
    static const char *pairs[][2] = {
        {"hip_r", "hip_r"},       {"hip_l", "hip_l"},         {"knee_r", "knee_r"},
        {"knee_l", "knee_l"},     {"ankle_r", "ankle_r"},     {"ankle_l", "ankle_l"},
        {"shoulder_r", "glenohumeral_shoulder_r"}, {"shoulder_l", "glenohumeral_shoulder_l"},
        {"elbow_r", "elbow_r"},   {"elbow_l", "elbow_l"}};
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; i++) {
        int j = pp_template_find_joint(&g_rep.tmpl, pairs[i][0]);
        assert_true(j >= 0);
        const cJSON *h = cJSON_GetObjectItemCaseSensitive(centres, pairs[i][1]);
        assert_int_equal(cJSON_GetArraySize(h), 3);
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double dx = g_rep.fits[j].centre[k] - cJSON_GetArrayItem(h, k)->valuedouble;
            d2 += dx * dx;
        }
        printf("  %-10s %.1f mm from the hint, fit rms %.2f mm\n", pairs[i][0], sqrt(d2) * 1e3,
               g_rep.fits[j].residual_mm);
        assert_true(sqrt(d2) < 0.015);
    }
    cJSON_Delete(root);
    free(text);
}

static void rotate(const float q[4], const double v[3], double out[3])
{
    /* v' = v + 2 w (u x v) + 2 u x (u x v), q = (u, w) */
    double u[3] = {q[0], q[1], q[2]}, w = q[3];
    double c1[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    double c2[3] = {u[1] * c1[2] - u[2] * c1[1], u[2] * c1[0] - u[0] * c1[2],
                    u[0] * c1[1] - u[1] * c1[0]};
    for (int k = 0; k < 3; k++)
        out[k] = v[k] + 2 * w * c1[k] + 2 * c2[k];
}

/* Model-space motion of a joint's frame: p -> W R^-1 (p - r) + w. */
static void joint_motion(const pose_transform *rest, const pose_transform *world, const float *p,
                         double out[3])
{
    float inv[4] = {-rest->rotation[0], -rest->rotation[1], -rest->rotation[2], rest->rotation[3]};
    double d[3] = {p[0] - rest->translation[0], p[1] - rest->translation[1],
                   p[2] - rest->translation[2]},
           l[3];
    rotate(inv, d, l);
    rotate(world->rotation, l, out);
    for (int k = 0; k < 3; k++)
        out[k] += world->translation[k];
}

static void check_knee_bend(pose_method method)
{
    pose_rig *rig;
    assert_int_equal(pose_rig_load(g_rig, &rig), POSE_OK);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_int_equal(pose_set_method(st, method), POSE_OK);
    int knee = pose_rig_find_joint(rig, "knee_r");
    assert_true(knee >= 0);
    const float bend[3] = {0, 90, 0};
    assert_true(pose_set_joint_euler(st, knee, bend, POSE_EULER_XYZ) >= 0);
    assert_int_equal(pose_apply(st), POSE_OK);
    pose_joint_info ji;
    assert_int_equal(pose_rig_joint_info(rig, knee, &ji), POSE_OK);
    pose_transform world;
    assert_int_equal(pose_joint_world(st, knee, &world), POSE_OK);

    /* Every right tibia vertex moves with the knee's frame (< 1 mm). */
    double tibia_max_move = 0;
    size_t bad = 0;
    static const char *lower_r[] = {"r_tibia", "r_fibula", "r_talus", "r_foot", "r_bofoot"};
    for (size_t b = 0; b < 5; b++) {
        int t = pose_rig_find_tissue(rig, lower_r[b]);
        assert_true(t >= 0);
        pose_tissue_info ti;
        assert_int_equal(pose_rig_tissue_info(rig, t, &ti), POSE_OK);
        size_t n;
        const float *p = pose_tissue_positions(st, t, &n);
        assert_int_equal(n, ti.vertex_count);
        for (size_t v = 0; v < n; v++) {
            double want[3], e2 = 0, m2 = 0;
            joint_motion(&ji.rest_model, &world, ti.rest_positions + 3 * v, want);
            for (int k = 0; k < 3; k++) {
                e2 += (p[3 * v + k] - want[k]) * (p[3 * v + k] - want[k]);
                m2 += (p[3 * v + k] - ti.rest_positions[3 * v + k]) *
                      (p[3 * v + k] - ti.rest_positions[3 * v + k]);
            }
            if (b == 0 && sqrt(e2) >= 1e-3) {
                fprintf(stderr, "tibia vertex %zu (%.4f %.4f %.4f) off by %.2f mm\n", v,
                        ti.rest_positions[3 * v], ti.rest_positions[3 * v + 1],
                        ti.rest_positions[3 * v + 2], sqrt(e2) * 1e3);
                bad++;
            }
            tibia_max_move = fmax(tibia_max_move, sqrt(m2));
        }
    }
    assert_int_equal(bad, 0);
    assert_true(tibia_max_move > 0.3);
    /* +y flexes the knee: the ankle swings backwards (-X) and up (+Z). */
    {
        int t = pose_rig_find_tissue(rig, "r_talus");
        pose_tissue_info ti;
        assert_int_equal(pose_rig_tissue_info(rig, t, &ti), POSE_OK);
        size_t nt;
        const float *p = pose_tissue_positions(st, t, &nt);
        double dx = 0, dz = 0;
        for (size_t v = 0; v < nt; v++) {
            dx += (p[3 * v] - ti.rest_positions[3 * v]) / (double)nt;
            dz += (p[3 * v + 2] - ti.rest_positions[3 * v + 2]) / (double)nt;
        }
        assert_true(dx < -0.3 && dz > 0.3);
    }

    /* The left leg's bones do not move at all. */
    static const char *left[] = {"l_femur", "l_patella", "l_tibia", "l_fibula", "l_talus", "l_foot", "l_bofoot"};
    for (size_t b = 0; b < 7; b++) {
        int t = pose_rig_find_tissue(rig, left[b]);
        pose_tissue_info ti;
        assert_int_equal(pose_rig_tissue_info(rig, t, &ti), POSE_OK);
        size_t n;
        const float *p = pose_tissue_positions(st, t, &n);
        for (size_t v = 0; v < 3 * n; v++)
            assert_true(fabsf(p[v] - ti.rest_positions[v]) < 1e-5f);
    }

    /* The skin stays attached: no vertex moves more than the bones below
     * the knee do, and the skin of the left leg stays put. */
    int skin = pose_rig_find_tissue(rig, "skin");
    pose_tissue_info si;
    assert_int_equal(pose_rig_tissue_info(rig, skin, &si), POSE_OK);
    size_t n;
    const float *p = pose_tissue_positions(st, skin, &n);
    double skin_max = 0, left_max = 0;
    for (size_t v = 0; v < n; v++) {
        double m2 = 0;
        for (int k = 0; k < 3; k++)
            m2 += (p[3 * v + k] - si.rest_positions[3 * v + k]) *
                  (p[3 * v + k] - si.rest_positions[3 * v + k]);
        skin_max = fmax(skin_max, sqrt(m2));
        const float *r = si.rest_positions + 3 * v;
        if (r[1] > 0.04f && r[2] < 0.8f)
            left_max = fmax(left_max, sqrt(m2));
    }
    printf("  %s: tibia rigid, lower leg moved up to %.0f mm, skin up to %.0f mm, left leg skin %.2f mm\n",
           method == POSE_LBS ? "LBS" : method == POSE_DQS ? "DQS" : "CoR", tibia_max_move * 1e3,
           skin_max * 1e3, left_max * 1e3);
    assert_true(skin_max <= tibia_max_move + 0.02);
    assert_true(left_max < 1e-3);
    pose_state_free(st);
    pose_rig_free(rig);
}

static void test_knee_bend_lbs(void **state)
{
    (void)state;
    check_knee_bend(POSE_LBS);
}

static void test_knee_bend_cor(void **state)
{
    (void)state;
    check_knee_bend(POSE_COR);
}

/* Coarse voxels: fingers thinner than a 20 mm voxel hold no voxel centre
 * inside the skin; their bones are kept by their vertices, not refused as
 * "outside the skin", and the rig still loads. */
static void test_coarse_bake(void **state)
{
    (void)state;
    char rig_path[1024];
    pp_bake_report rep;
    memset(&rep, 0, sizeof rep);
    assert_int_equal(bake_body(20, "body20.rig", rig_path, sizeof rig_path, &rep), 0);
    assert_true(rep.voxels.thin_bones > 0);
    assert_int_equal(rep.weights.empty_joints, 0);
    assert_true(rep.mapping.outside < 13388 / 50);
    pose_rig *rig = NULL;
    assert_int_equal(pose_rig_load(rig_path, &rig), POSE_OK);
    pose_rig_free(rig);
    pp_bake_report_free(&rep);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_report_checks),
        cmocka_unit_test(test_joint_centres_match_hints),
        cmocka_unit_test(test_knee_bend_lbs),
        cmocka_unit_test(test_knee_bend_cor),
        cmocka_unit_test(test_coarse_bake),
    };
    /* "threads" (the TSan stage): one whole bake on 2 threads, the coarse
     * one; the 12 mm bake's checks are values the other stages check, and
     * it takes minutes under TSan. */
    const struct CMUnitTest threads[] = {
        cmocka_unit_test(test_coarse_bake),
    };
    if (argc > 1 && !strcmp(argv[1], "threads"))
        return cmocka_run_group_tests(threads, NULL, NULL);
    return cmocka_run_group_tests(tests, bake_setup, bake_teardown);
}
