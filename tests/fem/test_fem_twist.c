/* SPDX-License-Identifier: Apache-2.0 */
/* The rotation's derivative in the dynamics' stiffness (fem_dyn_twist.h) on
 * one tet, stretched and flattened, upright and inverted (stretched in
 * volume, so every twist stiffens and the projection leaves the Hessian
 * whole): the product R K0 R^T u plus the twists' equals the central
 * difference of the co-rotated forces along u, and its u^T K u is u . K u;
 * R K0 R^T alone is off by far more; the corners' diagonal blocks are the
 * product's; generic and AVX2 kernels give the same bits. A skeletal tet
 * takes its joints' blended rotation and needs no twist. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "fem_dyn_tets.h"
#include "fem_dyn_twist.h"
#include "rt_skin.h" /* pose__kernels_force_generic */

#define L POSE__FEM_LANES
/* Extraction steps: from the exact rotation, enough to follow a small
 * perturbation to its own. */
#define STEPS 64

/* One block: the tet in lane 0 (rest corners 0, e_x, e_y, e_z: b = I), the
 * other lanes padding; mu 1, lambda 50 (Poisson's ratio 0.49): both
 * deformations below are flagged. */
static void one_tet(pose__fem_dyn_tets *t)
{
    memset(t, 0, sizeof *t);
    for (int k = 0; k < 4; k++)
        t->v[k][0] = (uint32_t)k;
    for (int i = 0; i < 3; i++)
        t->b[4 * i][0] = 1.0f;
    t->vmu[0] = 1.0f / 6.0f;
    t->vlambda[0] = 50.0f / 6.0f;
}

/* Rotation about unit axis n by angle a, row-major. */
static void rotation(const double n[3], double a, double R[9])
{
    const double c = cos(a), s = sin(a), C = 1.0 - c;
    const double M[9] = {
        c + n[0] * n[0] * C,        n[0] * n[1] * C - n[2] * s, n[0] * n[2] * C + n[1] * s,
        n[1] * n[0] * C + n[2] * s, c + n[1] * n[1] * C,        n[1] * n[2] * C - n[0] * s,
        n[2] * n[0] * C - n[1] * s, n[2] * n[1] * C + n[0] * s, c + n[2] * n[2] * C};
    memcpy(R, M, sizeof M);
}

/* Corners x (4 x 3, with the gathers' slack) of F = A diag(sigma) B^T,
 * and rot set to the extraction's answer A B^T (quaternion of A B^T). */
static void deform(const double sigma[3], float x[20], pose__fem_dyn_rot *rot)
{
    static const double na[3] = {0.48, 0.6, 0.64}, nb[3] = {0.0, 0.6, -0.8};
    double A[9], B[9], F[9], Q[9];
    rotation(na, 0.7, A);
    rotation(nb, -1.1, B);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            F[3 * r + c] = Q[3 * r + c] = 0.0;
            for (int k = 0; k < 3; k++) {
                F[3 * r + c] += A[3 * r + k] * sigma[k] * B[3 * c + k];
                Q[3 * r + c] += A[3 * r + k] * B[3 * c + k];
            }
        }
    memset(x, 0, 20 * sizeof(float));
    for (int k = 1; k < 4; k++) /* corner k = F e_k, corner 0 at the origin */
        for (int a = 0; a < 3; a++)
            x[3 * k + a] = (float)F[3 * a + k - 1];
    /* Q's quaternion (Q turns by 1.19 rad: w is far from 0) */
    const double w = 0.5 * sqrt(1.0 + Q[0] + Q[4] + Q[8]);
    const double q[4] = {(Q[7] - Q[5]) / (4 * w), (Q[2] - Q[6]) / (4 * w),
                         (Q[3] - Q[1]) / (4 * w), w};
    memset(rot, 0, sizeof *rot);
    for (int i = 0; i < 4; i++)
        for (unsigned l = 0; l < L; l++)
            rot->q[i][l] = l == 0 ? (float)q[i] : (i == 3 ? 1.0f : 0.0f);
}

/* Corner forces (12 rows) at x; rot starts from *start. */
static void forces(const pose__fem_dyn_tets *t, const pose__fem_dyn_rot *start, const float *x,
                   float *f)
{
    _Alignas(64) pose__fem_dyn_rot rot = *start;
    _Alignas(64) float kv[12 * L], blk[24 * L], v[20] = {0};
    _Alignas(64) uint32_t flag[L];
    pose__fem_dyn_rotate(t, &rot, x, NULL, v, STEPS, POSE__FEM_TWIST, f, kv, blk, flag, 0, 1);
}

typedef struct product {
    float out[12 * L], plain[12 * L], blk[24 * L], energy[L];
    size_t flagged;
} product;

/* At x: K u with the twists (out) and without (plain), the corners' blocks
 * and u^T K u. */
static void stiffness(const pose__fem_dyn_tets *t, pose__fem_dyn_rot *rot, const float *x,
                      const float *u, product *p)
{
    _Alignas(64) float f[12 * L], kv[12 * L], v[20] = {0};
    _Alignas(64) uint32_t flag[L];
    pose__fem_twist list[L];
    pose__fem_dyn_rotate(t, rot, x, NULL, v, STEPS, POSE__FEM_TWIST, f, kv, p->blk, flag, 0, 1);
    p->flagged = pose__fem_dyn_twist_build(t, rot, flag, x, v, kv, p->blk, 0, 1, list);
    pose__fem_dyn_product(t, rot, u, p->plain, p->energy, 0, 1);
    memcpy(p->out, p->plain, sizeof p->out);
    pose__fem_dyn_twist_product(t, rot, list, p->flagged, u, p->out, p->energy);
}

static double rel_error(const float *a, const double *b)
{
    double e = 0.0, n = 0.0;
    for (int i = 0; i < 12; i++) {
        e += (a[i * L] - b[i]) * (a[i * L] - b[i]);
        n += b[i] * b[i];
    }
    return sqrt(e / n);
}

/* The central difference's step. */
#define EPS 1e-3f

/* A direction u over the 4 corners and x moved by +-EPS along it. */
static void perturb(const float x[20], float u[20], float xp[20], float xm[20])
{
    static const float dir[12] = {0.3f, -0.7f, 0.2f, 0.9f, 0.1f, -0.4f,
                                  -0.5f, 0.6f, 0.8f, -0.2f, -0.9f, 0.35f};
    memset(u, 0, 20 * sizeof(float));
    memcpy(u, dir, sizeof dir);
    for (int i = 0; i < 20; i++) {
        xp[i] = x[i] + EPS * u[i];
        xm[i] = x[i] - EPS * u[i];
    }
}

static void check(const double sigma[3], const char *what)
{
    _Alignas(64) pose__fem_dyn_tets t;
    _Alignas(64) pose__fem_dyn_rot start, rot;
    _Alignas(64) float x[20], xp[20], xm[20], fp[12 * L], fm[12 * L], u[20] = {0};
    _Alignas(64) product p;
    one_tet(&t);
    deform(sigma, x, &start);
    perturb(x, u, xp, xm);
    forces(&t, &start, xp, fp);
    forces(&t, &start, xm, fm);
    double fd[12]; /* K u = -df/dx u */
    for (int i = 0; i < 12; i++)
        fd[i] = -((double)fp[i * L] - fm[i * L]) / (2.0 * EPS);
    rot = start;
    stiffness(&t, &rot, x, u, &p);
    const double err = rel_error(p.out, fd), err_plain = rel_error(p.plain, fd);
    double uku = 0.0;
    for (int i = 0; i < 12; i++)
        uku += (double)u[i] * p.out[i * L];
    printf("%s, sigma %g %g %g: K u against the forces' difference %.2g (R K0 R^T alone %.2g); "
           "u^T K u %.6g, u . K u %.6g\n",
           what, sigma[0], sigma[1], sigma[2], err, err_plain, (double)p.energy[0], uku);
    assert_int_equal(p.flagged, 1);
    assert_true(err < 1e-2);
    assert_true(err_plain > 30.0 * err);
    assert_true(fabs(p.energy[0] - uku) <= 1e-4 * fabs(uku));

    /* the corners' diagonal blocks: K e_(c,a) at corner c */
    for (int c = 0; c < 4; c++)
        for (int a = 0; a < 3; a++) {
            _Alignas(64) float e[20] = {0};
            _Alignas(64) product q;
            e[3 * c + a] = 1.0f;
            rot = start;
            stiffness(&t, &rot, x, e, &q);
            static const int idx[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
            for (int r = 0; r < 3; r++) {
                const float k = q.out[(3 * c + r) * L], b = q.blk[(6 * c + idx[r][a]) * L];
                assert_true(fabsf(k - b) <= 1e-4f * (fabsf(k) + 1.0f));
            }
        }

    /* generic kernels: the same bits */
    _Alignas(64) product g;
    pose__kernels_force_generic(1);
    rot = start;
    stiffness(&t, &rot, x, u, &g);
    pose__kernels_force_generic(0);
    assert_memory_equal(g.out, p.out, sizeof p.out);
    assert_memory_equal(g.blk, p.blk, sizeof p.blk);
}

static void test_stretched_flat(void **state)
{
    (void)state;
    static const double sigma[3] = {3.0, 0.5, 0.1};
    check(sigma, "upright");
}

static void test_stretched_inverted(void **state)
{
    (void)state;
    static const double sigma[3] = {3.0, 0.5, -0.1};
    check(sigma, "inverted");
}

/* A skeletal tet (pose__fem_dyn_set_skeletal): two joints turned by 0.4
 * and 0.8 rad about one axis, weighed equally, give it the rotation by
 * 0.6 rad, whatever its corners do. Turned rigidly by it, no force; at the
 * stretched, inverted deformation of the test above, not flagged, and its
 * R K0 R^T u is the forces' central difference (the energy is quadratic
 * in x: nothing is left out); generic and AVX2 the same bits. */
static void test_skeletal(void **state)
{
    (void)state;
    static const double n[3] = {0.48, 0.6, 0.64};
    _Alignas(64) float joint_q[2 * POSE__FEM_JOINT_STRIDE] = {0};
    for (int j = 0; j < 2; j++) {
        const double h = 0.5 * (0.4 + 0.4 * j);
        for (int a = 0; a < 3; a++)
            joint_q[j * POSE__FEM_JOINT_STRIDE + a] = (float)(sin(h) * n[a]);
        joint_q[j * POSE__FEM_JOINT_STRIDE + 3] = (float)cos(h);
    }
    static const uint32_t joints[2] = {0, 1};
    static const float weights[2] = {0.5f, 0.5f};
    _Alignas(64) pose__fem_dyn_tets t;
    _Alignas(64) pose__fem_dyn_rot rot;
    one_tet(&t);
    pose__fem_dyn_set_skeletal(&t, 0, 2, joints, weights);
    double R[9];
    rotation(n, 0.6, R);

    /* turned rigidly by R: no force, and R is the tet's rotation */
    _Alignas(64) float x[20] = {0}, f[12 * L], kv[12 * L], blk[24 * L], v[20] = {0};
    _Alignas(64) uint32_t flag[L];
    for (int k = 1; k < 4; k++)
        for (int a = 0; a < 3; a++)
            x[3 * k + a] = (float)R[3 * a + k - 1];
    pose__fem_dyn_rot_reset(&(pose__fem_mesh){.tet_count = 1}, &rot);
    pose__fem_dyn_rotate(&t, &rot, x, joint_q, v, STEPS, POSE__FEM_TWIST, f, kv, blk, flag, 0, 1);
    for (int i = 0; i < 9; i++)
        assert_true(fabs(rot.r[i][0] - R[i]) < 1e-6);
    for (int i = 0; i < 12; i++)
        assert_true(fabsf(f[i * L]) < 1e-5f);

    /* stretched and inverted: the plain product is the exact stiffness */
    static const double sigma[3] = {3.0, 0.5, -0.1};
    _Alignas(64) pose__fem_dyn_rot start;
    _Alignas(64) float xp[20], xm[20], fp[12 * L], fm[12 * L], out[12 * L], en[L], u[20] = {0};
    deform(sigma, x, &start);
    perturb(x, u, xp, xm);
    rot = start;
    pose__fem_dyn_rotate(&t, &rot, xp, joint_q, v, STEPS, POSE__FEM_TWIST, fp, kv, blk, flag, 0, 1);
    rot = start;
    pose__fem_dyn_rotate(&t, &rot, xm, joint_q, v, STEPS, POSE__FEM_TWIST, fm, kv, blk, flag, 0, 1);
    rot = start;
    pose__fem_dyn_rotate(&t, &rot, x, joint_q, v, STEPS, POSE__FEM_TWIST, f, kv, blk, flag, 0, 1);
    assert_int_equal(flag[0], 0);
    pose__fem_dyn_product(&t, &rot, u, out, en, 0, 1);
    double fd[12];
    for (int i = 0; i < 12; i++)
        fd[i] = -((double)fp[i * L] - fm[i * L]) / (2.0 * EPS);
    const double err = rel_error(out, fd);
    printf("skeletal, sigma %g %g %g: R K0 R^T u against the forces' difference %.2g\n", sigma[0],
           sigma[1], sigma[2], err);
    assert_true(err < 1e-3);

    /* generic kernels: the same bits */
    _Alignas(64) float fg[12 * L];
    _Alignas(64) pose__fem_dyn_rot rg = start;
    pose__kernels_force_generic(1);
    pose__fem_dyn_rotate(&t, &rg, x, joint_q, v, STEPS, POSE__FEM_TWIST, fg, kv, blk, flag, 0, 1);
    pose__kernels_force_generic(0);
    assert_memory_equal(fg, f, sizeof f);
    assert_memory_equal(&rg, &rot, sizeof rot);
}

int main(void)
{
    const struct CMUnitTest all[] = {
        cmocka_unit_test(test_stretched_flat),
        cmocka_unit_test(test_stretched_inverted),
        cmocka_unit_test(test_skeletal),
    };
    return cmocka_run_group_tests(all, NULL, NULL);
}
