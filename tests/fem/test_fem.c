/* SPDX-License-Identifier: Apache-2.0 */
/* The co-rotational FEM solver on analytic cases: a rigidly moved rest
 * state has no elastic force (the co-rotational property, at any rotation);
 * a cantilever clamped at one end sags under gravity as Euler-Bernoulli
 * says (within 5 % at fine resolution); POSE_FEM through the API holds bone
 * vertices where skinning puts them and is refused on rigs without data. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fem_box.h"
#include "pose/pose.h"

static void rotate(const double q[4], const float v[3], float out[3])
{
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double cx = y * v[2] - z * v[1], cy = z * v[0] - x * v[2], cz = x * v[1] - y * v[0];
    out[0] = (float)(v[0] + 2.0 * (w * cx + y * cz - z * cy));
    out[1] = (float)(v[1] + 2.0 * (w * cy + z * cx - x * cz));
    out[2] = (float)(v[2] + 2.0 * (w * cz + x * cy - y * cx));
}

static double max_norm(const float *f, size_t n)
{
    double m = 0.0;
    for (size_t i = 0; i < n; i++) {
        double l = sqrt((double)f[3 * i] * f[3 * i] + (double)f[3 * i + 1] * f[3 * i + 1] +
                        (double)f[3 * i + 2] * f[3 * i + 2]);
        if (l > m)
            m = l;
    }
    return m;
}

/* Rotated by 0..180 degrees about a skew axis and moved: no force. The
 * same box stretched by 1 % gets forces of the size Hooke's law gives, so
 * the zero is not a solver that sees nothing. */
static void test_rigid_rotation_zero_force(void **state)
{
    (void)state;
    box b = make_box(4, 3, 3, 0.05f, 0);
    sim s;
    const pose__fem_material m = {1e4f, 0.45f, 1000.0f};
    make_sim(&s, &b, m);
    float *x = malloc(3 * b.nv * sizeof(float)), *f = malloc(3 * b.nv * sizeof(float));
    assert_true(x && f);
    const double axis[3] = {0.48, -0.6, 0.64};
    for (int deg = 0; deg <= 180; deg += 30) {
        double h = deg * 3.14159265358979323846 / 360.0;
        double q[4] = {axis[0] * sin(h), axis[1] * sin(h), axis[2] * sin(h), cos(h)};
        for (size_t i = 0; i < b.nv; i++) {
            rotate(q, b.pos + 3 * i, x + 3 * i);
            x[3 * i] += 0.3f;
            x[3 * i + 2] -= 0.2f;
        }
        pose__fem_forces(&s.mesh, &s.work, x, f);
        /* float rounding of positions (~1e-8 m) times stiffness ~ E d: ~1e-6 N */
        double fmax = max_norm(f, b.nv);
        assert_true(fmax < 1e-3);
        if (deg == 90)
            printf("rotated 90 degrees: largest elastic force %.2e N\n", fmax);
    }
    for (size_t i = 0; i < 3 * b.nv; i++)
        x[i] = b.pos[i] * (i % 3 == 0 ? 1.01f : 1.0f);
    pose__fem_forces(&s.mesh, &s.work, x, f);
    /* a 1 % stretch along x: stress ~ (kappa + 4/3 mu) 0.01 ~ 380 Pa on
     * 0.05 m cells, ~1 N per vertex: 4 orders above the rotated box's */
    double fmax = max_norm(f, b.nv);
    printf("stretched 1 %%: largest elastic force %.3f N\n", fmax);
    assert_true(fmax > 0.3);
    free(x);
    free(f);
    free_sim(&s);
    free_box(&b);
}

/* Cantilever of length L (from the clamp), square section h, clamped by a
 * layer of bone cells, under its own weight: tip deflection
 * q L^4 / (8 E I), q = rho g h^2, I = h^4 / 12 (Euler-Bernoulli; shear adds
 * (h/L)^2 / 5 ~ 0.2 % at L = 10 h with nu = 0). */
static void test_cantilever(void **state)
{
    (void)state;
    const int nx = 81, n = 8; /* 80 cells along the beam after the clamp layer */
    const float h = 0.1f, d = h / (float)n, L = 80 * d;
    box b = make_box(nx, n, n, d, 1);
    sim s;
    const pose__fem_material m = {1e9f, 0.0f, 1000.0f};
    make_sim(&s, &b, m);
    float *x = malloc(3 * b.nv * sizeof(float));
    assert_non_null(x);
    memcpy(x, b.pos, 3 * b.nv * sizeof(float));
    pose__fem_params prm = {.outer_iterations = 2, .cg_iterations = 20000, .tolerance = 1e-6f,
                            .gravity = {0.0f, 0.0f, -9.81f}};
    pose__fem_stats st;
    pose__fem_solve(&s.mesh, &s.work, NULL, &prm, x, &st);
    double tip = 0.0;
    int count = 0;
    for (int j = 0; j <= n; j++)
        for (int k = 0; k <= n; k++) {
            size_t v = vid(&b, nx, j, k);
            tip += (double)x[3 * v + 2] - b.pos[3 * v + 2];
            count++;
        }
    tip /= count;
    const double q = 1000.0 * 9.81 * h * h, I = pow(h, 4) / 12.0;
    const double eb = q * pow(L, 4) / (8.0 * 1e9 * I);
    printf("cantilever %d x %d x %d cells: tip %.4f mm, Euler-Bernoulli %.4f mm (%+.2f %%); "
           "%d outer, %d CG, residual %.2g\n",
           nx - 1, n, n, -tip * 1e3, eb * 1e3, 100.0 * (-tip - eb) / eb, st.outer_iterations,
           st.cg_iterations, st.residual);
    assert_true(fabs(-tip - eb) <= 0.05 * eb);
    free(x);
    free_sim(&s);
    free_box(&b);
}

/* A one-joint rig over a box, with or without the fem section. */
static pose_rig *box_rig(const box *b, const pose_fem_material *fem)
{
    uint16_t *wj = calloc(b->nv, sizeof(uint16_t));
    float *w = malloc(b->nv * sizeof(float));
    assert_true(wj && w);
    for (size_t i = 0; i < b->nv; i++)
        w[i] = 1.0f;
    pose_joint_desc j = {.name = "root", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, 0, 0}}};
    pose_rig_desc d = {.joint_count = 1, .joints = &j, .tet_vertex_count = b->nv,
                       .tet_positions = b->pos, .tet_count = b->nt, .tets = b->tets,
                       .tet_labels = b->labels, .influences = 1, .weight_joints = wj,
                       .weights = w, .fem = fem};
    pose_rig *rig = NULL;
    pose_status st = pose_rig_create(&d, NULL, &rig);
    free(wj);
    free(w);
    return st == POSE_OK ? rig : NULL;
}

/* The API: POSE_FEM only on rigs with the fem section; the material round
 * trips (pose_rig_create writes the file image and loads it); bad materials are refused by the loader; a
 * rigid motion of the whole rig is reproduced exactly (no elastic force). */
static void test_api(void **state)
{
    (void)state;
    box b = make_box(6, 2, 2, 0.05f, 1);
    pose_rig *plain = box_rig(&b, NULL);
    assert_non_null(plain);
    assert_false(pose_rig_has_fem(plain));
    pose_fem_material m;
    assert_int_equal(pose_rig_fem_material(plain, &m), POSE_ERR_UNSUPPORTED);
    pose_state *st;
    assert_int_equal(pose_state_create(plain, &st), POSE_OK);
    assert_int_equal(pose_set_method(st, POSE_FEM), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_get_method(st), POSE_LBS);
    pose_state_free(st);
    pose_rig_free(plain);

    const pose_fem_material bad = {1e4f, 0.5f, 1000.0f};
    assert_null(box_rig(&b, &bad));
    assert_non_null(strstr(pose_last_error(), "Poisson"));

    const pose_fem_material good = {2e4f, 0.45f, 900.0f};
    pose_rig *rig = box_rig(&b, &good);
    assert_non_null(rig);
    assert_true(pose_rig_has_fem(rig));
    assert_int_equal(pose_rig_fem_material(rig, &m), POSE_OK);
    assert_true(m.young_modulus == 2e4f && m.poisson_ratio == 0.45f && m.density == 900.0f);

    pose_state_options so = {.size = sizeof so, .threads = 1, .method = POSE_FEM};
    pose_state *fem, *dqs;
    assert_int_equal(pose_state_create_ex(rig, &so, &fem), POSE_OK);
    so.method = POSE_DQS;
    assert_int_equal(pose_state_create_ex(rig, &so, &dqs), POSE_OK);
    pose_fem_options bad_opt = {.size = sizeof bad_opt, .tolerance = 2.0f};
    assert_int_equal(pose_set_fem_options(fem, &bad_opt), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_fem_options(fem, NULL), POSE_OK);
    const float q[4] = {0.2f, -0.4f, 0.3f, 0.8426149f}, t[3] = {0.1f, 0.2f, -0.3f};
    assert_int_equal(pose_set_joint(fem, 0, q), POSE_OK);
    assert_int_equal(pose_set_joint(dqs, 0, q), POSE_OK);
    assert_int_equal(pose_set_root(fem, t, NULL), POSE_OK);
    assert_int_equal(pose_set_root(dqs, t, NULL), POSE_OK);
    assert_int_equal(pose_apply(fem), POSE_OK);
    assert_int_equal(pose_apply(dqs), POSE_OK);
    const float *a = pose_tet_positions(fem, NULL), *r = pose_tet_positions(dqs, NULL);
    double worst = 0.0;
    for (size_t i = 0; i < 3 * b.nv; i++)
        worst = fmax(worst, fabs((double)a[i] - r[i]));
    printf("rigid motion through POSE_FEM: largest difference from DQS %.2e\n", worst);
    assert_true(worst < 1e-5);
    pose_fem_stats fs = {.size = sizeof fs};
    assert_int_equal(pose_get_fem_stats(fem, &fs), POSE_OK);
    assert_true(fs.outer_iterations >= 1);
    pose_state_free(fem);
    pose_state_free(dqs);

    pose_rig_free(rig);
    free_box(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rigid_rotation_zero_force),
        cmocka_unit_test(test_cantilever),
        cmocka_unit_test(test_api),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
