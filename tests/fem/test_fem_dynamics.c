/* SPDX-License-Identifier: Apache-2.0 */
/* Backward Euler dynamics of the co-rotational FEM (fem_dynamics.h,
 * pose_step) on boxes of tets: a free body keeps its momentum; a limb (two
 * bones joined by soft tissue) settles after a step change of its joint,
 * stays stable under a 360 deg/s swing at dt 1/1000 and 1/30 s, gives the
 * same bits on 1 and 2 threads and allocates nothing per step; the API
 * refuses what it cannot do; the solver's work arrays and the rig's
 * simulation mesh are allocated on first use. */
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
#include "fem_dynamics.h"
#include "pose/pose.h"
#include "rt_skin.h"   /* pose__kernels_force_generic, pose__kernels_variant */
#include "rt_thread.h" /* pose__thread_start */

typedef struct dyn_sim {
    sim s;
    pose__fem_dyn dyn;
    void *dyn_mem;
} dyn_sim;

static void make_dyn(dyn_sim *d, const box *b, pose__fem_material m)
{
    make_sim(&d->s, b, m);
    uint32_t *island = malloc(b->nv * sizeof(uint32_t));
    assert_non_null(island);
    size_t ni, ns;
    pose__fem_dyn_islands(&d->s.mesh, island, &ni, &ns);
    assert_int_equal(posix_memalign(&d->dyn_mem, 64, pose__fem_dyn_size(&d->s.mesh, ni, ns)), 0);
    pose__fem_dyn_init(&d->s.mesh, island, ni, ns, d->dyn_mem, &d->dyn);
    free(island);
    pose__fem_dyn_reset(&d->s.mesh, &d->dyn, b->pos);
}

static void free_dyn(dyn_sim *d)
{
    free(d->dyn_mem);
    free_sim(&d->s);
}

/* Linear momentum P = sum m v, angular momentum L = sum m x x v (about the
 * origin) and the centre of mass. */
static void momenta(const dyn_sim *d, double P[3], double L[3], double c[3])
{
    const pose__fem_mesh *m = &d->s.mesh;
    double M = 0.0;
    for (int a = 0; a < 3; a++)
        P[a] = L[a] = c[a] = 0.0;
    for (size_t i = 0; i < m->vertex_count; i++) {
        const double w = m->mass[i];
        const float *x = d->dyn.x + 3 * i, *v = d->dyn.v + 3 * i;
        M += w;
        for (int a = 0; a < 3; a++) {
            P[a] += w * v[a];
            c[a] += w * x[a];
        }
        L[0] += w * ((double)x[1] * v[2] - (double)x[2] * v[1]);
        L[1] += w * ((double)x[2] * v[0] - (double)x[0] * v[2]);
        L[2] += w * ((double)x[0] * v[1] - (double)x[1] * v[0]);
    }
    for (int a = 0; a < 3; a++)
        c[a] /= M;
}

static double norm3(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* A free box (no bone, no gravity, no Rayleigh damping) thrown and spun.
 * Every internal force comes in pairs (each tet's corner forces sum to
 * zero, and so do the rows of K), so backward Euler keeps the linear
 * momentum exactly; what is left is CG's residual and float rounding.
 * Angular momentum: the elastic forces are torque-free (rotation taken by
 * polar decomposition), but backward Euler itself dissipates rotation:
 * x' = x + dt v' moves each point along the chord, not the arc, so the
 * spin loses a little momentum every step (measured: 4.4e-4 of L over
 * 500 steps of 1/500 s at omega = 2 rad/s, always a loss). The test holds
 * P to 1e-5 (measured 3e-7: CG's residual at tolerance 1e-5 and float
 * rounding), the centre of mass to its straight line, L to 2e-3 and to a
 * loss, and checks that the spin did go on (the body turned by omega t). */
static void test_free_body_momentum(void **state)
{
    (void)state;
    box b = make_box(6, 3, 3, 0.05f, 0);
    dyn_sim d;
    make_dyn(&d, &b, (pose__fem_material){1e4f, 0.45f, 1000.0f});
    assert_int_equal(d.dyn.island_count, 1);
    const double w[3] = {0.0, 0.0, 2.0}, v0[3] = {0.1, -0.05, 0.02};
    double P0[3], L0[3], c0[3];
    momenta(&d, P0, L0, c0);
    for (size_t i = 0; i < b.nv; i++) {
        const float *x = d.dyn.x + 3 * i;
        double r[3] = {x[0] - c0[0], x[1] - c0[1], x[2] - c0[2]};
        float *v = d.dyn.v + 3 * i;
        v[0] = (float)(v0[0] + w[1] * r[2] - w[2] * r[1]);
        v[1] = (float)(v0[1] + w[2] * r[0] - w[0] * r[2]);
        v[2] = (float)(v0[2] + w[0] * r[1] - w[1] * r[0]);
    }
    momenta(&d, P0, L0, c0);
    const pose__fem_dyn_params prm = {.dt = 1.0f / 500.0f, .coupling = 100.0f,
                                      .tolerance = 1e-5f, .cg_iterations = 200};
    const int steps = 500;
    float *bones = malloc(3 * b.nv * sizeof(float));
    assert_non_null(bones);
    memcpy(bones, b.pos, 3 * b.nv * sizeof(float)); /* unused: no bone node */
    pose__fem_dyn_stats st;
    int most = 0;
    for (int s = 0; s < steps; s++) {
        pose__fem_dyn_step(&d.s.mesh, &d.s.work, &d.dyn, NULL, &prm, bones, &st);
        if (st.cg_iterations > most)
            most = st.cg_iterations;
    }
    double P[3], L[3], c[3];
    momenta(&d, P, L, c);
    double dP[3] = {P[0] - P0[0], P[1] - P0[1], P[2] - P0[2]};
    /* angular momentum about the centre of mass: L - c x P */
    double Lc0[3] = {L0[0] - (c0[1] * P0[2] - c0[2] * P0[1]), L0[1] - (c0[2] * P0[0] - c0[0] * P0[2]),
                     L0[2] - (c0[0] * P0[1] - c0[1] * P0[0])};
    double Lc[3] = {L[0] - (c[1] * P[2] - c[2] * P[1]), L[1] - (c[2] * P[0] - c[0] * P[2]),
                    L[2] - (c[0] * P[1] - c[1] * P[0])};
    double dL[3] = {Lc[0] - Lc0[0], Lc[1] - Lc0[1], Lc[2] - Lc0[2]};
    const double T = steps * (double)prm.dt;
    double moved[3] = {c[0] - c0[0] - v0[0] * T, c[1] - c0[1] - v0[1] * T, c[2] - c0[2] - v0[2] * T};
    /* the body's turn: the first vertex's direction from the centre */
    const float *x0 = b.pos, *x1 = d.dyn.x;
    double turn = atan2(x1[1] - c[1], x1[0] - c[0]) - atan2(x0[1] - c0[1], x0[0] - c0[0]);
    while (turn < 0.0)
        turn += 2.0 * 3.14159265358979323846;
    printf("free body, %d steps of %.4f s: |dP|/|P| %.2e, centre off its straight line by %.2e m, "
           "|dL|/|L| %.2e (L_z %.4e -> %.4e), turned %.3f rad (omega t = %.3f); CG at most %d, "
           "kinetic %.4e J\n",
           steps, (double)prm.dt, norm3(dP) / norm3(P0), norm3(moved), norm3(dL) / norm3(Lc0),
           Lc0[2], Lc[2], turn, w[2] * T, most, st.kinetic_energy);
    assert_true(norm3(dP) <= 1e-5 * norm3(P0));
    assert_true(norm3(moved) <= 1e-5);
    assert_true(norm3(dL) <= 2e-3 * norm3(Lc0));
    assert_true(Lc[2] < Lc0[2]); /* the dissipation backward Euler has */
    assert_true(fabs(turn - w[2] * T) < 0.02 * w[2] * T);
    free(bones);
    free_dyn(&d);
    free_box(&b);
}

/* ---------------------------------------------------------- the API */

/* A limb along x: bone cells at both ends (joint 0's and joint 1's), soft
 * tissue between. Joint 1 sits at the middle; vertices are skinned fully
 * to the joint on their side. 16 x 8 x 8 cells of 1.5 cm: 6144 tets, above
 * the size where the solver's passes use the worker threads. */
#define LIMB_NX 16
#define LIMB_N 8
#define LIMB_D 0.015f

static size_t g_allocs, g_largest, g_fail_above; /* g_fail_above 0: never fail */
static size_t g_big, g_big_count; /* allocations of at least g_big bytes (0: none counted) */
static pose__mutex g_count_lock;  /* states on two threads allocate at once (main) */
static void *count_alloc(size_t size, size_t align, void *user)
{
    (void)user;
    pose__mutex_lock(&g_count_lock);
    const int fail = g_fail_above && size > g_fail_above;
    if (!fail) {
        g_allocs++;
        g_largest = size > g_largest ? size : g_largest;
        g_big_count += g_big && size >= g_big;
    }
    pose__mutex_unlock(&g_count_lock);
    if (fail)
        return NULL;
    void *p = NULL;
    return posix_memalign(&p, align < sizeof(void *) ? sizeof(void *) : align, size) ? NULL : p;
}
static void count_free(void *p, void *user)
{
    (void)user;
    free(p);
}

static pose_rig *limb_rig_with(box *b, float density, const pose_allocator *allocator)
{
    *b = make_box(LIMB_NX, LIMB_N, LIMB_N, LIMB_D, 2);
    const float mid = 0.5f * LIMB_NX * LIMB_D, c = 0.5f * LIMB_N * LIMB_D;
    for (size_t t = 0; t < b->nt; t++) {
        const float *p0 = b->pos + 3 * (size_t)b->tets[4 * t];
        /* the tet's lowest corner along x tells its cell */
        for (int k = 1; k < 4; k++)
            if (b->pos[3 * (size_t)b->tets[4 * t + (size_t)k]] < p0[0] - 1e-6f)
                p0 = b->pos + 3 * (size_t)b->tets[4 * t + (size_t)k];
        if (p0[0] > (LIMB_NX - 2.5f) * LIMB_D)
            b->labels[t] = 2;
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
    const pose_fem_material fem = {1e4f, 0.45f, density};
    pose_rig_desc d = {.joint_count = 2, .joints = j, .tet_vertex_count = b->nv,
                       .tet_positions = b->pos, .tet_count = b->nt, .tets = b->tets,
                       .tet_labels = b->labels, .influences = 1, .weight_joints = wj,
                       .weights = w, .fem = &fem};
    pose_rig *rig = NULL;
    pose_status st = pose_rig_create(&d, allocator, &rig);
    free(wj);
    free(w);
    if (st != POSE_OK)
        fprintf(stderr, "limb rig: %s\n", pose_last_error());
    return rig;
}

static pose_rig *limb_rig(box *b, float density)
{
    return limb_rig_with(b, density, NULL);
}

static pose_state *limb_state(const pose_rig *rig, int threads)
{
    pose_state_options so = {.size = sizeof so, .threads = threads, .method = POSE_DQS,
                             .allocator = {count_alloc, count_free, NULL}};
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

/* Largest distance of a bone tet's vertex from where skinning puts it
 * (bone nodes hang on springs; the others move with their bone exactly),
 * largest of any vertex, and whether every coordinate is finite. */
static void lag(const pose_state *moved, const pose_state *skin, const box *b, double *bone,
                double *any, int *finite)
{
    const float *p = pose_tet_positions(moved, NULL), *q = pose_tet_positions(skin, NULL);
    for (size_t t = 0; t < b->nt; t++)
        for (int k = 0; k < 4; k++) {
            const size_t i = b->tets[4 * t + (size_t)k];
            const double dx = p[3 * i] - q[3 * i], dy = p[3 * i + 1] - q[3 * i + 1],
                         dz = p[3 * i + 2] - q[3 * i + 2];
            const double l = sqrt(dx * dx + dy * dy + dz * dz);
            if (!isfinite(l))
                *finite = 0;
            *any = fmax(*any, l);
            if (b->labels[t] != 0)
                *bone = fmax(*bone, l);
        }
}

/* The elbow bends by 45 degrees at once and stays: the tissue swings
 * after its bones and comes to rest, kinetic energy below 1e-6 of its peak
 * within 3 s (default damping, dt 1/120 s), at the skinned pose's elastic
 * equilibrium. */
static void test_settle_after_step(void **state)
{
    (void)state;
    box b;
    pose_rig *rig = limb_rig(&b, 1000.0f);
    assert_non_null(rig);
    pose_state *st = limb_state(rig, 1);
    assert_int_equal(pose_reset_dynamics(st), POSE_OK);
    bend(st, 45.0);
    const double dt = 1.0 / 120.0;
    double peak = 0.0, settled = -1.0;
    pose_dynamics_stats ds = {.size = sizeof ds};
    int most = 0;
    for (int s = 0; s < 360 && settled < 0.0; s++) {
        assert_int_equal(pose_step(st, dt), POSE_OK);
        assert_int_equal(pose_get_dynamics_stats(st, &ds), POSE_OK);
        peak = fmax(peak, ds.kinetic_energy);
        if (ds.cg_iterations > most)
            most = ds.cg_iterations;
        if (s > 0 && ds.kinetic_energy < 1e-6 * peak)
            settled = ds.time;
    }
    printf("step of 45 deg: peak kinetic energy %.3e J, below 1e-6 of it after %.3f s; "
           "%d island(s), CG at most %d per step\n",
           peak, settled, ds.islands, most);
    assert_true(peak > 0.0);
    assert_true(settled > 0.0 && settled <= 3.0);
    assert_int_equal(ds.islands, 1);
    pose_state_free(st);
    pose_rig_free(rig);
    free_box(&b);
}

/* The elbow swings 0 -> 90 -> 0 degrees twice at 360 deg/s, then holds:
 * nothing blows up at dt 1/1000 s nor at 1/30 s (each bone node stays
 * within a few millimetres of its bone, the tissue within the limb's size
 * of the skinned pose), and the motion dies out once the bones stop. */
static void swing(double dt)
{
    box b;
    pose_rig *rig = limb_rig(&b, 1000.0f);
    assert_non_null(rig);
    pose_state *st = limb_state(rig, 1), *skin = limb_state(rig, 1);
    const double rate = 360.0, swing_s = 4 * 90.0 / rate, hold_s = 2.0;
    const int steps = (int)lround((swing_s + hold_s) / dt);
    double peak = 0.0, bone = 0.0, any = 0.0, at_stop = 0.0, ke = 0.0;
    int finite = 1, cg = 0;
    pose_dynamics_stats ds = {.size = sizeof ds};
    for (int s = 1; s <= steps; s++) {
        const double t = s * dt, u = fmod(fmin(t, swing_s) * rate, 180.0);
        const double deg = u <= 90.0 ? u : 180.0 - u;
        bend(st, deg);
        bend(skin, deg);
        assert_int_equal(pose_step(st, dt), POSE_OK);
        assert_int_equal(pose_apply(skin), POSE_OK);
        pose_get_dynamics_stats(st, &ds);
        ke = ds.kinetic_energy;
        peak = fmax(peak, ke);
        lag(st, skin, &b, &bone, &any, &finite);
        cg += ds.cg_iterations;
        if (t <= swing_s)
            at_stop = ke;
    }
    printf("swing at dt %.4f s (%d steps, %.1f CG per step): bone vertices within %.2f mm of their "
           "bone, any vertex within %.1f mm of skinning; peak kinetic %.3e J, %.3e J when the bones "
           "stop, %.3e J %.1f s later\n",
           dt, steps, (double)cg / steps, 1e3 * bone, 1e3 * any, peak, at_stop, ke, hold_s);
    assert_true(finite);
    assert_true(bone < 0.005);
    assert_true(any < LIMB_NX * LIMB_D); /* the limb's length: a blow-up goes far past it */
    assert_true(ke < 1e-3 * peak);
    pose_state_free(st);
    pose_state_free(skin);
    pose_rig_free(rig);
    free_box(&b);
}

static void test_swing_dt_1000(void **state)
{
    (void)state;
    swing(1.0 / 1000.0);
}

static void test_swing_dt_30(void **state)
{
    (void)state;
    swing(1.0 / 30.0);
}

/* 1 and 2 threads, and the generic kernels against the AVX2 ones where the
 * CPU has them: the same bits, step after step; no allocation after the
 * first step. */
static void test_threads_and_allocation(void **state)
{
    (void)state;
    box b;
    pose_rig *rig = limb_rig(&b, 1000.0f);
    assert_non_null(rig);
    pose_state *one = limb_state(rig, 1), *two = limb_state(rig, 2), *generic = limb_state(rig, 1);
    pose_dynamics_options o;
    pose_dynamics_defaults(&o);
    o.gravity[2] = -9.81f;
    assert_int_equal(pose_set_dynamics_options(one, &o), POSE_OK);
    assert_int_equal(pose_set_dynamics_options(two, &o), POSE_OK);
    assert_int_equal(pose_set_dynamics_options(generic, &o), POSE_OK);
    const size_t allocs = g_allocs;
    for (int s = 1; s <= 40; s++) {
        bend(one, 2.0 * s);
        bend(two, 2.0 * s);
        bend(generic, 2.0 * s);
        assert_int_equal(pose_step(one, 1.0 / 120.0), POSE_OK);
        assert_int_equal(pose_step(two, 1.0 / 120.0), POSE_OK);
        pose__kernels_force_generic(1);
        assert_int_equal(pose_step(generic, 1.0 / 120.0), POSE_OK);
        pose__kernels_force_generic(0);
        assert_memory_equal(pose_tet_positions(one, NULL), pose_tet_positions(two, NULL),
                            3 * b.nv * sizeof(float));
        assert_memory_equal(pose_tet_positions(one, NULL), pose_tet_positions(generic, NULL),
                            3 * b.nv * sizeof(float));
    }
    assert_int_equal(g_allocs, allocs);
    pose_dynamics_stats a = {.size = sizeof a}, c = {.size = sizeof c};
    pose_get_dynamics_stats(one, &a);
    pose_get_dynamics_stats(two, &c);
    assert_true(a.kinetic_energy == c.kinetic_energy && a.cg_iterations == c.cg_iterations);
    printf("1 and 2 threads, %s and generic kernels: identical over 40 steps (kinetic %.4e J, "
           "CG %d); no allocation\n",
           pose__kernels_variant(), a.kinetic_energy, a.cg_iterations);
    pose_state_free(generic);
    pose_state_free(one);
    pose_state_free(two);
    pose_rig_free(rig);
    free_box(&b);
}

/* What pose_step refuses; reset goes back to the skinned pose at rest. */
static void test_api_errors_and_reset(void **state)
{
    (void)state;
    box b;
    pose_rig *rig = limb_rig(&b, 0.0f);
    assert_non_null(rig);
    pose_state *st = limb_state(rig, 1);
    assert_int_equal(pose_step(st, 0.01), POSE_ERR_UNSUPPORTED);
    assert_non_null(strstr(pose_last_error(), "density"));
    pose_state_free(st);
    pose_rig_free(rig);
    free_box(&b);

    rig = limb_rig(&b, 1000.0f);
    st = limb_state(rig, 1);
    assert_int_equal(pose_step(NULL, 0.01), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_step(st, 0.0), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_step(st, NAN), POSE_ERR_INVALID_ARGUMENT);
    pose_dynamics_options o;
    pose_dynamics_defaults(&o);
    o.tolerance = 0.0f;
    assert_int_equal(pose_set_dynamics_options(st, &o), POSE_ERR_INVALID_ARGUMENT);
    pose_dynamics_defaults(&o);
    o.mass_damping = -1.0f;
    assert_int_equal(pose_set_dynamics_options(st, &o), POSE_ERR_INVALID_ARGUMENT);
    pose_dynamics_defaults(&o);
    o.size = 8;
    assert_int_equal(pose_set_dynamics_options(st, &o), POSE_ERR_INVALID_ARGUMENT);
    pose_dynamics_stats ds = {.size = 8};
    assert_int_equal(pose_get_dynamics_stats(st, &ds), POSE_ERR_INVALID_ARGUMENT);
    bend(st, 30.0);
    for (int s = 0; s < 5; s++)
        assert_int_equal(pose_step(st, 1.0 / 60.0), POSE_OK);
    ds.size = sizeof ds;
    pose_get_dynamics_stats(st, &ds);
    assert_true(ds.kinetic_energy > 0.0 && fabs(ds.time - 5.0 / 60.0) < 1e-12);
    assert_int_equal(pose_reset_dynamics(st), POSE_OK);
    pose_get_dynamics_stats(st, &ds);
    assert_true(ds.kinetic_energy == 0.0 && ds.time == 0.0);
    pose_state *skin = limb_state(rig, 1);
    bend(skin, 30.0);
    pose_apply(skin);
    assert_memory_equal(pose_tet_positions(st, NULL), pose_tet_positions(skin, NULL),
                        3 * b.nv * sizeof(float));
    pose_state_free(skin);
    pose_state_free(st);
    pose_rig_free(rig);
    free_box(&b);

    box small = make_box(3, 2, 2, 0.05f, 1);
    pose_joint_desc j = {.name = "root", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, 0, 0}}};
    uint16_t *wj = calloc(small.nv, sizeof(uint16_t));
    float *w = malloc(small.nv * sizeof(float));
    assert_true(wj && w);
    for (size_t i = 0; i < small.nv; i++)
        w[i] = 1.0f;
    pose_rig_desc d = {.joint_count = 1, .joints = &j, .tet_vertex_count = small.nv,
                       .tet_positions = small.pos, .tet_count = small.nt, .tets = small.tets,
                       .tet_labels = small.labels, .influences = 1, .weight_joints = wj,
                       .weights = w};
    assert_int_equal(pose_rig_create(&d, NULL, &rig), POSE_OK);
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_int_equal(pose_step(st, 0.01), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_reset_dynamics(st), POSE_ERR_UNSUPPORTED);
    pose_state_free(st);
    pose_rig_free(rig);
    free(wj);
    free(w);
    free_box(&small);
}

/* The solver's work arrays (60 floats a tet and more) are allocated when a
 * state first needs them: a state that only skins does not carry them
 * (406 MB on the default bake); pose_set_method(POSE_FEM), a state created
 * with POSE_FEM and the dynamics' first use allocate them, and an
 * allocation that fails leaves the state as it was. */
static void test_fem_work_on_first_use(void **state)
{
    (void)state;
    box b;
    pose_rig *rig = limb_rig(&b, 1000.0f);
    assert_non_null(rig);
    size_t soft = 0; /* the simulation's tets */
    for (size_t t = 0; t < b.nt; t++)
        soft += b.labels[t] == 0;
    const size_t work = 60 * sizeof(float) * soft; /* at least the solver's per-tet arrays */
    g_largest = 0;
    pose_state *st = limb_state(rig, 1);
    assert_true(g_largest < work);
    assert_int_equal(pose_apply(st), POSE_OK);
    assert_true(g_largest < work);

    g_fail_above = work;
    assert_int_equal(pose_set_method(st, POSE_FEM), POSE_ERR_OUT_OF_MEMORY);
    assert_non_null(strstr(pose_last_error(), "pose_set_method"));
    assert_int_equal(pose_get_method(st), POSE_DQS);
    assert_int_equal(pose_step(st, 1.0 / 120.0), POSE_ERR_OUT_OF_MEMORY);
    assert_int_equal(pose_apply(st), POSE_OK);
    pose_state_options so = {.size = sizeof so, .threads = 1, .method = POSE_FEM,
                             .allocator = {count_alloc, count_free, NULL}};
    pose_state *fem = (pose_state *)&so; /* must come back NULL */
    assert_int_equal(pose_state_create_ex(rig, &so, &fem), POSE_ERR_OUT_OF_MEMORY);
    assert_null(fem);
    g_fail_above = 0;

    assert_int_equal(pose_set_method(st, POSE_FEM), POSE_OK);
    assert_true(g_largest >= work);
    const size_t allocs = g_allocs;
    bend(st, 30.0);
    assert_int_equal(pose_apply(st), POSE_OK);
    assert_int_equal(pose_step(st, 1.0 / 120.0), POSE_OK); /* the simulation's own buffers */
    assert_true(g_allocs > allocs);
    const size_t stepped = g_allocs;
    assert_int_equal(pose_step(st, 1.0 / 120.0), POSE_OK);
    assert_int_equal(g_allocs, stepped);
    printf("a skinning state's largest allocation stays under the solver's %zu bytes; POSE_FEM "
           "allocates them, and a failed allocation leaves the state as it was\n", work);
    pose_state_free(st);
    pose_rig_free(rig);
    free_box(&b);
}

/* The rig's simulation mesh (64 bytes a soft tet) is built when a state
 * first needs it, once, whichever threads ask at the same time; a rig that
 * is only skinned never carries it (about 125 MB on the default bake). */
static void *fem_on_thread(void *arg)
{
    pose_state *st = arg;
    return pose_set_method(st, POSE_FEM) == POSE_OK ? st : NULL;
}

static void test_fem_mesh_on_first_use(void **state)
{
    (void)state;
    box b;
    g_largest = 0;
    g_big_count = 0;
    const pose_allocator counting = {count_alloc, count_free, NULL};
    pose_rig *rig = limb_rig_with(&b, 1000.0f, &counting);
    assert_non_null(rig);
    size_t soft = 0;
    for (size_t t = 0; t < b.nt; t++)
        soft += b.labels[t] == 0;
    const size_t mesh = 64 * soft; /* at least its per-tet records */
    assert_true(pose_rig_has_fem(rig));
    assert_true(g_largest < mesh);
    pose_state *a = limb_state(rig, 1), *c = limb_state(rig, 1);
    assert_int_equal(pose_apply(a), POSE_OK);
    assert_true(g_largest < mesh);

    g_fail_above = mesh - 1; /* the rig's allocator too: the mesh cannot be built */
    assert_int_equal(pose_set_method(a, POSE_FEM), POSE_ERR_OUT_OF_MEMORY);
    assert_non_null(strstr(pose_last_error(), "simulation mesh"));
    assert_int_equal(pose_get_method(a), POSE_DQS);
    g_fail_above = 0;

    g_big = mesh;
    pose__thread t1, t2;
    assert_int_equal(pose__thread_start(&t1, fem_on_thread, a), 0);
    assert_int_equal(pose__thread_start(&t2, fem_on_thread, c), 0);
    pose__thread_join(&t1);
    pose__thread_join(&t2);
    g_big = 0;
    assert_int_equal(pose_get_method(a), POSE_FEM);
    assert_int_equal(pose_get_method(c), POSE_FEM);
    bend(a, 30.0);
    bend(c, 30.0);
    assert_int_equal(pose_apply(a), POSE_OK);
    assert_int_equal(pose_apply(c), POSE_OK);
    assert_memory_equal(pose_tet_positions(a, NULL), pose_tet_positions(c, NULL), 3 * b.nv * sizeof(float));
    /* one mesh for the rig, one work block per state */
    printf("%zu allocations of %zu bytes or more for two states set to POSE_FEM at once (the rig's mesh once, "
           "each state's work)\n", g_big_count, mesh);
    assert_int_equal(g_big_count, 3);
    pose_state_free(a);
    pose_state_free(c);
    pose_rig_free(rig);
    free_box(&b);
}

/* "threads" as the argument: only the test the TSan stage runs. */
int main(int argc, char **argv)
{
    const struct CMUnitTest all[] = {
        cmocka_unit_test(test_free_body_momentum),
        cmocka_unit_test(test_settle_after_step),
        cmocka_unit_test(test_swing_dt_1000),
        cmocka_unit_test(test_swing_dt_30),
        cmocka_unit_test(test_threads_and_allocation),
        cmocka_unit_test(test_api_errors_and_reset),
        cmocka_unit_test(test_fem_work_on_first_use),
        cmocka_unit_test(test_fem_mesh_on_first_use),
    };
    const struct CMUnitTest threads[] = {
        cmocka_unit_test(test_threads_and_allocation),
        cmocka_unit_test(test_fem_mesh_on_first_use),
    };
    if (pose__mutex_init(&g_count_lock) != 0)
        return 1;
    if (argc > 1 && !strcmp(argv[1], "threads"))
        return cmocka_run_group_tests(threads, NULL, NULL);
    return cmocka_run_group_tests(all, NULL, NULL);
}
