/* SPDX-License-Identifier: Apache-2.0
 * pose-bake refuses bad input with a message naming the file or joint, and
 * leaves no output behind. Small meshes are written as OBJ files. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bake_pipeline.h"

static char g_tmp[900];

static void path_of(char *out, size_t n, const char *name)
{
    snprintf(out, n, "%s/%s", g_tmp, name);
}

/* Axis-aligned box as an OBJ file, outward triangles. */
static void write_box(const char *name, const double lo[3], const double hi[3])
{
    char p[1024];
    path_of(p, sizeof p, name);
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    for (int i = 0; i < 8; i++)
        fprintf(f, "v %g %g %g\n", i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]);
    static const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int k = 0; k < 6; k++)
        fprintf(f, "f %d %d %d\nf %d %d %d\n", q[k][0] + 1, q[k][1] + 1, q[k][2] + 1, q[k][0] + 1,
                q[k][2] + 1, q[k][3] + 1);
    fclose(f);
}

static void write_text(const char *name, const char *text)
{
    char p[1024];
    path_of(p, sizeof p, name);
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static const char *TEMPLATE =
    "{\"format\": \"pose-skeleton-template\", \"version\": 1, \"joints\": [\n"
    "{\"name\": \"root\", \"parent\": null, \"rule\": \"root\", \"bones\": [\"upper\"]},\n"
    "{\"name\": \"knee\", \"parent\": \"root\", \"rule\": \"ball\", \"bones\": [\"lower\"], \"contact_mm\": 3}]}\n";

static int setup(void **state)
{
    (void)state;
    const char *tmp = getenv("POSE_TEST_TMP");
    if (!tmp)
        return -1;
    snprintf(g_tmp, sizeof g_tmp, "%s", tmp);
    write_box("skin.obj", (double[]){0, 0, 0}, (double[]){0.1, 0.1, 0.4});
    write_box("upper.obj", (double[]){0.03, 0.03, 0.22}, (double[]){0.07, 0.07, 0.38});
    write_box("lower.obj", (double[]){0.03, 0.03, 0.02}, (double[]){0.07, 0.07, 0.18}); /* 40 mm gap */
    write_box("far.obj", (double[]){5, 5, 5}, (double[]){5.1, 5.1, 5.1});
    write_text("empty.obj", "# nothing\n");
    write_text("t.json", TEMPLATE);
    return 0;
}

static void expect_failure(const char *skin, const char *const *bones, size_t nb, const char *tmpl,
                           const char *message)
{
    char sp[1024], tp[1024], out[1024], bp[4][1024];
    const char *bv[4];
    path_of(sp, sizeof sp, skin);
    path_of(tp, sizeof tp, tmpl);
    path_of(out, sizeof out, "out.rig");
    for (size_t i = 0; i < nb; i++) {
        path_of(bp[i], sizeof bp[i], bones[i]);
        bv[i] = bp[i];
    }
    pp_bake_options o = {.skin_path = sp, .bone_paths = bv, .bone_count = nb, .template_path = tp,
                         .output_path = out, .resolution_mm = 10};
    pp_bake_report rep;
    char err[1024] = "";
    int rc = pp_bake(&o, &rep, err, sizeof err);
    pp_bake_report_free(&rep);
    if (rc >= 0 || !strstr(err, message))
        fail_msg("status %d, message '%s'; expected failure with '%s'", rc, err, message);
    assert_int_equal(access(out, F_OK), -1); /* nothing written */
}

static void test_missing_skin(void **state)
{
    (void)state;
    const char *b[] = {"upper.obj", "lower.obj"};
    expect_failure("no_such_skin.obj", b, 2, "t.json", "no_such_skin.obj");
}

static void test_missing_template(void **state)
{
    (void)state;
    const char *b[] = {"upper.obj", "lower.obj"};
    expect_failure("skin.obj", b, 2, "nope.json", "nope.json: cannot open");
}

static void test_empty_bone_mesh(void **state)
{
    (void)state;
    const char *b[] = {"upper.obj", "empty.obj"};
    expect_failure("skin.obj", b, 2, "t.json", "empty.obj");
}

static void test_bone_outside_skin(void **state)
{
    (void)state;
    const char *b[] = {"upper.obj", "lower.obj", "far.obj"};
    expect_failure("skin.obj", b, 3, "t.json", "far.obj: bone 'far' lies entirely outside the skin");
}

static void test_template_names_missing_mesh(void **state)
{
    (void)state;
    const char *b[] = {"upper.obj"};
    expect_failure("skin.obj", b, 1, "t.json",
                   "joint 'knee': bone mesh 'lower' named by the template was not given");
}

static void test_joint_without_contact(void **state)
{
    (void)state;
    const char *b[] = {"upper.obj", "lower.obj"};
    expect_failure("skin.obj", b, 2, "t.json", "joint 'knee': no contact region");
}

static void test_duplicate_bone_names(void **state)
{
    (void)state;
    const char *b[] = {"upper.obj", "upper.obj"};
    expect_failure("skin.obj", b, 2, "t.json", "a bone named 'upper' was already given");
}

/* The same inputs with the bones touching bake, and the rig loads. */
static void test_small_bake_succeeds(void **state)
{
    (void)state;
    write_box("lower2.obj", (double[]){0.03, 0.03, 0.02}, (double[]){0.07, 0.07, 0.219});
    write_text("t2.json", "{\"format\": \"pose-skeleton-template\", \"version\": 1, \"joints\": [\n"
                          "{\"name\": \"root\", \"parent\": null, \"rule\": \"root\", \"bones\": [\"upper\"]},\n"
                          "{\"name\": \"knee\", \"parent\": \"root\", \"rule\": \"spine\", \"bones\": [\"lower2\"]}]}\n");
    /* A bone mesh the template does not name is kept as soft tissue. */
    write_box("cartilage.obj", (double[]){0.04, 0.04, 0.3}, (double[]){0.06, 0.06, 0.32});
    char sp[1024], tp[1024], out[1024], b1[1024], b2[1024], b3[1024];
    path_of(sp, sizeof sp, "skin.obj");
    path_of(tp, sizeof tp, "t2.json");
    path_of(out, sizeof out, "small.rig");
    path_of(b1, sizeof b1, "upper.obj");
    path_of(b2, sizeof b2, "lower2.obj");
    path_of(b3, sizeof b3, "cartilage.obj");
    const char *bv[] = {b1, b2, b3};
    pp_bake_options o = {.skin_path = sp, .bone_paths = bv, .bone_count = 3, .template_path = tp,
                         .output_path = out, .resolution_mm = 10, .threads = 2};
    pp_bake_report rep;
    char err[1024];
    int rc = pp_bake(&o, &rep, err, sizeof err);
    if (rc < 0)
        fail_msg("%s", err);
    /* Spine rule: centroid of the contact faces at z = 0.22. */
    assert_true(fabs(rep.fits[1].centre[2] - 0.2195) < 1e-3);
    assert_int_equal(rep.soft_bones, 1);
    assert_int_equal(rep.tissue_count, 4);
    assert_int_equal(rep.tissues[3].joint, -1);
    assert_int_equal(rep.tissues[3].kind, POSE_TISSUE_BONE);
    assert_int_equal(rep.tissues[1].joint, 0);
    assert_int_equal(rep.tissues[2].joint, 1);
    pp_bake_report_free(&rep);
    pose_rig *rig;
    assert_int_equal(pose_rig_load(out, &rig), POSE_OK);
    assert_int_equal(pose_rig_joint_count(rig), 2);
    assert_int_equal(pose_rig_tissue_count(rig), 4);
    assert_true(pose_rig_find_tissue(rig, "cartilage") == 3);
    pose_rig_free(rig);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_missing_skin),
        cmocka_unit_test(test_missing_template),
        cmocka_unit_test(test_empty_bone_mesh),
        cmocka_unit_test(test_bone_outside_skin),
        cmocka_unit_test(test_template_names_missing_mesh),
        cmocka_unit_test(test_joint_without_contact),
        cmocka_unit_test(test_duplicate_bone_names),
        cmocka_unit_test(test_small_bake_succeeds),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
