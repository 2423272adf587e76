/* SPDX-License-Identifier: Apache-2.0
 * Mapping tissue vertices into tets through the spatial hash. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "embed_hash.h"
#include "pp_test_mesh.h"

static const float H = 0.01f;

static void test_rejects_empty_mesh(void **state)
{
    (void)state;
    pp_tetmesh m = {0};
    pp_tet_hash *h = (pp_tet_hash *)1;
    char err[128];
    assert_int_equal(pp_tet_hash_build(&m, 0, &h, err, sizeof err), POSE_ERR_INVALID_DATA);
    assert_null(h);
    assert_non_null(strstr(err, "empty"));
}

static unsigned rng_state = 12345;
static double rnd(void)
{
    rng_state = rng_state * 1103515245u + 12345u;
    return (double)((rng_state >> 8) & 0xffffff) / (double)0x1000000;
}

/* Points made from known barycentrics come back with the same tet and the
 * same coordinates (up to float rounding), and agree with brute force. */
static void test_inside_points_exact(void **state)
{
    (void)state;
    pp_tetmesh m;
    assert_int_equal(pp_test_box(7, 5, 4, H, &m), 0);
    enum { N = 2000 };
    float *pts = malloc(3 * N * sizeof(float)), *bary = malloc(4 * N * sizeof(float));
    float *bary2 = malloc(4 * N * sizeof(float));
    uint32_t *want = malloc(N * sizeof(uint32_t)), *tet = malloc(N * sizeof(uint32_t));
    uint32_t *tet2 = malloc(N * sizeof(uint32_t));
    double (*wb)[4] = malloc(N * sizeof *wb);
    for (int i = 0; i < N; i++) {
        want[i] = (uint32_t)(rnd() * (double)m.tet_count) % (uint32_t)m.tet_count;
        /* Interior coordinates, away from faces so the tet is unique. */
        double s = 0;
        for (int k = 0; k < 4; k++)
            s += wb[i][k] = 0.05 + rnd();
        for (int k = 0; k < 4; k++)
            wb[i][k] /= s;
        for (int c = 0; c < 3; c++) {
            double x = 0;
            for (int k = 0; k < 4; k++)
                x += wb[i][k] * m.positions[3 * (size_t)m.tets[4 * (size_t)want[i] + k] + c];
            pts[3 * i + c] = (float)x;
        }
    }
    pp_tet_hash *h;
    char err[128];
    assert_int_equal(pp_tet_hash_build(&m, 0, &h, err, sizeof err), POSE_OK);
    pp_embed_report rep = {0};
    assert_int_equal(pp_embed_points(h, pts, N, -1, 0, 2, tet, bary, &rep), POSE_OK);
    assert_int_equal(rep.vertices, N);
    assert_int_equal(rep.outside, 0);
    pp_embed_points_naive(&m, pts, N, tet2, bary2);
    for (int i = 0; i < N; i++) {
        assert_int_equal(tet[i], want[i]);
        assert_int_equal(tet2[i], want[i]);
        for (int k = 0; k < 4; k++) {
            assert_true(fabs(bary[4 * i + k] - wb[i][k]) < 1e-5);
            assert_true(fabs(bary2[4 * i + k] - bary[4 * i + k]) < 1e-6);
        }
    }
    pp_tet_hash_free(h);
    free(pts), free(bary), free(bary2), free(want), free(tet), free(tet2), free(wb);
    pp_tetmesh_free(&m);
}

/* Outside points take the nearest tet; their extrapolated coordinates
 * still reproduce the point, and the report says how far out. */
static void test_outside_points(void **state)
{
    (void)state;
    pp_tetmesh m;
    assert_int_equal(pp_test_box(4, 4, 4, H, &m), 0);
    const float pts[3][3] = {{0.02f, 0.02f, 0.055f}, /* 15 mm above the top face */
                             {-0.003f, 0.02f, 0.02f}, /* 3 mm left */
                             {0.02f, 0.02f, 0.02f}};  /* inside */
    pp_tet_hash *h;
    char err[128];
    assert_int_equal(pp_tet_hash_build(&m, 0, &h, err, sizeof err), POSE_OK);
    uint32_t tet[3];
    float bary[12];
    pp_embed_report rep = {0};
    assert_int_equal(pp_embed_points(h, &pts[0][0], 3, -1, 0, 1, tet, bary, &rep), POSE_OK);
    assert_int_equal(rep.outside, 2);
    assert_true(fabs(rep.max_distance - 0.015) < 1e-6);
    for (int i = 0; i < 3; i++) {
        double s = 0;
        for (int c = 0; c < 3; c++) {
            double x = 0;
            for (int k = 0; k < 4; k++)
                x += bary[4 * i + k] * m.positions[3 * (size_t)m.tets[4 * (size_t)tet[i] + k] + c];
            assert_true(fabs(x - pts[i][c]) < 1e-6);
        }
        for (int k = 0; k < 4; k++)
            s += bary[4 * i + k];
        assert_true(fabs(s - 1) < 1e-6);
    }
    /* The nearest tet touches the top face: one of its vertices has z = 0.04. */
    int top = 0;
    for (int k = 0; k < 4; k++)
        top |= m.positions[3 * (size_t)m.tets[4 * (size_t)tet[0] + k] + 2] > 0.0399f;
    assert_true(top);
    pp_tet_hash_free(h);
    pp_tetmesh_free(&m);
}

/* A bone vertex asks for its own bone's tets and gets one even when it
 * lies just outside them, in soft tissue. */
static void test_prefers_own_label(void **state)
{
    (void)state;
    pp_tetmesh m;
    assert_int_equal(pp_test_box(8, 2, 2, H, &m), 0);
    pp_test_label_slab(&m, H, 0, 3, 1);
    const float p[3] = {0.0335f, 0.01f, 0.01f}; /* 3.5 mm past the bone slab */
    pp_tet_hash *h;
    char err[128];
    assert_int_equal(pp_tet_hash_build(&m, 0, &h, err, sizeof err), POSE_OK);
    uint32_t t;
    float b[4];
    pp_embed_report rep = {0};
    assert_int_equal(pp_embed_points(h, p, 1, 1, 0.02, 1, &t, b, &rep), POSE_OK);
    assert_int_equal(m.labels[t], 1);
    assert_int_equal(rep.outside, 0);
    assert_int_equal(rep.label_fallback, 0);
    /* Out of reach of the label: falls back to the containing soft tet. */
    const float far[3] = {0.07f, 0.01f, 0.01f};
    assert_int_equal(pp_embed_points(h, far, 1, 1, 0.01, 1, &t, b, &rep), POSE_OK);
    assert_int_equal(m.labels[t], 0);
    assert_int_equal(rep.label_fallback, 1);
    pp_tet_hash_free(h);
    pp_tetmesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rejects_empty_mesh),
        cmocka_unit_test(test_inside_points_exact),
        cmocka_unit_test(test_outside_points),
        cmocka_unit_test(test_prefers_own_label),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
