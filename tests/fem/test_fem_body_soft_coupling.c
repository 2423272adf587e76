/* SPDX-License-Identifier: Apache-2.0 */
/* Soft-soft couplings on the body baked from the bundled anatomy (the
 * fem_body_bake fixture, POSE_FEM_RIG). The body's soft tissue is one
 * connected lattice, so the check is of what the springs must not do and
 * of their cost at body scale: each free node within REACH of the right
 * tibia that has two lattice neighbours symmetric about it is tied to their
 * midpoint (weights 1/2, 1/2: slack at rest; 15 nodes on the coarse bake,
 * 4 with a neighbour in another of the solvers' 1024-vertex chunks, at
 * least one required). At rest POSE_FEM is unchanged by them; through a
 * knee ramp pose_step gives the same bits on 1 and 2 threads, stays finite
 * and keeps the tied nodes near their points. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fem_body_rig.h"
#include "pose/pose.h"

#define REACH 0.05f /* rig units (m) */
#define DT (1.0 / 120.0)
#define STEPS 20

static pose_rig *g_rig;
static int g_knee[2];
static pose_fem_soft_coupling *g_soft;
static size_t g_soft_count;
static size_t g_crossing; /* springs whose ends lie in different 1024-vertex chunks */

/* Each node near the right tibia tied to the midpoint of two neighbours
 * (a tet edge each) whose rest positions are symmetric about it; nodes of
 * a bone tet are not free (pose_fem_soft_coupling ignores them). */
static int setup(void **state)
{
    (void)state;
    if (!(g_rig = fem_body_rig_load()))
        return -1;
    g_knee[0] = pose_rig_find_joint(g_rig, "knee_r");
    g_knee[1] = pose_rig_find_joint(g_rig, "knee_l");
    pose_tet_info tet;
    if (g_knee[0] < 0 || g_knee[1] < 0 || pose_rig_tet_info(g_rig, &tet) != POSE_OK)
        return -1;
    size_t n = 0;
    if (pose_rig_fem_nodes_near_joint(g_rig, g_knee[0], REACH, NULL, 0, &n) != POSE_OK || !n)
        return -1;
    uint32_t *near = malloc(n * sizeof *near);
    uint8_t *held = calloc(tet.vertex_count, 1);
    g_soft = malloc(n * sizeof *g_soft);
    if (!near || !held || !g_soft ||
        pose_rig_fem_nodes_near_joint(g_rig, g_knee[0], REACH, near, n, &n) != POSE_OK)
        return -1;
    for (size_t t = 0; t < tet.tet_count; t++)
        for (int c = 0; c < 4 && tet.labels[t]; c++)
            held[tet.tets[4 * t + (size_t)c]] = 1;
    const float *x = tet.rest_positions;
    for (size_t i = 0; i < n; i++) {
        const uint32_t a = near[i];
        uint32_t nb[64];
        size_t k = 0;
        for (size_t t = 0; t < tet.tet_count && k < 60; t++) { /* a's neighbours */
            const uint32_t *tv = tet.tets + 4 * t;
            if (tv[0] != a && tv[1] != a && tv[2] != a && tv[3] != a)
                continue;
            for (int c = 0; c < 4; c++)
                if (tv[c] != a && !held[tv[c]])
                    nb[k++] = tv[c];
        }
        int found = 0;
        for (size_t p = 0; p < k && !found; p++)
            for (size_t q = p + 1; q < k && !found; q++) {
                const uint32_t b = nb[p], c = nb[q];
                double off = 0.0;
                for (size_t e = 0; e < 3; e++)
                    off = fmax(off, fabs(0.5 * ((double)x[3 * b + e] + x[3 * c + e]) - x[3 * a + e]));
                if (b != c && off < 1e-6) {
                    g_soft[g_soft_count++] = (pose_fem_soft_coupling){
                        .node = a, .other = {b, c}, .weight = {0.5f, 0.5f}, .stiffness = 100.0f};
                    g_crossing += a / 1024 != b / 1024 || a / 1024 != c / 1024;
                    found = 1;
                }
            }
    }
    free(near);
    free(held);
    return g_crossing > 0 ? 0 : -1; /* at least one spring across chunks */
}

static int teardown(void **state)
{
    (void)state;
    free(g_soft);
    pose_rig_free(g_rig);
    return 0;
}

static pose_state *new_state(int threads, int tied)
{
    pose_state_options so = {.size = sizeof so, .threads = threads, .method = POSE_FEM};
    pose_state *st;
    assert_int_equal(pose_state_create_ex(g_rig, &so, &st), POSE_OK);
    if (tied) {
        assert_int_equal(pose_set_fem_soft_couplings(st, g_soft, g_soft_count, sizeof *g_soft),
                         POSE_OK);
        assert_int_equal(pose_fem_soft_coupling_count(st), g_soft_count);
    }
    return st;
}

/* Largest distance from a tied node to its point. */
static double tie_gap(const pose_state *st)
{
    const float *x = pose_tet_positions(st, NULL);
    double worst = 0.0;
    for (size_t i = 0; i < g_soft_count; i++) {
        const pose_fem_soft_coupling *c = &g_soft[i];
        double d2 = 0.0;
        for (int e = 0; e < 3; e++) {
            const double p =
                0.5 * ((double)x[3 * c->other[0] + (size_t)e] + x[3 * c->other[1] + (size_t)e]);
            d2 += pow(x[3 * c->node + (size_t)e] - p, 2);
        }
        worst = fmax(worst, sqrt(d2));
    }
    return worst;
}

/* POSE_FEM at rest: slack springs change nothing but rounding. */
static void test_slack_at_rest(void **state)
{
    (void)state;
    pose_state *free_st = new_state(2, 0), *tied = new_state(2, 1);
    assert_int_equal(pose_apply(free_st), POSE_OK);
    assert_int_equal(pose_apply(tied), POSE_OK);
    size_t nv;
    const float *a = pose_tet_positions(free_st, &nv), *b = pose_tet_positions(tied, NULL);
    double worst = 0.0;
    for (size_t i = 0; i < 3 * nv; i++)
        worst = fmax(worst, fabs((double)a[i] - b[i]));
    printf("body, %zu nodes near the right tibia tied to midpoints of their neighbours (%zu "
           "across chunks): POSE_FEM at rest moves by %.2g mm with them\n",
           g_soft_count, g_crossing, 1e3 * worst);
    assert_true(worst < 1e-5);
    pose_state_free(free_st);
    pose_state_free(tied);
}

/* pose_step through a 0-60 degree knee ramp: 1 and 2 threads give the same
 * bits; the tied nodes stay near their points. */
static void test_threads_same_bits(void **state)
{
    (void)state;
    pose_state *st[3] = {new_state(1, 1), new_state(2, 1), new_state(2, 0)};
    double gap = 0.0, ms[3] = {0, 0, 0};
    int iterations[3] = {0, 0, 0};
    for (int i = 1; i <= STEPS; i++)
        for (int s = 0; s < 3; s++) {
            const float deg[3] = {(float)(60.0 * i / STEPS), 0.0f, 0.0f};
            for (int k = 0; k < 2; k++)
                assert_true(pose_set_joint_clinical(st[s], g_knee[k], deg) >= 0);
            assert_int_equal(pose_step(st[s], DT), POSE_OK);
            pose_dynamics_stats ds = {.size = sizeof ds};
            assert_int_equal(pose_get_dynamics_stats(st[s], &ds), POSE_OK);
            assert_int_equal(ds.islands, 1);
            iterations[s] += ds.cg_iterations;
            ms[s] += 1e3 * (ds.seconds_assembly + ds.seconds_cg);
            if (s == 1)
                gap = fmax(gap, tie_gap(st[1]));
        }
    size_t nv;
    const float *x = pose_tet_positions(st[0], &nv);
    assert_memory_equal(x, pose_tet_positions(st[1], NULL), 3 * nv * sizeof(float));
    for (size_t i = 0; i < 3 * nv; i++)
        assert_true(isfinite(x[i]));
    printf("body, knees 0-60 deg in %d steps of 1/120 s: tied nodes at most %.3f mm off their "
           "points; CG %.1f iterations and %.1f ms (assembly + CG, 2 threads) a step tied, %.1f "
           "and %.1f free; 1 and 2 threads the same bits\n",
           STEPS, 1e3 * gap, (double)iterations[1] / STEPS, ms[1] / STEPS,
           (double)iterations[2] / STEPS, ms[2] / STEPS);
    assert_true(gap < 1e-3);
    for (int s = 0; s < 3; s++)
        pose_state_free(st[s]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slack_at_rest),
        cmocka_unit_test(test_threads_same_bits),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
