/* SPDX-License-Identifier: Apache-2.0 */
/* Couplings (pose.h pose_fem_coupling): soft nodes tied to a bone's rigid
 * motion by zero-length springs, in POSE_FEM and pose_step, on a limb of
 * tets: bone cells at both ends (joint 0's and joint 1's, the elbow at the
 * middle), soft tissue between, joint 1's bone surface as a bone tissue.
 * Bent at the elbow, a layer of coupled nodes stays on its bone's rigid
 * motion while the uncoupled tissue beside it slides. */
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

#define NX 16
#define NY 8
#define D 0.015f
#define LAYER 9 /* the coupled layer of nodes: x = 9 D, beyond the elbow (8 D) */

typedef struct limb {
    box b;
    pose_rig *rig;
} limb;

/* Corners and triangles of the box [x0, x1] x [0, NY D]^2 (outward). */
static void box_surface(float x0, float x1, float pos[24], uint32_t tri[36])
{
    const float h = NY * D;
    for (int c = 0; c < 8; c++) {
        pos[3 * c] = c & 1 ? x1 : x0;
        pos[3 * c + 1] = c & 2 ? h : 0.0f;
        pos[3 * c + 2] = c & 4 ? h : 0.0f;
    }
    static const uint32_t t[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                   2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    memcpy(tri, t, sizeof t);
}

/* The limb; with `couplings` stored in the rig (its couplings section). */
static limb make_limb(const pose_fem_coupling *couplings, size_t count)
{
    limb l;
    l.b = make_box(NX, NY, NY, D, 2);
    box *b = &l.b;
    const float mid = 0.5f * NX * D, c = 0.5f * NY * D;
    uint32_t bone_tet = 0;
    for (size_t t = 0; t < b->nt; t++) {
        const float *p0 = b->pos + 3 * (size_t)b->tets[4 * t];
        for (int k = 1; k < 4; k++) /* the tet's lowest corner along x tells its cell */
            if (b->pos[3 * (size_t)b->tets[4 * t + (size_t)k]] < p0[0] - 1e-6f)
                p0 = b->pos + 3 * (size_t)b->tets[4 * t + (size_t)k];
        if (p0[0] > (NX - 2.5f) * D) {
            b->labels[t] = 2;
            bone_tet = (uint32_t)t;
        }
    }
    uint16_t *wj = calloc(b->nv, sizeof(uint16_t));
    float *w = malloc(b->nv * sizeof(float));
    assert_true(wj && w);
    for (size_t i = 0; i < b->nv; i++) {
        wj[i] = b->pos[3 * i] >= mid - 1e-6f;
        w[i] = 1.0f;
    }
    pose_joint_desc j[2] = {
        {.name = "root", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, c, c}}},
        {.name = "elbow", .parent = 0, .rest_model = {{0, 0, 0, 1}, {mid, c, c}}},
    };
    /* joint 1's bone: the surface of the last two cells (its rigid tets) */
    float bpos[24], bbary[32] = {0};
    uint32_t btri[36], btet[8];
    box_surface((NX - 2) * D, NX * D, bpos, btri);
    for (int k = 0; k < 8; k++) {
        btet[k] = bone_tet; /* placed by its joint: the embedding is not used */
        bbary[4 * k] = 1.0f;
    }
    const pose_tissue_desc tissue = {.name = "bone_1", .kind = POSE_TISSUE_BONE, .joint = 1,
                                     .vertex_count = 8, .positions = bpos, .triangle_count = 12,
                                     .triangles = btri, .tet = btet, .bary = bbary};
    const pose_fem_material fem = {1e4f, 0.45f, 1000.0f};
    pose_rig_desc d = {.joint_count = 2, .joints = j, .tet_vertex_count = b->nv,
                       .tet_positions = b->pos, .tet_count = b->nt, .tets = b->tets,
                       .tet_labels = b->labels, .influences = 1, .weight_joints = wj,
                       .weights = w, .tissue_count = 1, .tissues = &tissue, .fem = &fem,
                       .fem_coupling_count = count, .fem_couplings = couplings};
    l.rig = NULL;
    if (pose_rig_create(&d, NULL, &l.rig) != POSE_OK)
        fail_msg("limb rig: %s", pose_last_error());
    free(wj);
    free(w);
    return l;
}

static void free_limb(limb *l)
{
    pose_rig_free(l->rig);
    free_box(&l->b);
}

/* Every node of layer i, coupled to joint 1 at its rest position. */
static size_t layer_couplings(const box *b, int i, float stiffness, pose_fem_coupling *out)
{
    size_t n = 0;
    for (int j = 0; j <= b->ny; j++)
        for (int k = 0; k <= b->nz; k++) {
            const uint32_t v = vid(b, i, j, k);
            out[n] = (pose_fem_coupling){.node = v, .joint = 1, .stiffness = stiffness};
            memcpy(out[n].anchor, b->pos + 3 * (size_t)v, sizeof out[n].anchor);
            n++;
        }
    return n;
}

static pose_state *new_state(const pose_rig *rig, pose_method method)
{
    pose_state_options so = {.size = sizeof so, .threads = 1, .method = method};
    pose_state *st = NULL;
    assert_int_equal(pose_state_create_ex(rig, &so, &st), POSE_OK);
    return st;
}

static void bend(pose_state *st, double deg)
{
    const double h = deg * 3.14159265358979323846 / 360.0;
    const float q[4] = {0.0f, (float)sin(h), 0.0f, (float)cos(h)}; /* about y */
    assert_true(pose_set_joint(st, 1, q) >= 0);
}

/* Largest distance between two states' tet vertices of layer i. */
static double layer_gap(const box *b, int i, const pose_state *a, const pose_state *c)
{
    const float *p = pose_tet_positions(a, NULL), *q = pose_tet_positions(c, NULL);
    double worst = 0.0;
    for (int j = 0; j <= b->ny; j++)
        for (int k = 0; k <= b->nz; k++) {
            const size_t v = vid(b, i, j, k);
            const double dx = p[3 * v] - q[3 * v], dy = p[3 * v + 1] - q[3 * v + 1],
                         dz = p[3 * v + 2] - q[3 * v + 2];
            worst = fmax(worst, sqrt(dx * dx + dy * dy + dz * dz));
        }
    return worst;
}

/* The nodes near joint 1's bone: the free layers within reach of its
 * surface (x = 14 D): 13 and 12 at 3.2 cm; 13 alone at 2 cm; none at 1 cm
 * (layer 14 is the bone tets' own, held). */
static void test_nodes_near_joint(void **state)
{
    (void)state;
    limb l = make_limb(NULL, 0);
    uint32_t nodes[400];
    size_t n = 0;
    assert_int_equal(pose_rig_fem_nodes_near_joint(l.rig, 1, 0.032f, nodes, 400, &n), POSE_OK);
    assert_int_equal(n, 2 * 9 * 9);
    for (size_t i = 0; i < n; i++) {
        const float x = l.b.pos[3 * (size_t)nodes[i]];
        assert_true(fabsf(x - 12 * D) < 1e-6f || fabsf(x - 13 * D) < 1e-6f);
        assert_true(i == 0 || nodes[i] > nodes[i - 1]);
    }
    assert_int_equal(pose_rig_fem_nodes_near_joint(l.rig, 1, 0.02f, NULL, 0, &n), POSE_OK);
    assert_int_equal(n, 81);
    assert_int_equal(pose_rig_fem_nodes_near_joint(l.rig, 1, 0.01f, nodes, 400, &n), POSE_OK);
    assert_int_equal(n, 0);
    assert_int_equal(pose_rig_fem_nodes_near_joint(l.rig, 0, 0.1f, nodes, 400, &n),
                     POSE_ERR_UNSUPPORTED); /* joint 0 has no bone tissue */
    assert_int_equal(pose_rig_fem_nodes_near_joint(l.rig, 2, 0.1f, nodes, 400, &n),
                     POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_rig_fem_nodes_near_joint(l.rig, 1, -1.0f, nodes, 400, &n),
                     POSE_ERR_INVALID_ARGUMENT);
    free_limb(&l);
}

/* POSE_FEM at a 90-degree bend: the layer beyond the elbow (skinned
 * rigidly with joint 1: DQS with one weight) relaxes toward the kink by
 * centimetres when free and stays on its bone's rigid motion when coupled;
 * the next layer, uncoupled, still slides. The rig's couplings and the
 * same ones set through the API give the same bits. */
static void test_quasi_static(void **state)
{
    (void)state;
    limb l = make_limb(NULL, 0);
    pose_fem_coupling c[81];
    const size_t n = layer_couplings(&l.b, LAYER, 100.0f, c);
    pose_state *rigid = new_state(l.rig, POSE_DQS), *free_st = new_state(l.rig, POSE_FEM),
               *tied = new_state(l.rig, POSE_FEM);
    assert_int_equal(pose_fem_coupling_count(tied), 0);
    assert_int_equal(pose_set_fem_couplings(tied, c, n, sizeof c[0]), POSE_OK);
    assert_int_equal(pose_fem_coupling_count(tied), 81);
    pose_state *all[3] = {rigid, free_st, tied};
    for (int s = 0; s < 3; s++) {
        bend(all[s], 90.0);
        assert_int_equal(pose_apply(all[s]), POSE_OK);
    }
    const double slid = layer_gap(&l.b, LAYER, free_st, rigid);
    const double held = layer_gap(&l.b, LAYER, tied, rigid);
    const double next_free = layer_gap(&l.b, LAYER - 2, free_st, rigid);
    const double next_tied = layer_gap(&l.b, LAYER - 2, tied, rigid);
    printf("quasi-static, 90 deg: layer %d off its bone's rigid motion: free %.3f mm, coupled "
           "%.3f mm; layer %d (uncoupled) %.3f / %.3f mm\n",
           LAYER, 1e3 * slid, 1e3 * held, LAYER - 2, 1e3 * next_free, 1e3 * next_tied);
    assert_true(slid > 0.01);        /* the free tissue slides by centimetres (25.5 mm) */
    assert_true(held < 0.01 * slid); /* the coupled layer does not (0.06 mm) */
    assert_true(next_tied > 0.2 * next_free);

    /* the same couplings from the rig's section */
    limb baked = make_limb(c, n);
    pose_fem_coupling back[81];
    assert_int_equal(pose_rig_fem_couplings(baked.rig, back, 81), 81);
    assert_memory_equal(back, c, sizeof c);
    pose_state *from_rig = new_state(baked.rig, POSE_FEM);
    assert_int_equal(pose_fem_coupling_count(from_rig), 81);
    bend(from_rig, 90.0);
    assert_int_equal(pose_apply(from_rig), POSE_OK);
    assert_memory_equal(pose_tet_positions(from_rig, NULL), pose_tet_positions(tied, NULL),
                        3 * l.b.nv * sizeof(float));
    /* and none: the layer slides again (not the same bits: the rotations
     * start from the coupled pose's) */
    assert_int_equal(pose_set_fem_couplings(from_rig, NULL, 0, 0), POSE_OK);
    assert_int_equal(pose_fem_coupling_count(from_rig), 0);
    assert_int_equal(pose_apply(from_rig), POSE_OK);
    assert_true(fabs(layer_gap(&l.b, LAYER, from_rig, rigid) - slid) < 0.1 * slid);
    pose_state_free(from_rig);
    free_limb(&baked);
    for (int s = 0; s < 3; s++)
        pose_state_free(all[s]);
    free_limb(&l);
}

/* pose_step: the elbow ramps 0 -> 90 degrees in 0.25 s (120 Hz) and holds
 * 0.5 s; the free layer trails its bone by centimetres, the coupled one
 * stays within a small part of that at every step. */
static void test_dynamics(void **state)
{
    (void)state;
    limb l = make_limb(NULL, 0);
    pose_fem_coupling c[81];
    const size_t n = layer_couplings(&l.b, LAYER, 100.0f, c);
    pose_state *rigid = new_state(l.rig, POSE_DQS), *free_st = new_state(l.rig, POSE_DQS),
               *tied = new_state(l.rig, POSE_DQS);
    assert_int_equal(pose_set_fem_couplings(tied, c, n, sizeof c[0]), POSE_OK);
    assert_int_equal(pose_reset_dynamics(free_st), POSE_OK);
    assert_int_equal(pose_reset_dynamics(tied), POSE_OK);
    double slid = 0.0, held = 0.0, next_free = 0.0, next_tied = 0.0;
    for (int s = 1; s <= 90; s++) {
        const double deg = s < 30 ? 3.0 * s : 90.0;
        bend(rigid, deg);
        bend(free_st, deg);
        bend(tied, deg);
        assert_int_equal(pose_apply(rigid), POSE_OK);
        assert_int_equal(pose_step(free_st, 1.0 / 120.0), POSE_OK);
        assert_int_equal(pose_step(tied, 1.0 / 120.0), POSE_OK);
        slid = fmax(slid, layer_gap(&l.b, LAYER, free_st, rigid));
        held = fmax(held, layer_gap(&l.b, LAYER, tied, rigid));
        next_free = fmax(next_free, layer_gap(&l.b, LAYER - 2, free_st, rigid));
        next_tied = fmax(next_tied, layer_gap(&l.b, LAYER - 2, tied, rigid));
    }
    printf("dynamics, 0-90 deg in 0.25 s, held 0.5 s: layer %d off its bone's rigid motion at "
           "most: free %.3f mm, coupled %.3f mm; layer %d (uncoupled) %.3f / %.3f mm\n",
           LAYER, 1e3 * slid, 1e3 * held, LAYER - 2, 1e3 * next_free, 1e3 * next_tied);
    assert_true(slid > 0.01);        /* 69.7 mm */
    assert_true(held < 0.01 * slid); /* 0.062 mm */
    assert_true(next_tied > 0.2 * next_free);
    pose_state_free(rigid);
    pose_state_free(free_st);
    pose_state_free(tied);
    free_limb(&l);
}

static void test_api_errors(void **state)
{
    (void)state;
    limb l = make_limb(NULL, 0);
    pose_state *st = new_state(l.rig, POSE_FEM);
    pose_fem_coupling ok[2] = {{.node = vid(&l.b, 5, 1, 1), .joint = 0, .stiffness = 10.0f},
                               {.node = vid(&l.b, 0, 0, 0), .joint = 0, .stiffness = 10.0f}};
    assert_int_equal(pose_set_fem_couplings(NULL, ok, 1, sizeof ok[0]), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_fem_couplings(st, NULL, 1, sizeof ok[0]), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_fem_couplings(st, ok, 1, sizeof ok[0] - 4), POSE_ERR_INVALID_ARGUMENT);
    pose_fem_coupling bad = ok[0];
    bad.node = (uint32_t)l.b.nv;
    assert_int_equal(pose_set_fem_couplings(st, &bad, 1, sizeof bad), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "is not a tet vertex"));
    bad = ok[0];
    bad.joint = 2;
    assert_int_equal(pose_set_fem_couplings(st, &bad, 1, sizeof bad), POSE_ERR_INVALID_ARGUMENT);
    bad = ok[0];
    bad.stiffness = 0.0f;
    assert_int_equal(pose_set_fem_couplings(st, &bad, 1, sizeof bad), POSE_ERR_INVALID_ARGUMENT);
    bad = ok[0];
    bad.anchor[1] = NAN;
    assert_int_equal(pose_set_fem_couplings(st, &bad, 1, sizeof bad), POSE_ERR_INVALID_ARGUMENT);
    pose_fem_coupling twice[2] = {ok[0], ok[0]};
    assert_int_equal(pose_set_fem_couplings(st, twice, 2, sizeof twice[0]), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "listed twice"));
    /* a node held by a bone tet (vertex 0) is ignored; the other counts */
    assert_int_equal(pose_set_fem_couplings(st, ok, 2, sizeof ok[0]), POSE_OK);
    assert_int_equal(pose_fem_coupling_count(st), 1);
    assert_int_equal(pose_fem_coupling_count(NULL), 0);
    pose_state_free(st);
    free_limb(&l);

    /* without a fem section */
    pose_joint_desc j = {.name = "root", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, 0, 0}}};
    box b = make_box(1, 1, 1, 1.0f, 0);
    uint16_t wj[8] = {0};
    float w[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    pose_rig_desc d = {.joint_count = 1, .joints = &j, .tet_vertex_count = b.nv,
                       .tet_positions = b.pos, .tet_count = b.nt, .tets = b.tets,
                       .tet_labels = b.labels, .influences = 1, .weight_joints = wj, .weights = w};
    pose_rig *rig = NULL;
    assert_int_equal(pose_rig_create(&d, NULL, &rig), POSE_OK);
    st = new_state(rig, POSE_DQS);
    assert_int_equal(pose_set_fem_couplings(st, ok, 1, sizeof ok[0]), POSE_ERR_UNSUPPORTED);
    size_t n = 0;
    assert_int_equal(pose_rig_fem_nodes_near_joint(rig, 0, 0.1f, NULL, 0, &n), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_rig_fem_couplings(rig, NULL, 0), 0);
    pose_state_free(st);
    pose_rig_free(rig);
    free_box(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nodes_near_joint),
        cmocka_unit_test(test_quasi_static),
        cmocka_unit_test(test_dynamics),
        cmocka_unit_test(test_api_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
