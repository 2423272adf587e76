/* SPDX-License-Identifier: Apache-2.0
 * Harmonic weights on bars: the linear-tet solution of Laplace's equation
 * between two bone slabs is exactly linear in x (linear functions are
 * harmonic and lie in the finite-element space), so weights are checked
 * against the analytic ramp, not just for plausibility. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pp_test_mesh.h"
#include "tetmesh.h"
#include "weights_fem.h"

enum { NX = 24, NY = 2, NZ = 2 };
static const float H = 0.01f;

static void test_rejects_bad_labels(void **state)
{
    (void)state;
    pp_tetmesh m;
    assert_int_equal(pp_test_box(4, 1, 1, H, &m), 0);
    pp_weights w;
    char err[256];
    /* No bone at all: nothing to bind to. */
    assert_true(pp_weights_compute(&m, 2, NULL, &w, NULL, err, sizeof err) < 0);
    assert_non_null(strstr(err, "no tet is labelled as bone"));
    /* A label naming a joint that does not exist. */
    m.labels[0] = 3;
    assert_int_equal(pp_weights_compute(&m, 2, NULL, &w, NULL, err, sizeof err),
                     POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(err, "label 3"));
    /* K above the maximum. */
    m.labels[0] = 1;
    pp_weight_options o = {.influences = 9};
    assert_int_equal(pp_weights_compute(&m, 2, &o, &w, NULL, err, sizeof err),
                     POSE_ERR_INVALID_ARGUMENT);
    pp_tetmesh_free(&m);
}

static double x_of(const pp_tetmesh *m, size_t v)
{
    return m->positions[3 * v];
}

static void test_two_bone_bar(void **state)
{
    (void)state;
    pp_tetmesh m;
    assert_int_equal(pp_test_box(NX, NY, NZ, H, &m), 0);
    pp_test_label_slab(&m, H, 0, 3, 1);        /* joint 0: cells 0..2, x in [0, 0.03] */
    pp_test_label_slab(&m, H, NX - 3, NX, 2);  /* joint 1: x in [0.21, 0.24] */
    pp_weights w;
    pp_weight_report rep;
    char err[256];
    assert_int_equal(pp_weights_compute(&m, 2, NULL, &w, &rep, err, sizeof err), POSE_OK);
    assert_int_equal(w.influences, 2); /* K capped at the joint count */
    assert_true(rep.min_weight > -1e-12);
    assert_true(rep.max_weight < 1 + 1e-12);
    assert_true(rep.max_sum_error < 1e-9);
    assert_int_equal(rep.fixed_vertices, 2 * 4 * (NY + 1) * (NZ + 1));
    const double xa = 0.03, xb = 0.21;
    for (size_t v = 0; v < m.vertex_count; v++) {
        double x = x_of(&m, v), w0 = pp_weights_get(&w, v, 0), w1 = pp_weights_get(&w, v, 1);
        assert_true(fabs(w0 + w1 - 1.0) < 1e-6);
        if (x <= xa + 1e-6) {
            assert_true(w0 == 1.0f && w1 == 0.0f); /* exactly, on bone tets */
        } else if (x >= xb - 1e-6) {
            assert_true(w0 == 0.0f && w1 == 1.0f);
        } else {
            assert_true(fabs(w0 - (xb - x) / (xb - xa)) < 1e-5);
        }
    }
    /* Monotonic along every lattice line. */
    for (int k = 0; k <= NZ; k++)
        for (int j = 0; j <= NY; j++)
            for (int i = 0; i < NX; i++) {
                size_t a = pp_test_vertex(NX, NY, i, j, k), b = pp_test_vertex(NX, NY, i + 1, j, k);
                assert_true(pp_weights_get(&w, a, 0) >= pp_weights_get(&w, b, 0) - 1e-7f);
            }
    pp_weights_free(&w);
    pp_tetmesh_free(&m);
}

/* Four bones in a row: between neighbours the weights are the two hat
 * functions; every other joint is 0 there (after top-K). */
static void test_four_bone_bar(void **state)
{
    (void)state;
    pp_tetmesh m;
    assert_int_equal(pp_test_box(NX, NY, NZ, H, &m), 0);
    const int slab[4][2] = {{0, 2}, {7, 9}, {14, 16}, {22, 24}};
    for (int j = 0; j < 4; j++)
        pp_test_label_slab(&m, H, slab[j][0], slab[j][1], (uint16_t)(j + 1));
    pp_weights w;
    pp_weight_report rep;
    char err[256];
    pp_weight_options o = {.influences = 4, .block = 3}; /* two solve blocks */
    assert_int_equal(pp_weights_compute(&m, 4, &o, &w, &rep, err, sizeof err), POSE_OK);
    assert_true(rep.max_sum_error < 1e-9);
    assert_true(rep.min_weight > -1e-9);
    for (size_t v = 0; v < m.vertex_count; v++) {
        double x = x_of(&m, v), s = 0;
        for (unsigned j = 0; j < 4; j++)
            s += pp_weights_get(&w, v, j);
        assert_true(fabs(s - 1.0) < 1e-6);
        for (int j = 0; j < 4; j++) {
            double lo = slab[j][0] * H, hi = slab[j][1] * H, expect;
            if (x >= lo - 1e-6 && x <= hi + 1e-6)
                expect = 1;
            else if (j > 0 && x < lo && x > slab[j - 1][1] * H)
                expect = (x - slab[j - 1][1] * H) / (lo - slab[j - 1][1] * H);
            else if (j < 3 && x > hi && x < slab[j + 1][0] * H)
                expect = (slab[j + 1][0] * H - x) / (slab[j + 1][0] * H - hi);
            else
                expect = 0;
            assert_true(fabs(pp_weights_get(&w, v, (unsigned)j) - expect) < 1e-5);
        }
    }
    pp_weights_free(&w);
    pp_tetmesh_free(&m);
}

/* K = 1 keeps only the strongest joint, renormalized to 1. */
static void test_keep_k_largest(void **state)
{
    (void)state;
    pp_tetmesh m;
    assert_int_equal(pp_test_box(NX, 1, 1, H, &m), 0);
    pp_test_label_slab(&m, H, 0, 2, 1);
    pp_test_label_slab(&m, H, NX - 2, NX, 2);
    pp_weights w;
    pp_weight_report rep;
    char err[256];
    pp_weight_options o = {.influences = 1};
    assert_int_equal(pp_weights_compute(&m, 2, &o, &w, &rep, err, sizeof err), POSE_OK);
    assert_int_equal(w.influences, 1);
    assert_true(rep.max_dropped > 0.4 && rep.max_dropped <= 0.5 + 1e-9);
    for (size_t v = 0; v < m.vertex_count; v++) {
        assert_true(w.weights[v] == 1.0f);
        assert_int_equal(w.joints[v], x_of(&m, v) < 0.12 - 1e-6 ? 0 : x_of(&m, v) > 0.12 + 1e-6 ? 1 : w.joints[v]);
    }
    pp_weights_free(&w);
    pp_tetmesh_free(&m);
}

/* A soft island with no bone is pinned to the nearest bone's joint rather
 * than leaving the matrix singular. */
static void test_floating_island_is_pinned(void **state)
{
    (void)state;
    pp_tetmesh a, b;
    assert_int_equal(pp_test_box(6, 1, 1, H, &a), 0);
    assert_int_equal(pp_test_box(2, 1, 1, H, &b), 0);
    pp_test_label_slab(&a, H, 0, 1, 1);
    pp_test_label_slab(&a, H, 5, 6, 2);
    /* Append b, shifted past a's right end (near joint 1). */
    pp_tetmesh m = {0};
    m.vertex_count = a.vertex_count + b.vertex_count;
    m.tet_count = a.tet_count + b.tet_count;
    m.positions = malloc(3 * m.vertex_count * sizeof(float));
    m.tets = malloc(4 * m.tet_count * sizeof(uint32_t));
    m.labels = calloc(m.tet_count, sizeof(uint16_t));
    memcpy(m.positions, a.positions, 3 * a.vertex_count * sizeof(float));
    for (size_t v = 0; v < b.vertex_count; v++) {
        m.positions[3 * (a.vertex_count + v)] = b.positions[3 * v] + 0.1f;
        m.positions[3 * (a.vertex_count + v) + 1] = b.positions[3 * v + 1];
        m.positions[3 * (a.vertex_count + v) + 2] = b.positions[3 * v + 2];
    }
    memcpy(m.tets, a.tets, 4 * a.tet_count * sizeof(uint32_t));
    for (size_t i = 0; i < 4 * b.tet_count; i++)
        m.tets[4 * a.tet_count + i] = b.tets[i] + (uint32_t)a.vertex_count;
    memcpy(m.labels, a.labels, a.tet_count * sizeof(uint16_t));
    pp_weights w;
    pp_weight_report rep;
    char err[256];
    assert_int_equal(pp_weights_compute(&m, 2, NULL, &w, &rep, err, sizeof err), POSE_OK);
    assert_int_equal(rep.floating_regions, 1);
    assert_int_equal(rep.floating_vertices, b.vertex_count);
    for (size_t v = a.vertex_count; v < m.vertex_count; v++)
        assert_true(pp_weights_get(&w, v, 1) == 1.0f);
    pp_weights_free(&w);
    pp_tetmesh_free(&m);
    pp_tetmesh_free(&a);
    pp_tetmesh_free(&b);
}

/* A two-bone bar whose inner vertices are jittered by up to 0.25 cells, so
 * that many tets are obtuse (as snapping makes them) and the plain FEM
 * operator has positive off-diagonal entries (no maximum principle; on the
 * shared body its weights reached -0.07..1.07). The default lumps those
 * entries onto the diagonal, an M-matrix: the raw weights stay in [0, 1]
 * before any clamping and still sum to 1. */
static void test_obtuse_tets_keep_bounds(void **state)
{
    (void)state;
    pp_tetmesh m;
    assert_int_equal(pp_test_box(12, 4, 4, H, &m), 0);
    pp_test_label_slab(&m, H, 0, 1, 1);
    pp_test_label_slab(&m, H, 11, 12, 2);
    uint32_t seed = 12345;
    for (size_t v = 0; v < m.vertex_count; v++) {
        float *p = m.positions + 3 * v;
        if (p[0] < 1.5f * H || p[0] > 10.5f * H)
            continue; /* bone vertices stay */
        for (int k = 0; k < 3; k++) {
            seed = seed * 1664525u + 1013904223u;
            p[k] += 0.25f * H * ((float)(seed >> 8) / 16777216.0f * 2.0f - 1.0f);
        }
    }
    for (size_t t = 0; t < m.tet_count; t++)
        assert_true(pp_tet_volume(&m, t) > 0.0); /* still a valid mesh */
    char err[256];
    pp_weights w;
    pp_weight_report plain, lumped;
    pp_weight_options o = {.plain_fem = 1};
    assert_int_equal(pp_weights_compute(&m, 2, &o, &w, &plain, err, sizeof err), POSE_OK);
    pp_weights_free(&w);
    assert_int_equal(plain.clipped_entries, 0);
    assert_int_equal(pp_weights_compute(&m, 2, NULL, &w, &lumped, err, sizeof err), POSE_OK);
    assert_true(lumped.clipped_entries > 0);
    assert_true(lumped.min_weight >= -1e-9);
    assert_true(lumped.max_weight <= 1 + 1e-9);
    assert_true(lumped.max_sum_error < 1e-9);
    pp_weights_free(&w);
    pp_tetmesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rejects_bad_labels),
        cmocka_unit_test(test_two_bone_bar),
        cmocka_unit_test(test_four_bone_bar),
        cmocka_unit_test(test_keep_k_largest),
        cmocka_unit_test(test_floating_island_is_pinned),
        cmocka_unit_test(test_obtuse_tets_keep_bounds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
