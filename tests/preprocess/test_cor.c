/* SPDX-License-Identifier: Apache-2.0
 * Centres of rotation: the fast clustered evaluation against the direct
 * formula on small meshes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cor_fast.h"
#include "pp_test_mesh.h"

static const float H = 0.01f;

static void bar(pp_tetmesh *m, pp_weights *w, int bones, unsigned k)
{
    assert_int_equal(pp_test_box(16, 3, 3, H, m), 0);
    /* Bones spread along the bar; the ends and the middle. */
    for (int j = 0; j < bones; j++) {
        int c = j * 15 / (bones - 1);
        pp_test_label_slab(m, H, c, c + 1, (uint16_t)(j + 1));
    }
    /* A bent bar: shear the vertices so the centres are not trivially on
     * the axis. */
    for (size_t v = 0; v < m->vertex_count; v++) {
        float *p = m->positions + 3 * v;
        p[2] += 0.2f * (p[0] - 0.08f) * (p[0] - 0.08f) * 10.0f;
    }
    char err[256];
    /* The plain FEM operator: the sheared bar has obtuse tets, and lumping
     * them (the default) gives weights with kinks on which the default bin
     * step deviates 1.4e-4 of the bar's length (two bones); these checks are
     * about the CoR sums, not the weights. */
    pp_weight_options o = {.influences = k, .plain_fem = 1};
    assert_int_equal(pp_weights_compute(m, (size_t)bones, &o, w, NULL, err, sizeof err), POSE_OK);
}

static double max_dev(const float *a, const float *b, size_t n)
{
    double d = 0;
    for (size_t i = 0; i < 3 * n; i++)
        d = fmax(d, fabs((double)a[i] - b[i]));
    return d;
}

static void check_fast_matches_naive(int bones, unsigned k, int threads, double tol)
{
    pp_tetmesh m;
    pp_weights w;
    bar(&m, &w, bones, k);
    float *naive = malloc(3 * m.vertex_count * sizeof(float));
    float *fast = malloc(3 * m.vertex_count * sizeof(float));
    assert_int_equal(pp_cor_naive(&m, &w, 0.1, naive), POSE_OK);
    pp_cor_options o = {.sigma = 0.1, .tolerance = tol, .threads = threads};
    pp_cor_report rep;
    char err[128];
    assert_int_equal(pp_cor_compute(&m, &w, &o, fast, &rep, err, sizeof err), POSE_OK);
    assert_true(rep.vertices_with_cor > 0);
    assert_true(rep.bins > 0 && rep.pairs > 0 && rep.tets_used > 0);
    if (tol < 0) /* exact mode: one bin per (tet, pair) */
        assert_true(rep.bins >= rep.tets_used);
    else
        assert_true(rep.evaluations > 0);
    /* Model size: the bar is 0.16 m long; required deviation < 1e-4 of it. */
    double dev = max_dev(naive, fast, m.vertex_count);
    assert_true(dev < 1e-4 * 0.16);
    if (tol < 0) /* without clustering the two are the same sum */
        assert_true(dev < 1e-6);
    /* Centres of multi-joint vertices lie inside the bar's bounding box (a
     * convex combination of tet centroids). */
    for (size_t v = 0; v < m.vertex_count; v++) {
        assert_true(fast[3 * v] >= -1e-6f && fast[3 * v] <= 0.16f + 1e-6f);
        if (pp_weights_get(&w, v, 0) == 1.0f) /* rigid vertices keep their position */
            assert_true(fast[3 * v] == m.positions[3 * v]);
    }
    free(naive);
    free(fast);
    pp_weights_free(&w);
    pp_tetmesh_free(&m);
}

static void test_rejects_mismatched_weights(void **state)
{
    (void)state;
    pp_tetmesh m;
    pp_weights w;
    bar(&m, &w, 2, 2);
    w.vertex_count--;
    float *c = malloc(3 * m.vertex_count * sizeof(float));
    char err[128];
    assert_int_equal(pp_cor_compute(&m, &w, NULL, c, NULL, err, sizeof err),
                     POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "weights"));
    w.vertex_count++;
    free(c);
    pp_weights_free(&w);
    pp_tetmesh_free(&m);
}

static void test_exact_without_clustering(void **state)
{
    (void)state;
    check_fast_matches_naive(3, 4, 1, -1);
}

static void test_clustered_two_bones(void **state)
{
    (void)state;
    check_fast_matches_naive(2, 2, 1, 0);
}

static void test_clustered_four_bones_threads(void **state)
{
    (void)state;
    check_fast_matches_naive(4, 4, 3, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rejects_mismatched_weights),
        cmocka_unit_test(test_exact_without_clustering),
        cmocka_unit_test(test_clustered_two_bones),
        cmocka_unit_test(test_clustered_four_bones_threads),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
