/* SPDX-License-Identifier: Apache-2.0 */
/* Soft-soft couplings (pose.h pose_fem_soft_coupling): zero-length springs
 * between soft simulation nodes, in POSE_FEM and pose_step. Two separate
 * boxes of tets side by side along x: A held at its far end by bone cells
 * of the root joint, B all soft and touching A's free face with a face of
 * its own (coincident nodes, no shared vertex). Under gravity B falls away
 * when free; tied node to node it hangs from A as one body, as a single
 * box of both lengths does; shifted half a cell, its nodes tied to points
 * of A's face (four weights each) hang it the same way. */
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
#include "fem_links.h"
#include "pose/pose.h"

#define NA 8 /* cells of A along x (the first bone) */
#define NB 8 /* cells of B along x */
#define N 8  /* cells across */
#define D 0.015f
#define G (-9.81f)

typedef struct pair_rig {
    size_t nv_a, nv;  /* A's vertices first, then B's */
    float *pos;       /* rest positions (the rig's copy is the same) */
    pose_rig *rig;
} pair_rig;

/* A and B as two meshes (B shifted by half a cell across with `shift`), or
 * (merged) one box of NA + NB cells. */
static pair_rig make_pair(int merged, int shift, const pose_fem_soft_coupling *soft,
                          size_t soft_count)
{
    box a = make_box(merged ? NA + NB : NA, N, N, D, 1), b = make_box(NB, N, N, D, 0);
    pair_rig p = {.nv_a = a.nv, .nv = merged ? a.nv : a.nv + b.nv};
    const size_t nt = merged ? a.nt : a.nt + b.nt;
    p.pos = malloc(3 * p.nv * sizeof(float));
    uint32_t *tets = malloc(4 * nt * sizeof(uint32_t));
    uint16_t *labels = malloc(nt * sizeof(uint16_t));
    uint16_t *wj = calloc(p.nv, sizeof(uint16_t));
    float *w = malloc(p.nv * sizeof(float));
    assert_true(p.pos && tets && labels && wj && w);
    memcpy(p.pos, a.pos, 3 * a.nv * sizeof(float));
    memcpy(tets, a.tets, 4 * a.nt * sizeof(uint32_t));
    memcpy(labels, a.labels, a.nt * sizeof(uint16_t));
    if (!merged) {
        for (size_t v = 0; v < b.nv; v++) {
            p.pos[3 * (a.nv + v)] = b.pos[3 * v] + NA * D;
            p.pos[3 * (a.nv + v) + 1] = b.pos[3 * v + 1] + (shift ? 0.5f * D : 0.0f);
            p.pos[3 * (a.nv + v) + 2] = b.pos[3 * v + 2] + (shift ? 0.5f * D : 0.0f);
        }
        for (size_t t = 0; t < 4 * b.nt; t++)
            tets[4 * a.nt + t] = b.tets[t] + (uint32_t)a.nv;
        memcpy(labels + a.nt, b.labels, b.nt * sizeof(uint16_t));
    }
    for (size_t v = 0; v < p.nv; v++)
        w[v] = 1.0f;
    pose_joint_desc j = {.name = "root", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, 0, 0}}};
    const pose_fem_material fem = {1e5f, 0.45f, 1000.0f};
    pose_rig_desc d = {.joint_count = 1, .joints = &j, .tet_vertex_count = p.nv,
                       .tet_positions = p.pos, .tet_count = nt, .tets = tets,
                       .tet_labels = labels, .influences = 1, .weight_joints = wj, .weights = w,
                       .fem = &fem, .fem_soft_coupling_count = soft_count,
                       .fem_soft_couplings = soft};
    if (pose_rig_create(&d, NULL, &p.rig) != POSE_OK)
        fail_msg("pair rig: %s", pose_last_error());
    free(tets);
    free(labels);
    free(wj);
    free(w);
    free_box(&a);
    free_box(&b);
    return p;
}

static void free_pair(pair_rig *p)
{
    pose_rig_free(p->rig);
    free(p->pos);
}

/* The interface: each node of B's face x = NA D tied to A's node there
 * (weight 1); returns the count (81). */
static size_t tie_faces(const pair_rig *p, float stiffness, pose_fem_soft_coupling *out)
{
    box a = {.nx = NA, .ny = N, .nz = N}, b = {.nx = NB, .ny = N, .nz = N};
    size_t n = 0;
    for (int j = 0; j <= N; j++)
        for (int k = 0; k <= N; k++) {
            out[n] = (pose_fem_soft_coupling){.node = (uint32_t)p->nv_a + vid(&b, 0, j, k),
                                              .other = {vid(&a, NA, j, k)},
                                              .weight = {1.0f},
                                              .stiffness = stiffness};
            n++;
        }
    return n;
}

static pose_state *new_state(const pose_rig *rig, pose_method method, int threads)
{
    pose_state_options so = {.size = sizeof so, .threads = threads, .method = method};
    pose_state *st = NULL;
    assert_int_equal(pose_state_create_ex(rig, &so, &st), POSE_OK);
    return st;
}

static void set_gravity(pose_state *st)
{
    pose_dynamics_options o;
    pose_dynamics_defaults(&o);
    o.gravity[2] = G;
    o.cg_iterations = 400; /* converged: stiff ties take 3 times the single box's (about 190 vs 70) */
    assert_int_equal(pose_set_dynamics_options(st, &o), POSE_OK);
    /* converged far enough to compare with the single box's sag */
    pose_fem_options f = {.size = sizeof f, .outer_iterations = 2, .cg_iterations = 2000,
                          .tolerance = 1e-3f, .gravity = {0.0f, 0.0f, G}};
    assert_int_equal(pose_set_fem_options(st, &f), POSE_OK);
}

/* Largest distance between the two ends of the couplings c (weight-1 node pairs). */
static double tie_gap(const pose_state *st, const pose_fem_soft_coupling *c, size_t n)
{
    const float *x = pose_tet_positions(st, NULL);
    double worst = 0.0;
    for (size_t i = 0; i < n; i++) {
        const float *p = x + 3 * (size_t)c[i].node, *q = x + 3 * (size_t)c[i].other[0];
        worst = fmax(worst, sqrt(pow(p[0] - q[0], 2) + pow(p[1] - q[1], 2) + pow(p[2] - q[2], 2)));
    }
    return worst;
}

/* Mean z displacement of B's far face (x = (NA + NB) D) from rest. */
static double far_drop(const pair_rig *p, const pose_state *st)
{
    const float *x = pose_tet_positions(st, NULL);
    double sum = 0.0;
    int n = 0;
    for (size_t v = 0; v < p->nv; v++)
        if (fabsf(p->pos[3 * v] - (NA + NB) * D) < 1e-6f) {
            sum += x[3 * v + 2] - p->pos[3 * v + 2];
            n++;
        }
    return sum / n;
}

/* The spring's force is k times the separation and minus the gradient of
 * its energy 1/2 k |x_a - sum w_c x_c|^2 (central differences), for a node
 * pair and a node tied to a point inside a tet. */
static void test_force_is_energy_gradient(void **state)
{
    (void)state;
    const uint32_t node[2] = {0, 1}, corner[8] = {2, 0, 0, 0, 3, 4, 5, 6};
    const float weight[8] = {1, 0, 0, 0, 0.1f, 0.2f, 0.3f, 0.4f}, k[2] = {3.0f, 7.0f};
    const uint32_t touched[7] = {0, 1, 2, 3, 4, 5, 6};
    float x[21], out[21], out2[21];
    srand(7);
    for (int i = 0; i < 21; i++)
        x[i] = (float)((double)rand() / RAND_MAX - 0.5);
    for (int s = 0; s < 2; s++) {
        const pose__fem_links l = {.count = 1, .node = node + s, .corner = corner + 4 * s,
                                   .weight = weight + 4 * s, .k = k + s, .touched_count = 7,
                                   .touched = touched, .out = out, .out2 = out2};
        pose__fem_links_product(&l, x, NULL, 0.0f, out);
        double sep[3];
        for (int a = 0; a < 3; a++) {
            sep[a] = x[3 * node[s] + a];
            for (int c = 0; c < 4; c++)
                sep[a] -= (double)weight[4 * s + c] * x[3 * corner[4 * s + c] + a];
        }
        /* |force on the node| = k |separation| (K_l x is minus the force) */
        for (int a = 0; a < 3; a++)
            assert_true(fabs(out[3 * node[s] + a] - k[s] * sep[a]) < 1e-5 * k[s]);
        for (int i = 0; i < 21; i++) {
            const float h = 1e-3f, keep = x[i];
            double e[2];
            for (int side = 0; side < 2; side++) {
                x[i] = keep + (side ? h : -h);
                double d2 = 0.0;
                for (int a = 0; a < 3; a++) {
                    double da = x[3 * node[s] + a];
                    for (int c = 0; c < 4; c++)
                        da -= (double)weight[4 * s + c] * x[3 * corner[4 * s + c] + a];
                    d2 += da * da;
                }
                e[side] = 0.5 * k[s] * d2;
            }
            x[i] = keep;
            const double grad = (e[1] - e[0]) / (2.0 * h);
            assert_true(fabs(grad - out[i]) < 1e-3 * k[s]);
        }
    }
}

/* pose_step under gravity for 0.25 s: free, B falls away from A (2
 * islands); tied, one island hanging from A, its far face within 2 % of a
 * single box's, the tied nodes within 0.01 mm of each other. */
static void test_dynamics_one_island(void **state)
{
    (void)state;
    pair_rig two = make_pair(0, 0, NULL, 0), one = make_pair(1, 0, NULL, 0);
    pose_fem_soft_coupling c[81];
    const size_t n = tie_faces(&two, 100.0f, c);
    pose_state *free_st = new_state(two.rig, POSE_DQS, 1), *tied = new_state(two.rig, POSE_DQS, 1),
               *merged = new_state(one.rig, POSE_DQS, 1);
    assert_int_equal(pose_set_fem_soft_couplings(tied, c, n, sizeof c[0]), POSE_OK);
    assert_int_equal(pose_fem_soft_coupling_count(tied), 81);
    pose_state *all[3] = {free_st, tied, merged};
    for (int s = 0; s < 3; s++)
        set_gravity(all[s]);
    pose_dynamics_stats ds = {.size = sizeof ds};
    assert_int_equal(pose_get_dynamics_stats(free_st, &ds), POSE_OK);
    assert_int_equal(ds.islands, 2);
    assert_int_equal(pose_get_dynamics_stats(tied, &ds), POSE_OK);
    assert_int_equal(ds.islands, 1);
    double gap = 0.0;
    int iterations = 0, single_it = 0;
    for (int i = 0; i < 30; i++)
        for (int s = 0; s < 3; s++) {
            assert_int_equal(pose_step(all[s], 1.0 / 120.0), POSE_OK);
            if (s == 1) {
                gap = fmax(gap, tie_gap(tied, c, n));
                assert_int_equal(pose_get_dynamics_stats(tied, &ds), POSE_OK);
                iterations = ds.cg_iterations > iterations ? ds.cg_iterations : iterations;
            }
            if (s == 2) {
                assert_int_equal(pose_get_dynamics_stats(merged, &ds), POSE_OK);
                single_it = ds.cg_iterations > single_it ? ds.cg_iterations : single_it;
            }
        }
    assert_int_equal(pose_get_dynamics_stats(tied, &ds), POSE_OK);
    assert_int_equal(ds.islands, 1);
    const double fell = far_drop(&two, free_st), hung = far_drop(&two, tied),
                 single = far_drop(&one, merged);
    printf("dynamics, gravity 0.25 s: B's far face dropped %.2f mm free, %.2f mm tied, %.2f mm "
           "as one box; tied nodes at most %.4f mm apart; CG at most %d iterations a step (one "
           "box: %d)\n",
           1e3 * -fell, 1e3 * -hung, 1e3 * -single, 1e3 * gap, iterations, single_it);
    assert_true(-fell > 0.2);                        /* free fall: 0.3 m less damping */
    assert_true(fabs(hung - single) < 0.02 * fabs(single)); /* hangs as one body (0.5 %) */
    assert_true(gap < 1e-5);                               /* 0.0026 mm */
    for (int s = 0; s < 3; s++)
        pose_state_free(all[s]);
    free_pair(&two);
    free_pair(&one);
}

/* The same 20 steps on 1 and 2 threads give the same bits (12 288 tets:
 * the passes use the pool), as do the rig's couplings and the API's. */
static void test_threads_same_bits(void **state)
{
    (void)state;
    pair_rig two = make_pair(0, 0, NULL, 0);
    pose_fem_soft_coupling c[81];
    const size_t n = tie_faces(&two, 100.0f, c);
    pair_rig baked = make_pair(0, 0, c, n);
    pose_fem_soft_coupling back[81];
    assert_int_equal(pose_rig_fem_soft_couplings(baked.rig, back, 81, sizeof back[0]), 81);
    assert_memory_equal(back, c, sizeof c);
    pose_state *st[3] = {new_state(two.rig, POSE_DQS, 1), new_state(two.rig, POSE_DQS, 2),
                         new_state(baked.rig, POSE_DQS, 2)};
    assert_int_equal(pose_fem_soft_coupling_count(st[2]), 81);
    for (int s = 0; s < 3; s++) {
        if (s < 2)
            assert_int_equal(pose_set_fem_soft_couplings(st[s], c, n, sizeof c[0]), POSE_OK);
        set_gravity(st[s]);
        for (int i = 0; i < 20; i++)
            assert_int_equal(pose_step(st[s], 1.0 / 120.0), POSE_OK);
    }
    for (int s = 1; s < 3; s++)
        assert_memory_equal(pose_tet_positions(st[0], NULL), pose_tet_positions(st[s], NULL),
                            3 * two.nv * sizeof(float));
    for (int s = 0; s < 3; s++)
        pose_state_free(st[s]);
    free_pair(&two);
    free_pair(&baked);
}

/* Couplings set on a running simulation join its islands there and then,
 * and removing them splits them again. */
static void test_relink_running(void **state)
{
    (void)state;
    pair_rig two = make_pair(0, 0, NULL, 0);
    pose_fem_soft_coupling c[81];
    const size_t n = tie_faces(&two, 100.0f, c);
    pose_state *st = new_state(two.rig, POSE_DQS, 1);
    set_gravity(st);
    pose_dynamics_stats ds = {.size = sizeof ds};
    for (int i = 0; i < 3; i++)
        assert_int_equal(pose_step(st, 1.0 / 120.0), POSE_OK);
    assert_int_equal(pose_get_dynamics_stats(st, &ds), POSE_OK);
    assert_int_equal(ds.islands, 2);
    assert_int_equal(pose_set_fem_soft_couplings(st, c, n, sizeof c[0]), POSE_OK);
    assert_int_equal(pose_get_dynamics_stats(st, &ds), POSE_OK);
    assert_int_equal(ds.islands, 1);
    assert_int_equal(pose_step(st, 1.0 / 120.0), POSE_OK);
    assert_int_equal(pose_get_dynamics_stats(st, &ds), POSE_OK);
    assert_int_equal(ds.islands, 1);
    assert_int_equal(pose_set_fem_soft_couplings(st, NULL, 0, 0), POSE_OK);
    assert_int_equal(pose_fem_soft_coupling_count(st), 0);
    assert_int_equal(pose_step(st, 1.0 / 120.0), POSE_OK);
    assert_int_equal(pose_get_dynamics_stats(st, &ds), POSE_OK);
    assert_int_equal(ds.islands, 2);
    pose_state_free(st);
    free_pair(&two);
}

/* POSE_FEM under gravity: tied, B's sag matches the single box's within
 * 1 % and the tied nodes stay within 0.01 mm; a node tied to the centre of
 * one of A's tets keeps to that point. */
static void test_quasi_static(void **state)
{
    (void)state;
    pair_rig two = make_pair(0, 0, NULL, 0), one = make_pair(1, 0, NULL, 0);
    pose_fem_soft_coupling c[81];
    size_t n = tie_faces(&two, 100.0f, c);
    pose_state *tied = new_state(two.rig, POSE_FEM, 1), *merged = new_state(one.rig, POSE_FEM, 1);
    assert_int_equal(pose_set_fem_soft_couplings(tied, c, n, sizeof c[0]), POSE_OK);
    set_gravity(tied);
    set_gravity(merged);
    assert_int_equal(pose_apply(tied), POSE_OK);
    assert_int_equal(pose_apply(merged), POSE_OK);
    pose_fem_stats fs = {.size = sizeof fs};
    assert_int_equal(pose_get_fem_stats(tied, &fs), POSE_OK);
    const double hung = far_drop(&two, tied), single = far_drop(&one, merged);
    const double gap = tie_gap(tied, c, n);
    pose_fem_stats ms = {.size = sizeof ms};
    assert_int_equal(pose_get_fem_stats(merged, &ms), POSE_OK);
    printf("quasi-static, gravity: B's far face sags %.2f mm tied, %.2f mm as one box; tied nodes "
           "at most %.4f mm apart; %d CG iterations (one box: %d)\n",
           1e3 * -hung, 1e3 * -single, 1e3 * gap, fs.cg_iterations, ms.cg_iterations);
    assert_true(-single > 1e-3);
    assert_true(fabs(hung - single) < 0.01 * fabs(single)); /* 27.12 mm both */
    assert_true(gap < 1e-5);                                /* 0.0015 mm */
    pose_state_free(tied);
    pose_state_free(merged);
    free_pair(&one);

    /* B shifted by half a cell across: each of its interface nodes inside
     * A's face tied to the centre of the square of A's face it lies on
     * (four weights of 1/4: zero length at rest), the edge ones left free */
    pair_rig sh = make_pair(0, 1, NULL, 0);
    box a = {.nx = NA, .ny = N, .nz = N}, b = {.nx = NB, .ny = N, .nz = N};
    n = 0;
    for (int j = 0; j < N; j++)
        for (int k = 0; k < N; k++)
            c[n++] = (pose_fem_soft_coupling){
                .node = (uint32_t)sh.nv_a + vid(&b, 0, j, k),
                .other = {vid(&a, NA, j, k), vid(&a, NA, j + 1, k), vid(&a, NA, j, k + 1),
                          vid(&a, NA, j + 1, k + 1)},
                .weight = {0.25f, 0.25f, 0.25f, 0.25f},
                .stiffness = 100.0f};
    pose_state *pt = new_state(sh.rig, POSE_FEM, 1);
    set_gravity(pt);
    assert_int_equal(pose_set_fem_soft_couplings(pt, c, n, sizeof c[0]), POSE_OK);
    assert_int_equal(pose_apply(pt), POSE_OK);
    const float *x = pose_tet_positions(pt, NULL);
    double far = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d2 = 0.0;
        for (int e = 0; e < 3; e++) {
            double pnt = 0.0;
            for (int k = 0; k < 4; k++)
                pnt += 0.25 * x[3 * (size_t)c[i].other[k] + (size_t)e];
            d2 += pow(x[3 * (size_t)c[i].node + (size_t)e] - pnt, 2);
        }
        far = fmax(far, sqrt(d2));
    }
    const double shifted = far_drop(&sh, pt);
    printf("quasi-static, B shifted half a cell, %zu nodes tied to the centres of A's face "
           "squares: sags %.2f mm, nodes at most %.4f mm off their points\n",
           n, 1e3 * -shifted, 1e3 * far);
    assert_true(far < 1e-5);
    assert_true(fabs(shifted - single) < 0.2 * fabs(single));
    pose_state_free(pt);
    free_pair(&sh);
    free_pair(&two);
}

static void test_api_errors(void **state)
{
    (void)state;
    pair_rig two = make_pair(0, 0, NULL, 0);
    pose_fem_soft_coupling c[81];
    tie_faces(&two, 10.0f, c);
    pose_state *st = new_state(two.rig, POSE_FEM, 1);
    const size_t sz = sizeof c[0];
    assert_int_equal(pose_set_fem_soft_couplings(NULL, c, 1, sz), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_fem_soft_couplings(st, NULL, 1, sz), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_fem_soft_couplings(st, c, 1, sz - 4), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_fem_soft_couplings(st, c, 2, sz), POSE_OK);
    pose_fem_soft_coupling bad[2] = {c[0], c[1]};
    bad[1].node = (uint32_t)two.nv;
    assert_int_equal(pose_set_fem_soft_couplings(st, bad, 2, sz), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "soft coupling 1: node"));
    assert_int_equal(pose_fem_soft_coupling_count(st), 2); /* unchanged by the refused call */
    bad[1] = c[1];
    bad[1].other[0] = bad[1].node;
    assert_int_equal(pose_set_fem_soft_couplings(st, bad, 2, sz), POSE_ERR_INVALID_ARGUMENT);
    bad[1] = c[1];
    bad[1].weight[0] = 0.5f;
    assert_int_equal(pose_set_fem_soft_couplings(st, bad, 2, sz), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "weights sum"));
    bad[1].weight[1] = 0.5f; /* the same node twice */
    bad[1].other[1] = bad[1].other[0];
    assert_int_equal(pose_set_fem_soft_couplings(st, bad, 2, sz), POSE_ERR_INVALID_ARGUMENT);
    bad[1] = c[1];
    bad[1].weight[2] = NAN;
    assert_int_equal(pose_set_fem_soft_couplings(st, bad, 2, sz), POSE_ERR_INVALID_ARGUMENT);
    bad[1] = c[1];
    bad[1].stiffness = -1.0f;
    assert_int_equal(pose_set_fem_soft_couplings(st, bad, 2, sz), POSE_ERR_INVALID_ARGUMENT);
    bad[1] = c[1];
    bad[1].other[0] = (uint32_t)two.nv + 5;
    assert_int_equal(pose_set_fem_soft_couplings(st, bad, 2, sz), POSE_ERR_INVALID_ARGUMENT);
    /* a node held by A's bone cells (vertex 0) is ignored, the other counts */
    bad[1] = c[1];
    bad[1].other[0] = 0;
    assert_int_equal(pose_set_fem_soft_couplings(st, bad, 2, sz), POSE_OK);
    assert_int_equal(pose_fem_soft_coupling_count(st), 1);
    assert_int_equal(pose_fem_soft_coupling_count(NULL), 0);
    /* a larger element (a later version's) is read by its 0.2 part */
    struct {
        pose_fem_soft_coupling c;
        float later;
    } wide[2] = {{c[0], 1.0f}, {c[1], 2.0f}};
    assert_int_equal(pose_set_fem_soft_couplings(st, &wide[0].c, 2, sizeof wide[0]), POSE_OK);
    assert_int_equal(pose_fem_soft_coupling_count(st), 2);
    assert_int_equal(pose_rig_fem_soft_couplings(two.rig, NULL, 0, sz), 0);
    assert_int_equal(pose_rig_fem_soft_couplings(NULL, NULL, 0, sz), 0);
    pose_state_free(st);
    free_pair(&two);
}

int main(void)
{
    /* TSan's stage runs the threaded test alone (tests/fem/CMakeLists.txt):
     * the others' solves take minutes under it and start no threads */
    const char *only = getenv("POSE_TEST_ONLY");
    if (only)
        cmocka_set_test_filter(only);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_force_is_energy_gradient),
        cmocka_unit_test(test_api_errors),
        cmocka_unit_test(test_dynamics_one_island),
        cmocka_unit_test(test_threads_same_bits),
        cmocka_unit_test(test_relink_running),
        cmocka_unit_test(test_quasi_static),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
