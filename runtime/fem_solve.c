/* SPDX-License-Identifier: Apache-2.0 */
/* Quasi-static co-rotational FEM solver (fem_solve.h). */
#include "fem_solve.h"

#include <math.h>
#include <string.h>

#include "rt_quat.h"
#include "rt_thread.h"
#include "fem_rot8.h"
#include "rt_vec.h"

static size_t align64(size_t n)
{
    return (n + 63u) & ~(size_t)63u;
}

size_t pose__fem_work_size(const pose__fem_mesh *m)
{
    return align64(20 * m->tet_count * sizeof(float)) + align64(4 * m->tet_count * sizeof(float)) +
           align64(12 * m->tet_count * sizeof(float)) +
           align64(24 * m->tet_count * sizeof(float)) + align64(6 * m->vertex_count * sizeof(float)) +
           5 * align64(3 * m->vertex_count * sizeof(float)) +
           align64(3 * m->surface.vertex_count * sizeof(float)) +
           align64(3 * m->surface.vertex_count * sizeof(double)) +
           align64(4 * m->chunk_count * sizeof(double));
}

void pose__fem_work_reset(const pose__fem_mesh *m, pose__fem_work *w)
{
    for (size_t t = 0; t < m->tet_count; t++) {
        float *q = w->quat + 4 * t;
        q[0] = q[1] = q[2] = 0.0f;
        q[3] = 1.0f;
    }
}

void pose__fem_work_init(const pose__fem_mesh *m, void *memory, pose__fem_work *w)
{
    unsigned char *b = memory;
    memset(b, 0, pose__fem_work_size(m));
    size_t off = 0;
    w->rot = (float *)(b + off);
    off += align64(20 * m->tet_count * sizeof(float));
    w->quat = (float *)(b + off);
    off += align64(4 * m->tet_count * sizeof(float));
    w->corner = (float *)(b + off);
    off += align64(12 * m->tet_count * sizeof(float));
    w->dblk = (float *)(b + off);
    off += align64(24 * m->tet_count * sizeof(float));
    w->pre = (float *)(b + off);
    off += align64(6 * m->vertex_count * sizeof(float));
    float **vec[5] = {&w->r, &w->z, &w->p, &w->ap, &w->gvol};
    for (int i = 0; i < 5; i++) {
        *vec[i] = (float *)(b + off);
        off += align64(3 * m->vertex_count * sizeof(float));
    }
    w->sgrad = (float *)(b + off);
    off += align64(3 * m->surface.vertex_count * sizeof(float));
    w->spos = (double *)(b + off);
    off += align64(3 * m->surface.vertex_count * sizeof(double));
    w->partial = (double *)(b + off);
    pose__fem_work_reset(m, w);
}

/* ------------------------------------------------------------ per tet */

/* Steps of the rotation extraction per tet and pass in the solver. Most
 * tets converge in 3-6 from the last rotation; a block of 8 runs as long as
 * its slowest lane, and a tet that has not converged (a fresh state, a
 * tet sheared hard) goes on from where it stopped at the next outer
 * iteration or frame. pose__fem_forces (tests) runs to convergence. */
#define FEM_POLAR_STEPS 8

/* Rotational part of A (row-major) by Mueller et al. 2016 ("A robust method
 * to extract the rotational part of deformations"): iterate q toward the
 * rotation maximizing tr(R^T A), starting from the last one. Unlike the
 * polar decomposition by SVD or Newton iteration, it always returns a
 * rotation, also for flat and inverted tets, and warm-started it converges
 * in one or two iterations between outer iterations and frames. */
static void extract_rotation(const float A[9], float q[4], float R[9], int steps)
{
    for (int it = 0; it < steps; it++) {
        pose__quat_to_matrix(q, R);
        float om[3] = {0, 0, 0}, d = 0.0f;
        for (int c = 0; c < 3; c++) {
            float r0 = R[c], r1 = R[3 + c], r2 = R[6 + c];
            float a0 = A[c], a1 = A[3 + c], a2 = A[6 + c];
            om[0] += r1 * a2 - r2 * a1;
            om[1] += r2 * a0 - r0 * a2;
            om[2] += r0 * a1 - r1 * a0;
            d += r0 * a0 + r1 * a1 + r2 * a2;
        }
        float s = 1.0f / (fabsf(d) + 1e-9f);
        om[0] *= s;
        om[1] *= s;
        om[2] *= s;
        float w2 = om[0] * om[0] + om[1] * om[1] + om[2] * om[2];
        if (w2 < 1e-12f)
            return;
        /* q <- normalize((1, omega / 2) q): the rotation about omega by
         * 2 atan(|omega| / 2) instead of |omega|; the same fixed point
         * without a sine and cosine per step (a third of the pass). */
        float a[3] = {0.5f * om[0], 0.5f * om[1], 0.5f * om[2]};
        float n[4] = {
            q[0] + a[0] * q[3] + a[1] * q[2] - a[2] * q[1],
            q[1] - a[0] * q[2] + a[1] * q[3] + a[2] * q[0],
            q[2] + a[0] * q[1] - a[1] * q[0] + a[2] * q[3],
            q[3] - a[0] * q[0] - a[1] * q[1] - a[2] * q[2],
        };
        float len = 1.0f / sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] + n[3] * n[3]);
        for (int k = 0; k < 4; k++)
            q[k] = n[k] * len;
    }
    pose__quat_to_matrix(q, R);
}

/* Gradient of the field u over the tet: G = sum_i (u_i - u_0) g_i^T. */
static inline void tet_gradient(const pose__fem_tet *t, const float *u, float G[9])
{
    const float *u0 = u + 3 * (size_t)t->v[0];
    float e[3][3];
    for (int i = 0; i < 3; i++) {
        const float *ui = u + 3 * (size_t)t->v[i + 1];
        e[i][0] = ui[0] - u0[0];
        e[i][1] = ui[1] - u0[1];
        e[i][2] = ui[2] - u0[2];
    }
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            G[3 * r + c] = e[0][r] * t->b[c] + e[1][r] * t->b[3 + c] + e[2][r] * t->b[6 + c];
}

/* Cofactor matrix of F (row-major): dJ/dF for J = det F. */
static inline float cofactor(const float F[9], float C[9])
{
    C[0] = F[4] * F[8] - F[5] * F[7];
    C[1] = F[5] * F[6] - F[3] * F[8];
    C[2] = F[3] * F[7] - F[4] * F[6];
    C[3] = F[2] * F[7] - F[1] * F[8];
    C[4] = F[0] * F[8] - F[2] * F[6];
    C[5] = F[1] * F[6] - F[0] * F[7];
    C[6] = F[1] * F[5] - F[2] * F[4];
    C[7] = F[2] * F[3] - F[0] * F[5];
    C[8] = F[0] * F[4] - F[1] * F[3];
    return F[0] * C[0] + F[1] * C[1] + F[2] * C[2];
}

/* Corner forces. Linear isotropic elasticity split into shear and volume,
 * mu |dev eps|^2 + kappa / 2 tr(eps)^2 (kappa = lambda + 2 mu / 3, the
 * same energy at small strain), with the shear co-rotated,
 * eps = sym(R^T F) - I, and the volume measured by the true J = det F,
 * linearized at the outer iteration's F_k: J ~ J_k + C_k : (F - F_k),
 * C_k = cof F_k. Plain co-rotated linear elasticity keeps tr(S) = 3 (S the
 * stretch), not det S = (1+a)(1+b)(1-a-b) < 1, and its shear term
 * |S - I|^2 is lowered by shrinking a sheared tet: on the baked body at
 * 120-150 degrees of flexion it lost 4 % of the volume (measured), more
 * than skinning. Linearized per outer iteration, like R, the system stays
 * linear, symmetric and positive (Gauss-Newton); at rest (R = C = I) it is
 * exactly linear elasticity.
 *
 * residual: G is the deformation gradient F, the corners get the forces
 * -V P g_i, P = R mu (H + H^T - 2/3 tr H I) + kappa (J - 1) C with
 * H = R^T F - I; otherwise G is the gradient of a displacement and the
 * corners get K p: the same with H = R^T G and (C : G) for (J - 1). */
static inline void tet_corners(const pose__fem_tet *t, const float R[9], const float C[9],
                               float jm1, const float G[9], int residual, float out[12])
{
    float H[9];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            H[3 * r + c] = R[r] * G[c] + R[3 + r] * G[3 + c] + R[6 + r] * G[6 + c];
    float vol;
    if (residual) {
        H[0] -= 1.0f;
        H[4] -= 1.0f;
        H[8] -= 1.0f;
        vol = t->vkappa * jm1;
    } else {
        float cg = 0.0f;
        for (int k = 0; k < 9; k++)
            cg += C[k] * G[k];
        vol = t->vkappa * cg;
    }
    /* deviatoric part only: the trace is the volume term's */
    const float third = (2.0f / 3.0f) * (H[0] + H[4] + H[8]);
    float S[9];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            S[3 * r + c] = t->vmu * (H[3 * r + c] + H[3 * c + r] - (r == c ? third : 0.0f));
    float P[9];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            P[3 * r + c] = R[3 * r] * S[c] + R[3 * r + 1] * S[3 + c] + R[3 * r + 2] * S[6 + c] +
                           vol * C[3 * r + c];
    const float sign = residual ? -1.0f : 1.0f;
    float s0[3] = {0, 0, 0};
    for (int i = 0; i < 3; i++) {
        const float *g = t->b + 3 * i;
        for (int r = 0; r < 3; r++) {
            float f = sign * (P[3 * r] * g[0] + P[3 * r + 1] * g[1] + P[3 * r + 2] * g[2]);
            out[3 * (i + 1) + r] = f;
            s0[r] += f;
        }
    }
    out[0] = -s0[0];
    out[1] = -s0[1];
    out[2] = -s0[2];
}

/* Rotation, cofactor and J - 1 of one tet at x, stored in rot[20]. */
static inline void tet_linearize(const pose__fem_tet *t, const float *x, float *q, float *rot,
                                 float F[9], int steps)
{
    tet_gradient(t, x, F);
    extract_rotation(F, q, rot, steps);
    rot[18] = cofactor(F, rot + 9) - 1.0f;
}

/* ------------------------------------------------------------ passes */

enum { PASS_ROTATE, PASS_GATHER_RESIDUAL, PASS_PRODUCT, PASS_GATHER_PRODUCT, PASS_UPDATE };

typedef struct solve_ctx {
    const pose__fem_mesh *mesh;
    pose__fem_work *w;
    const pose__fem_params *prm;
    float *x;
    int pass;
    float alpha, beta;
    float vol_force;   /**< -kappa_g (V - V0): the volume term's force is vol_force * gvol */
    float vol_product; /**< kappa_g (gvol . p) */
} solve_ctx;

static void rotate_block(const pose__fem_tet *tets, pose__fem_work *w, const float *x, size_t t0);

/* The 3x3 diagonal blocks of K at the tet's corners (symmetric, 6 floats:
 * xx xy xz yy yz zz): moving corner k by d alone gives G = d g^T, whose
 * energy is V mu (|g|^2 |d|^2 + (d . R g)^2 / 3) / 2 (deviatoric) +
 * V kappa (d . C g)^2 / 2, so the block is
 * V mu (|g|^2 I + w w^T / 3) + V kappa c c^T with w = R g, c = C g. Block
 * Jacobi with them follows each tet's rotation and its volume direction,
 * which a rotation-free diagonal cannot: the stiff volume terms of a near
 * incompressible material are what slows CG. */
static void tet_blocks(const pose__fem_tet *t, const float *rot, float *out)
{
    const float *R = rot, *C = rot + 9;
    for (int k = 0; k < 4; k++) {
        float g[3];
        if (k == 0)
            for (int a = 0; a < 3; a++)
                g[a] = -(t->b[a] + t->b[3 + a] + t->b[6 + a]);
        else
            for (int a = 0; a < 3; a++)
                g[a] = t->b[3 * (k - 1) + a];
        float wv[3], cv[3];
        for (int r = 0; r < 3; r++) {
            wv[r] = R[3 * r] * g[0] + R[3 * r + 1] * g[1] + R[3 * r + 2] * g[2];
            cv[r] = C[3 * r] * g[0] + C[3 * r + 1] * g[1] + C[3 * r + 2] * g[2];
        }
        const float gg = t->vmu * (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        const float m3 = t->vmu / 3.0f;
        static const int ij[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
        for (int e = 0; e < 6; e++) {
            int i = ij[e][0], j = ij[e][1];
            out[6 * k + e] = (i == j ? gg : 0.0f) + m3 * wv[i] * wv[j] + t->vkappa * cv[i] * cv[j];
        }
    }
}

/* Tets [b, e) (whole blocks of 8 from b): every tet's rotation, cofactor
 * and J - 1 at x into work->rot, its elastic corner forces into
 * work->corner, its corners' 3x3 stiffness blocks into work->dblk. */
static void tets_rotate(const pose__fem_mesh *m, pose__fem_work *w, const float *x, size_t b,
                        size_t e)
{
    const pose__fem_tet *tets = m->tets;
    size_t t = b;
    for (; t + 8 <= e; t += 8)
        rotate_block(tets, w, x, t);
    for (size_t u = b; u < t; u++)
        tet_blocks(&tets[u], w->rot + 20 * u, w->dblk + 24 * u);
    for (; t < e; t++) {
        const pose__fem_tet *tt = &tets[t];
        float F[9], *rot = w->rot + 20 * t;
        tet_linearize(tt, x, w->quat + 4 * t, rot, F, FEM_POLAR_STEPS);
        tet_corners(tt, rot, rot + 9, rot[18], F, 1, w->corner + 12 * t);
        tet_blocks(tt, rot, w->dblk + 24 * t);
    }
}

/* ---- 8 tets at once (lane l = tet t0 + l). The same operations as the
 * scalar functions above, in the same order (no fused multiply-add: the
 * build does not contract), so a tet gets the same bits in a block as
 * alone, and the result does not depend on where parts split the tets.
 * Per-tet data is gathered from the 64-byte records and the rotation
 * records; the arithmetic runs 8 wide. */

static const size_t k_lanes[8] = {0, 1, 2, 3, 4, 5, 6, 7};

static POSE__INLINE void load_block(const pose__fem_tet *tets, size_t t0, pose__v8f B[9], pose__v8f *vmu,
                       pose__v8f *vkappa, uint32_t idx[4][8])
{
    const float *rec = (const float *)(const void *)(tets + t0);
    const uint32_t *vi = (const uint32_t *)(const void *)(tets + t0);
    for (int k = 0; k < 9; k++)
        B[k] = V8_GATHER(rec, k_lanes, 16, 4 + k);
    *vmu = V8_GATHER(rec, k_lanes, 16, 13);
    *vkappa = V8_GATHER(rec, k_lanes, 16, 14);
    for (int k = 0; k < 4; k++)
        for (int l = 0; l < 8; l++)
            idx[k][l] = vi[16 * l + k];
}

/* tet_corners, 8 wide; vol is kappa V (J - 1) (residual) or kappa V (C : G). */
static POSE__INLINE void corners_block(const pose__v8f B[9], const pose__v8f R[9],
                                       const pose__v8f C[9], const pose__v8f *vmu_p,
                                       const pose__v8f *vol_p, const pose__v8f G[9],
                                       int residual, float *out)
{
    const pose__v8f vmu = *vmu_p, vol = *vol_p;
    pose__v8f H[9];
    for (int r = 0; r < 3; r++)
        for (int col = 0; col < 3; col++)
            H[3 * r + col] = R[r] * G[col] + R[3 + r] * G[3 + col] + R[6 + r] * G[6 + col];
    if (residual) {
        H[0] -= V8_SPLAT(1.0f);
        H[4] -= V8_SPLAT(1.0f);
        H[8] -= V8_SPLAT(1.0f);
    }
    const pose__v8f third = V8_SPLAT(2.0f / 3.0f) * (H[0] + H[4] + H[8]);
    pose__v8f S[9];
    for (int r = 0; r < 3; r++)
        for (int col = 0; col < 3; col++)
            S[3 * r + col] =
                vmu * (H[3 * r + col] + H[3 * col + r] - (r == col ? third : V8_SPLAT(0.0f)));
    pose__v8f P[9];
    for (int r = 0; r < 3; r++)
        for (int col = 0; col < 3; col++)
            P[3 * r + col] = R[3 * r] * S[col] + R[3 * r + 1] * S[3 + col] +
                             R[3 * r + 2] * S[6 + col] + vol * C[3 * r + col];
    const pose__v8f sign = V8_SPLAT(residual ? -1.0f : 1.0f);
    pose__v8f f[4][3];
    for (int a = 0; a < 3; a++)
        f[0][a] = V8_SPLAT(0.0f);
    for (int i = 0; i < 3; i++)
        for (int r = 0; r < 3; r++) {
            f[i + 1][r] = sign * (P[3 * r] * B[3 * i] + P[3 * r + 1] * B[3 * i + 1] +
                                  P[3 * r + 2] * B[3 * i + 2]);
            f[0][r] += f[i + 1][r];
        }
    for (int r = 0; r < 3; r++)
        f[0][r] = -f[0][r];
    for (int l = 0; l < 8; l++)
        for (int k = 0; k < 4; k++)
            for (int a = 0; a < 3; a++)
                out[12 * l + 3 * k + a] = f[k][a][l];
}

static POSE__INLINE void gradient_block(const pose__v8f B[9], const pose__v8f d[4][3], pose__v8f G[9])
{
    for (int r = 0; r < 3; r++)
        for (int col = 0; col < 3; col++)
            G[3 * r + col] = (d[1][r] - d[0][r]) * B[col] + (d[2][r] - d[0][r]) * B[3 + col] +
                             (d[3][r] - d[0][r]) * B[6 + col];
}

static void rotate_block(const pose__fem_tet *tets, pose__fem_work *w, const float *x, size_t t0)
{
    pose__v8f B[9], vmu, vkappa;
    uint32_t idx[4][8];
    load_block(tets, t0, B, &vmu, &vkappa, idx);
    pose__v8f d[4][3];
    for (int k = 0; k < 4; k++)
        for (int a = 0; a < 3; a++)
            d[k][a] = V8_GATHER(x, idx[k], 3, a);
    pose__v8f F[9], q[4], R[9], C[9];
    gradient_block(B, d, F);
    float *qs = w->quat + 4 * t0;
    for (int k = 0; k < 4; k++)
        q[k] = V8_GATHER(qs, k_lanes, 4, k);
    pose__fem_rotation8(F, q, R, FEM_POLAR_STEPS);
    /* cofactor, as the scalar one */
    C[0] = F[4] * F[8] - F[5] * F[7];
    C[1] = F[5] * F[6] - F[3] * F[8];
    C[2] = F[3] * F[7] - F[4] * F[6];
    C[3] = F[2] * F[7] - F[1] * F[8];
    C[4] = F[0] * F[8] - F[2] * F[6];
    C[5] = F[1] * F[6] - F[0] * F[7];
    C[6] = F[1] * F[5] - F[2] * F[4];
    C[7] = F[2] * F[3] - F[0] * F[5];
    C[8] = F[0] * F[4] - F[1] * F[3];
    const pose__v8f jm1 = (F[0] * C[0] + F[1] * C[1] + F[2] * C[2]) - V8_SPLAT(1.0f);
    float *rot = w->rot + 20 * t0;
    for (int l = 0; l < 8; l++) {
        for (int k = 0; k < 4; k++)
            qs[4 * l + k] = q[k][l];
        for (int k = 0; k < 9; k++) {
            rot[20 * l + k] = R[k][l];
            rot[20 * l + 9 + k] = C[k][l];
        }
        rot[20 * l + 18] = jm1[l];
    }
    const pose__v8f vol = vkappa * jm1;
    corners_block(B, R, C, &vmu, &vol, F, 1, w->corner + 12 * t0);
}

/* The product K p: the search direction p' = z + beta p formed per corner. */
static void product_block(const pose__fem_tet *tets, pose__fem_work *w, const float *z,
                          const float *p, const pose__v8f *vb, size_t t0)
{
    pose__v8f B[9], vmu, vkappa;
    uint32_t idx[4][8];
    load_block(tets, t0, B, &vmu, &vkappa, idx);
    pose__v8f d[4][3];
    for (int k = 0; k < 4; k++)
        for (int a = 0; a < 3; a++)
            d[k][a] = V8_GATHER(z, idx[k], 3, a) + *vb * V8_GATHER(p, idx[k], 3, a);
    pose__v8f G[9], R[9], C[9];
    gradient_block(B, d, G);
    const float *rot = w->rot + 20 * t0;
    for (int k = 0; k < 9; k++) {
        R[k] = V8_GATHER(rot, k_lanes, 20, k);
        C[k] = V8_GATHER(rot, k_lanes, 20, 9 + k);
    }
    pose__v8f cg = V8_SPLAT(0.0f);
    for (int k = 0; k < 9; k++)
        cg += C[k] * G[k];
    const pose__v8f vol = vkappa * cg;
    corners_block(B, R, C, &vmu, &vol, G, 0, w->corner + 12 * t0);
}

/* Tets [b, e): corner products K d of the warped stiffness (the last
 * rotate pass's) with d = z + beta p per vertex, into work->corner. The next
 * search direction p' = z + beta p is formed per corner here and stored per
 * vertex by the gather that follows, saving a pass. */
static void tets_product(const pose__fem_mesh *m, pose__fem_work *w, const float *z,
                         const float *p, float beta, size_t b, size_t e)
{
    const pose__fem_tet *tets = m->tets;
    size_t t = b;
    for (; t + 8 <= e; t += 8) {
        const pose__v8f vb = V8_SPLAT(beta);
        product_block(tets, w, z, p, &vb, t);
    }
    for (; t < e; t++) {
        const pose__fem_tet *tt = &tets[t];
        const float bt = beta;
        float d[4][3];
        for (int k = 0; k < 4; k++) {
            size_t v = 3 * (size_t)tt->v[k];
            for (int a = 0; a < 3; a++)
                d[k][a] = z[v + a] + bt * p[v + a];
        }
        float G[9];
        for (int r = 0; r < 3; r++)
            for (int col = 0; col < 3; col++)
                G[3 * r + col] = (d[1][r] - d[0][r]) * tt->b[col] +
                                 (d[2][r] - d[0][r]) * tt->b[3 + col] +
                                 (d[3][r] - d[0][r]) * tt->b[6 + col];
        const float *rot = w->rot + 20 * t;
        tet_corners(tt, rot, rot + 9, 0.0f, G, 0, w->corner + 12 * t);
    }
}

void pose__fem_vertex_block(const pose__fem_mesh *m, const float *dblk, size_t v, double k[6])
{
    for (int e = 0; e < 6; e++)
        k[e] = 0.0;
    for (uint32_t i = m->corner_offset[v]; i < m->corner_offset[v + 1]; i++) {
        const float *b = dblk + 6 * (size_t)m->corners[i];
        for (int e = 0; e < 6; e++)
            k[e] += b[e];
    }
}

int pose__fem_invert_block(const double k[6], float out[6])
{
    const double c00 = k[3] * k[5] - k[4] * k[4], c01 = k[2] * k[4] - k[1] * k[5],
                 c02 = k[1] * k[4] - k[2] * k[3];
    const double det = k[0] * c00 + k[1] * c01 + k[2] * c02;
    if (!(det > 1e-30 * k[0] * k[3] * k[5]))
        return -1;
    const double s = 1.0 / det;
    out[0] = (float)(c00 * s);
    out[1] = (float)(c01 * s);
    out[2] = (float)(c02 * s);
    out[3] = (float)((k[0] * k[5] - k[2] * k[2]) * s);
    out[4] = (float)((k[1] * k[2] - k[0] * k[4]) * s);
    out[5] = (float)((k[0] * k[3] - k[1] * k[1]) * s);
    return 0;
}

/* The inverse of vertex v's diagonal block (symmetric, 6 floats; with its
 * coupling spring ks), or zero for a held vertex. Falls back to the
 * rotation-free diagonal when the block is singular (a vertex of flat tets
 * only). */
static void vertex_preconditioner(const pose__fem_mesh *m, const float *dblk, size_t v, float ks,
                                  float *pre)
{
    double k[6];
    pose__fem_vertex_block(m, dblk, v, k);
    k[0] += ks;
    k[3] += ks;
    k[5] += ks;
    const float id = m->inv_diag[v];
    if (id == 0.0f || pose__fem_invert_block(k, pre) < 0) {
        pre[0] = pre[3] = pre[5] = id;
        pre[1] = pre[2] = pre[4] = 0.0f;
    }
}

static void vertices_pass(solve_ctx *c, size_t chunk)
{
    const pose__fem_mesh *m = c->mesh;
    pose__fem_work *w = c->w;
    size_t b = chunk * POSE__FEM_CHUNK, e = b + POSE__FEM_CHUNK;
    if (e > m->vertex_count)
        e = m->vertex_count;
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;
    const float *spring = c->prm->spring;
    const pose__fem_links *links = c->prm->links;
    for (size_t v = b; v < e; v++) {
        const float id = m->inv_diag[v];
        /* a coupling's zero-length spring (free vertices only) */
        const float ks = spring && id > 0.0f ? spring[v] : 0.0f;
        /* the soft-soft couplings' product at v, formed before the pass
         * (K_l x, then K_l (z + beta p)), and their diagonal */
        const float *lo = links && id > 0.0f ? links->out + 3 * v : NULL;
        float *r = w->r + 3 * v, *z = w->z + 3 * v, *p = w->p + 3 * v, *ap = w->ap + 3 * v;
        const float *gv = w->gvol + 3 * v;
        if (c->pass == PASS_GATHER_RESIDUAL) {
            float f[3];
            pose__fem_gather(m, w->corner, v, f);
            float *pre = w->pre + 6 * v;
            vertex_preconditioner(m, w->dblk, v, lo ? ks + links->diag[v] : ks, pre);
            const float *xt = ks > 0.0f ? c->prm->target + 3 * v : NULL, *xv = c->x + 3 * v;
            for (int a = 0; a < 3; a++) {
                r[a] = id > 0.0f ? f[a] + m->mass[v] * c->prm->gravity[a] + c->vol_force * gv[a]
                                 : 0.0f;
                if (xt)
                    r[a] += ks * (xt[a] - xv[a]);
                if (lo)
                    r[a] -= lo[a];
                p[a] = 0.0f;
            }
            pose__fem_apply_block(pre, r, z);
            for (int a = 0; a < 3; a++) {
                s0 += (double)r[a] * z[a];
                s1 += (double)r[a] * r[a];
            }
        } else if (c->pass == PASS_GATHER_PRODUCT) {
            float f[3];
            pose__fem_gather(m, w->corner, v, f);
            for (int a = 0; a < 3; a++) {
                p[a] = z[a] + c->beta * p[a];
                ap[a] = id > 0.0f ? f[a] + ks * p[a] : 0.0f;
                if (lo)
                    ap[a] += lo[a];
                s0 += (double)p[a] * ap[a];
                s2 += (double)p[a] * gv[a];
            }
        } else { /* PASS_UPDATE */
            float *x = c->x + 3 * v;
            if (id > 0.0f)
                for (int a = 0; a < 3; a++)
                    x[a] += c->alpha * p[a];
            for (int a = 0; a < 3; a++) {
                /* the volume term's rank-one product: kappa_g (g . p) g */
                float apv = id > 0.0f ? ap[a] + c->vol_product * gv[a] : 0.0f;
                r[a] -= c->alpha * apv;
            }
            pose__fem_apply_block(w->pre + 6 * v, r, z);
            for (int a = 0; a < 3; a++) {
                s0 += (double)r[a] * z[a];
                s1 += (double)r[a] * r[a];
            }
        }
    }
    w->partial[4 * chunk] = s0;
    w->partial[4 * chunk + 1] = s1;
    w->partial[4 * chunk + 2] = s2;
}

static void pass_task(void *ctx, unsigned part, unsigned parts)
{
    solve_ctx *c = ctx;
    const pose__fem_mesh *m = c->mesh;
    if (c->pass == PASS_ROTATE || c->pass == PASS_PRODUCT) {
        size_t b, e; /* whole blocks of 8 tets per part (the product runs 8 wide) */
        pose__part_range8(m->tet_count, part, parts, &b, &e);
        if (c->pass == PASS_ROTATE)
            tets_rotate(m, c->w, c->x, b, e);
        else
            tets_product(m, c->w, c->w->z, c->w->p, c->beta, b, e);
        return;
    }
    size_t b = pose__part_begin(m->chunk_count, part, parts);
    size_t e = pose__part_begin(m->chunk_count, part + 1, parts);
    for (size_t k = b; k < e; k++)
        vertices_pass(c, k);
}

/* Below this many tets the caller works alone (a wake-up costs more). */
#define FEM_SERIAL_TETS 4096u

static void run(solve_ctx *c, pose__pool *pool, int pass, double *s0, double *s1, double *s2)
{
    c->pass = pass;
    if (pool && pose__pool_threads(pool) > 1 && c->mesh->tet_count >= FEM_SERIAL_TETS)
        pose__pool_run(pool, pass_task, c);
    else
        pass_task(c, 0, 1);
    if (!s0)
        return;
    double a = 0.0, b = 0.0, g = 0.0; /* chunk after chunk: same sums for any thread count */
    for (size_t k = 0; k < c->mesh->chunk_count; k++) {
        a += c->w->partial[4 * k];
        b += c->w->partial[4 * k + 1];
        g += c->w->partial[4 * k + 2];
    }
    *s0 = a;
    if (s1)
        *s1 = b;
    if (s2)
        *s2 = g;
}

/* The enclosed volume's gradient with respect to the tet vertices, into
 * w->gvol (serial: a few thousand surface vertices, and the scatter to tet
 * vertices must sum in one order); returns the volume term's force factor
 * -kappa_g (V - V0). */
double pose__fem_volume_gradient(const pose__fem_mesh *m, pose__fem_work *w, const float *x)
{
    const pose__fem_surface *s = &m->surface;
    memset(w->gvol, 0, 3 * m->vertex_count * sizeof(float));
    if (s->vertex_count == 0)
        return 0.0;
    memset(w->sgrad, 0, 3 * s->vertex_count * sizeof(float));
    /* each surface vertex placed once, not once per triangle it is in */
    for (size_t i = 0; i < s->vertex_count; i++) {
        const uint32_t *t = s->tets + 4 * (size_t)s->tet[i];
        const float *b = s->bary + 4 * i;
        for (int a = 0; a < 3; a++)
            w->spos[3 * i + a] =
                (double)b[0] * x[3 * (size_t)t[0] + a] + (double)b[1] * x[3 * (size_t)t[1] + a] +
                (double)b[2] * x[3 * (size_t)t[2] + a] + (double)b[3] * x[3 * (size_t)t[3] + a];
    }
    double vol = 0.0;
    for (size_t f = 0; f < s->triangle_count; f++) {
        const uint32_t *tri = s->triangles + 3 * f;
        const double *p[3] = {w->spos + 3 * (size_t)tri[0], w->spos + 3 * (size_t)tri[1],
                              w->spos + 3 * (size_t)tri[2]};
        for (int k = 0; k < 3; k++) {
            const double *u = p[(k + 1) % 3], *v = p[(k + 2) % 3];
            double g[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                           u[0] * v[1] - u[1] * v[0]};
            float *o = w->sgrad + 3 * (size_t)tri[k];
            for (int a = 0; a < 3; a++) /* a product, not a division: a third of the pass */
                o[a] += (float)(g[a] * (1.0 / 6.0));
            if (k == 0)
                vol += p[0][0] * g[0] + p[0][1] * g[1] + p[0][2] * g[2];
        }
    }
    vol /= 6.0;
    for (size_t v = 0; v < s->vertex_count; v++) {
        const uint32_t *t = s->tets + 4 * (size_t)s->tet[v];
        const float *b = s->bary + 4 * v, *g = w->sgrad + 3 * v;
        for (int k = 0; k < 4; k++)
            for (int a = 0; a < 3; a++)
                w->gvol[3 * (size_t)t[k] + a] += b[k] * g[a];
    }
    return -s->stiffness * (vol - s->rest_volume);
}

static double now(void)
{
    return 1e-9 * (double)pose__now_ns();
}

void pose__fem_solve(const pose__fem_mesh *m, pose__fem_work *w, pose__pool *pool,
                     const pose__fem_params *prm, float *x, pose__fem_stats *stats)
{
    pose__fem_stats st = {0};
    solve_ctx c = {.mesh = m, .w = w, .prm = prm, .x = x};
    double first = -1.0, rr = 0.0;
    for (int outer = 0; outer < prm->outer_iterations && m->tet_count > 0; outer++) {
        double t0 = now();
        run(&c, pool, PASS_ROTATE, NULL, NULL, NULL);
        c.vol_force = (float)pose__fem_volume_gradient(m, w, x);
        if (prm->links) /* their force -K_l x (fem_links.h: one thread) */
            pose__fem_links_product(prm->links, x, NULL, 0.0f, prm->links->out);
        double rz = 0.0;
        run(&c, pool, PASS_GATHER_RESIDUAL, &rz, &rr, NULL);
        double t1 = now();
        st.seconds_rotations += t1 - t0;
        st.outer_iterations++;
        if (first < 0.0)
            first = rr;
        const double stop = (double)prm->tolerance * prm->tolerance * first;
        if (rr <= stop || rz <= 0.0)
            break;
        c.beta = 0.0f;
        int it = 0;
        for (; it < prm->cg_iterations; it++) {
            double pap = 0.0, pg = 0.0;
            run(&c, pool, PASS_PRODUCT, NULL, NULL, NULL);
            if (prm->links) /* K_l p' with p' = z + beta p, as the tets form it */
                pose__fem_links_product(prm->links, w->z, w->p, c.beta, prm->links->out);
            run(&c, pool, PASS_GATHER_PRODUCT, &pap, NULL, &pg);
            c.vol_product = (float)(m->surface.stiffness * pg);
            pap += m->surface.stiffness * pg * pg;
            if (!(pap > 0.0))
                break;
            c.alpha = (float)(rz / pap);
            double rz_new = 0.0;
            run(&c, pool, PASS_UPDATE, &rz_new, &rr, NULL);
            c.beta = (float)(rz_new / rz);
            rz = rz_new;
            /* Each outer iteration only needs the warped system solved to
             * the tolerance of the whole refinement, relative to the first
             * residual: later rotations change the system anyway. */
            if (rr <= stop || rz <= 0.0) {
                it++;
                break;
            }
        }
        st.cg_iterations += it;
        st.seconds_cg += now() - t1;
    }
    st.residual = first > 0.0 ? sqrt(rr / first) : 0.0;
    if (stats)
        *stats = st;
}

void pose__fem_forces(const pose__fem_mesh *m, pose__fem_work *w, const float *x, float *forces)
{
    for (size_t t = 0; t < m->tet_count; t++) {
        float F[9], *rot = w->rot + 20 * t;
        tet_linearize(&m->tets[t], x, w->quat + 4 * t, rot, F, 64);
        tet_corners(&m->tets[t], rot, rot + 9, rot[18], F, 1, w->corner + 12 * t);
    }
    for (size_t v = 0; v < m->vertex_count; v++)
        pose__fem_gather(m, w->corner, v, forces + 3 * v);
}
