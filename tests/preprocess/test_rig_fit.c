/* SPDX-License-Identifier: Apache-2.0
 * Rigging building blocks on exact synthetic data: sphere and circle fits
 * recover known centres, a ball joint between two spherical meshes lands on
 * their common centre, frames are orthonormal and follow the template. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rig_fit.h"

static const double PI = 3.14159265358979323846;

static void test_sphere_fit_on_a_cap(void **state)
{
    (void)state;
    /* A 50-degree cap: a partial surface, like an articular region. */
    const double c[3] = {0.1, -0.2, 0.9}, r = 0.025;
    double pts[3 * 200];
    size_t n = 0;
    for (int i = 1; i <= 10; i++)
        for (int j = 0; j < 20; j++, n++) {
            double th = (50.0 * PI / 180) * i / 10, ph = 2 * PI * j / 20;
            pts[3 * n] = c[0] + r * sin(th) * cos(ph);
            pts[3 * n + 1] = c[1] + r * sin(th) * sin(ph);
            pts[3 * n + 2] = c[2] + r * cos(th);
        }
    double got[3], rad, rms;
    assert_true(pp_fit_sphere(pts, n, got, &rad, &rms));
    for (int k = 0; k < 3; k++)
        assert_true(fabs(got[k] - c[k]) < 1e-9);
    assert_true(fabs(rad - r) < 1e-9 && rms < 1e-9);
    /* Coplanar points do not determine a sphere. */
    for (size_t i = 0; i < n; i++)
        pts[3 * i + 2] = 0.5;
    int ok = pp_fit_sphere(pts, n, got, &rad, &rms);
    assert_true(!ok || rad > 1e3); /* refused, or an absurd radius the caller rejects */
}

static void test_circle_fit_about_an_axis(void **state)
{
    (void)state;
    /* A 100-degree arc of a cylinder about y, 40 mm long. */
    const double c[3] = {-0.006, -0.076, 0.467}, r = 0.021, axis[3] = {0, 1, 0};
    double pts[3 * 120];
    size_t n = 0;
    for (int i = 0; i < 12; i++)
        for (int j = 0; j < 10; j++, n++) {
            double a = (-140 + 100.0 * i / 11) * PI / 180;
            pts[3 * n] = c[0] + r * cos(a);
            pts[3 * n + 1] = c[1] - 0.02 + 0.04 * j / 9;
            pts[3 * n + 2] = c[2] + r * sin(a);
        }
    double got[3], rad, rms;
    assert_true(pp_fit_circle(pts, n, axis, got, &rad, &rms));
    for (int k = 0; k < 3; k++)
        assert_true(fabs(got[k] - c[k]) < 1e-9);
    assert_true(fabs(rad - r) < 1e-9);
}

static void test_quaternion_from_matrix(void **state)
{
    (void)state;
    const double rz90[3][3] = {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}};
    float q[4];
    pp_quat_from_matrix(rz90, q);
    assert_true(fabsf(q[0]) < 1e-7f && fabsf(q[1]) < 1e-7f);
    assert_true(fabsf(q[2] - sqrtf(0.5f)) < 1e-6f && fabsf(q[3] - sqrtf(0.5f)) < 1e-6f);
    const double rx180[3][3] = {{1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
    pp_quat_from_matrix(rx180, q);
    assert_true(fabsf(fabsf(q[0]) - 1) < 1e-6f && fabsf(q[3]) < 1e-6f);
}

/* UV sphere mesh of radius r about c. */
static void sphere_mesh(pp_mesh *m, const char *name, const double c[3], double r)
{
    enum { NT = 16, NP = 24 };
    memset(m, 0, sizeof *m);
    strcpy(m->name, name);
    m->vertex_count = (NT - 1) * NP + 2;
    m->positions = malloc(3 * m->vertex_count * sizeof(float));
    m->triangle_count = 2 * NP * (NT - 1);
    m->triangles = malloc(3 * m->triangle_count * sizeof(uint32_t));
    size_t v = 0, t = 0;
    for (int i = 1; i < NT; i++)
        for (int j = 0; j < NP; j++, v++) {
            double th = PI * i / NT, ph = 2 * PI * j / NP;
            m->positions[3 * v] = (float)(c[0] + r * sin(th) * cos(ph));
            m->positions[3 * v + 1] = (float)(c[1] + r * sin(th) * sin(ph));
            m->positions[3 * v + 2] = (float)(c[2] + r * cos(th));
        }
    uint32_t top = (uint32_t)v, bottom = (uint32_t)v + 1;
    for (int k = 0; k < 3; k++) {
        m->positions[3 * top + k] = (float)(c[k] + (k == 2 ? r : 0));
        m->positions[3 * bottom + k] = (float)(c[k] - (k == 2 ? r : 0));
    }
    for (int j = 0; j < NP; j++) {
        uint32_t a = (uint32_t)j, b = (uint32_t)((j + 1) % NP);
        uint32_t tri1[3] = {top, a, b};
        memcpy(m->triangles + 3 * t++, tri1, sizeof tri1);
        uint32_t off = (uint32_t)((NT - 2) * NP);
        uint32_t tri2[3] = {bottom, off + b, off + a};
        memcpy(m->triangles + 3 * t++, tri2, sizeof tri2);
    }
    for (int i = 0; i < NT - 2; i++)
        for (int j = 0; j < NP; j++) {
            uint32_t a = (uint32_t)(i * NP + j), b = (uint32_t)(i * NP + (j + 1) % NP);
            uint32_t c2 = a + NP, d = b + NP;
            uint32_t t1[3] = {a, c2, d}, t2[3] = {a, d, b};
            memcpy(m->triangles + 3 * t++, t1, sizeof t1);
            memcpy(m->triangles + 3 * t++, t2, sizeof t2);
        }
}

/* A femoral head inside an acetabular shell 3 mm larger: the ball joint
 * lands on their common centre; frames are orthonormal. */
static void test_ball_joint_between_spheres(void **state)
{
    (void)state;
    const double c[3] = {0.0, -0.08, 0.87};
    pp_mesh bones[2];
    sphere_mesh(&bones[0], "cup", c, 0.026);
    sphere_mesh(&bones[1], "head", c, 0.023);
    const char *text =
        "{\"format\": \"pose-skeleton-template\", \"version\": 1, \"joints\": ["
        "{\"name\": \"pelvis\", \"parent\": null, \"rule\": \"root\", \"bones\": [\"cup\"]},"
        "{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"head\"], "
        "\"contact_mm\": 4, \"axis\": [0, 1, 0]}]}";
    pp_template t;
    char err[256];
    assert_int_equal(pp_template_parse(text, strlen(text), "t", &t, err, sizeof err), POSE_OK);
    pp_fit_joint f[2];
    assert_int_equal(pp_rig_fit(&t, bones, 2, f, err, sizeof err), POSE_OK);
    for (int k = 0; k < 3; k++)
        assert_true(fabs(f[1].centre[k] - c[k]) < 1e-6); /* float vertices */
    assert_true(fabs(f[1].radius_mm - 23.0) < 0.01);
    assert_int_equal(f[1].contact_points, bones[1].vertex_count);
    for (int j = 0; j < 2; j++) /* columns orthonormal, right-handed */
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                double d = 0;
                for (int r = 0; r < 3; r++)
                    d += f[j].frame[r][a] * f[j].frame[r][b];
                assert_true(fabs(d - (a == b)) < 1e-9);
            }
    assert_true(f[1].frame[1][1] > 0.99); /* y follows the template axis */
    /* Too small a contact distance: no region, the message names the joint. */
    t.joints[1].contact_mm = 1;
    assert_int_equal(pp_rig_fit(&t, bones, 2, f, err, sizeof err), POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(err, "joint 'hip': no contact region"));
    pp_template_free(&t);
    pp_mesh_free(&bones[0]);
    pp_mesh_free(&bones[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_fit_on_a_cap),
        cmocka_unit_test(test_circle_fit_about_an_axis),
        cmocka_unit_test(test_quaternion_from_matrix),
        cmocka_unit_test(test_ball_joint_between_spheres),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
