/* SPDX-License-Identifier: Apache-2.0 */
/* The dynamics' tet passes (fem_dyn_tets.h), 8 tets per vector, written once
 * and compiled once per variant: the including file defines POSE__KV(name)
 * to give the functions their variant suffix. No fused multiply-add (the
 * build does not contract), so every variant gives the same bits. */
#ifndef POSE__KV
#  error "define POSE__KV before including fem_dyn_tets_body.h"
#endif

#include "fem_dyn_tets.h"
#include "fem_rot8.h"
#include "rt_vec.h"

#define LOAD8(p) (*(const pose__v8f *)(const void *)(p))
#define STORE8(p, x) (*(pose__v8f *)(void *)(p) = (x))

/* The gradient over the block's tets of the field whose corner values are
 * u[k][a]: G = sum_i (u_i - u_0) g_i^T (row-major). */
static POSE__INLINE void grad8(const pose__fem_dyn_tets *t, pose__v8f u[4][3], pose__v8f G[9])
{
    for (int i = 1; i < 4; i++)
        for (int a = 0; a < 3; a++)
            u[i][a] -= u[0][a];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            G[3 * r + c] = u[1][r] * LOAD8(t->b[c]) + u[2][r] * LOAD8(t->b[3 + c]) +
                           u[3][r] * LOAD8(t->b[6 + c]);
}

/* H = R^T G */
static POSE__INLINE void unrotate8(const pose__v8f R[9], const pose__v8f G[9], pose__v8f H[9])
{
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            H[3 * r + c] = R[r] * G[c] + R[3 + r] * G[3 + c] + R[6 + r] * G[6 + c];
}

/* Corner values of P = R S, S = vmu (H + H^T) + vlambda tr(H) I (linear
 * isotropic stress of the unrotated gradient H, times the rest volume):
 * corner i > 0 gets P g_i, corner 0 minus their sum; negated when neg (the
 * forces -V P g_i). Stored as 12 rows at out. */
static POSE__INLINE void corners8(const pose__fem_dyn_tets *t, const pose__v8f R[9],
                                  const pose__v8f H[9], int neg, float *out, pose__v8f *energy)
{
    const pose__v8f vmu = LOAD8(t->vmu), lt = LOAD8(t->vlambda) * (H[0] + H[4] + H[8]);
    pose__v8f S[9];
    S[0] = vmu * (H[0] + H[0]) + lt;
    S[4] = vmu * (H[4] + H[4]) + lt;
    S[8] = vmu * (H[8] + H[8]) + lt;
    S[1] = S[3] = vmu * (H[1] + H[3]);
    S[2] = S[6] = vmu * (H[2] + H[6]);
    S[5] = S[7] = vmu * (H[5] + H[7]);
    pose__v8f P[9];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            P[3 * r + c] = R[3 * r] * S[c] + R[3 * r + 1] * S[3 + c] + R[3 * r + 2] * S[6 + c];
    if (energy) /* u^T K u = P : G = S : H (H = R^T G; S symmetric) */
        *energy = S[0] * H[0] + S[4] * H[4] + S[8] * H[8] + S[1] * (H[1] + H[3]) +
                  S[2] * (H[2] + H[6]) + S[5] * (H[5] + H[7]);
    pose__v8f s0[3] = {V8_SPLAT(0.0f), V8_SPLAT(0.0f), V8_SPLAT(0.0f)};
    for (int i = 0; i < 3; i++) {
        const pose__v8f g0 = LOAD8(t->b[3 * i]), g1 = LOAD8(t->b[3 * i + 1]),
                        g2 = LOAD8(t->b[3 * i + 2]);
        for (int r = 0; r < 3; r++) {
            pose__v8f f = P[3 * r] * g0 + P[3 * r + 1] * g1 + P[3 * r + 2] * g2;
            if (neg)
                f = -f;
            STORE8(out + (3 * (i + 1) + r) * POSE__FEM_LANES, f);
            s0[r] += f;
        }
    }
    for (int r = 0; r < 3; r++)
        STORE8(out + r * POSE__FEM_LANES, -s0[r]);
}

/* The corners' diagonal blocks of K = R K0 R^T: moving corner k by d alone
 * gives G = d g^T, so the block is vmu (|g|^2 I + w w^T) + vlambda w w^T
 * with w = R g. Block Jacobi with them follows each tet's rotation, which a
 * rotation-free diagonal cannot (the stiff volume terms of a near
 * incompressible material are what slows CG). 24 rows at out. */
static POSE__INLINE void blocks8(const pose__fem_dyn_tets *t, const pose__v8f R[9], float *out)
{
    const pose__v8f vmu = LOAD8(t->vmu), ww = vmu + LOAD8(t->vlambda);
    for (int k = 0; k < 4; k++) {
        pose__v8f g[3];
        for (int a = 0; a < 3; a++)
            g[a] = k == 0 ? -(LOAD8(t->b[a]) + LOAD8(t->b[3 + a]) + LOAD8(t->b[6 + a]))
                          : LOAD8(t->b[3 * (k - 1) + a]);
        pose__v8f w[3];
        for (int r = 0; r < 3; r++)
            w[r] = R[3 * r] * g[0] + R[3 * r + 1] * g[1] + R[3 * r + 2] * g[2];
        const pose__v8f gg = vmu * (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        float *o = out + 6 * k * POSE__FEM_LANES;
        STORE8(o, gg + ww * (w[0] * w[0]));
        STORE8(o + 1 * POSE__FEM_LANES, ww * (w[0] * w[1]));
        STORE8(o + 2 * POSE__FEM_LANES, ww * (w[0] * w[2]));
        STORE8(o + 3 * POSE__FEM_LANES, gg + ww * (w[1] * w[1]));
        STORE8(o + 4 * POSE__FEM_LANES, ww * (w[1] * w[2]));
        STORE8(o + 5 * POSE__FEM_LANES, gg + ww * (w[2] * w[2]));
    }
}

/* Which tets need the rotation's derivative (fem_dyn_twist.h): with S =
 * R^T F (= H + I here) and s_k = tr S - sigma_k the stiffness of the twist
 * about S's axis k is 2 vmu + c / s_k, c = 2 vlambda (tr S - 3) - 4 vmu, of
 * which R K0 R^T holds none. Flagged (all bits set) when c > 0 and c / h >
 * twist 2 vmu with h = det M / e2(M) (M = tr S I - sym S, whose
 * eigenvalues are the s_k; s_min / 3 <= h <= s_min when they are
 * positive), so every tet whose twist stiffness exceeds (1 + twist) 2 vmu
 * is flagged; and when det M <= 0 (R short of the maximum of tr(R^T F),
 * which fem_dyn_twist.c restarts the extraction at). Padding lanes (zero
 * moduli) never are. */
static POSE__INLINE void twist8(const pose__fem_dyn_tets *t, const pose__v8f H[9], float twist,
                                uint32_t *flag)
{
    const pose__v8f half = V8_SPLAT(0.5f), one = V8_SPLAT(1.0f);
    const pose__v8f s0 = H[0] + one, s1 = H[4] + one, s2 = H[8] + one, tr = s0 + s1 + s2;
    const pose__v8f a = half * (H[1] + H[3]), b = half * (H[2] + H[6]), c = half * (H[5] + H[7]);
    const pose__v8f m0 = s1 + s2, m1 = s0 + s2, m2 = s0 + s1;
    /* M's off-diagonals are -a, -b, -c: their signs cancel in e2 and det's
     * last term is -2abc */
    const pose__v8f e2 = m0 * m1 + m0 * m2 + m1 * m2 - (a * a + b * b + c * c);
    const pose__v8f det =
        m0 * (m1 * m2 - c * c) - a * a * m2 - b * b * m1 - V8_SPLAT(2.0f) * a * b * c;
    const pose__v8f vmu = LOAD8(t->vmu);
    const pose__v8f cc =
        V8_SPLAT(2.0f) * LOAD8(t->vlambda) * (tr - V8_SPLAT(3.0f)) - V8_SPLAT(4.0f) * vmu;
    const pose__v8i f = ((pose__v8i)(cc > V8_SPLAT(0.0f)) &
                         (pose__v8i)(cc * e2 > V8_SPLAT(2.0f * twist) * vmu * det)) |
                        ((pose__v8i)(det <= V8_SPLAT(0.0f)) & (pose__v8i)(vmu > V8_SPLAT(0.0f)));
    *(pose__v8i *)(void *)flag = f;
}

/* The block's corner values of a per-vertex field (3 floats per vertex). */
static POSE__INLINE void gather8(const pose__fem_dyn_tets *t, const float *u, pose__v8f out[4][3])
{
#ifdef __AVX2__
    for (int k = 0; k < 4; k++) {
        const __m256i i = _mm256_loadu_si256((const __m256i *)(const void *)t->v[k]);
        const __m256i i3 = _mm256_add_epi32(_mm256_add_epi32(i, i), i);
        for (int a = 0; a < 3; a++)
            out[k][a] = (pose__v8f)_mm256_i32gather_ps(u + a, i3, 4);
    }
#else
    for (int k = 0; k < 4; k++)
        for (int a = 0; a < 3; a++)
            out[k][a] = V8_GATHER(u, t->v[k], 3, a);
#endif
}

/* A skeletal lane's quaternion: its joints' rotations blended by weight,
 * each turned into the first one's hemisphere, normalized. */
static POSE__INLINE void skeletal8(const pose__fem_dyn_tets *t, const float *joint_q, pose__v8f q[4])
{
    pose__v8f first[4];
    for (int c = 0; c < 4; c++)
        q[c] = first[c] = V8_GATHER(joint_q, t->joint[0], POSE__FEM_JOINT_STRIDE, c);
    for (int c = 0; c < 4; c++)
        q[c] *= LOAD8(t->weight[0]);
    for (int i = 1; i < 4; i++) {
        pose__v8f p[4];
        for (int c = 0; c < 4; c++)
            p[c] = V8_GATHER(joint_q, t->joint[i], POSE__FEM_JOINT_STRIDE, c);
        const pose__v8f dot = p[0] * first[0] + p[1] * first[1] + p[2] * first[2] + p[3] * first[3];
        const pose__v8f w = V8_NEG_WHERE(LOAD8(t->weight[i]), dot);
        for (int c = 0; c < 4; c++)
            q[c] += w * p[c];
    }
    const pose__v8f len =
        V8_SPLAT(1.0f) / V8_SQRT(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int c = 0; c < 4; c++)
        q[c] *= len;
}

void POSE__KV(pose__fem_dyn_rotate)(const pose__fem_dyn_tets *tets, pose__fem_dyn_rot *rot,
                                    const float *x, const float *joint_q, const float *v,
                                    int steps, float twist, float *f, float *kv, float *blk,
                                    uint32_t *flag, size_t b, size_t e)
{
    const size_t rows = 12 * POSE__FEM_LANES;
    for (size_t k = b; k < e; k++) {
        const pose__fem_dyn_tets *t = tets + k;
        pose__fem_dyn_rot *ro = rot + k;
        pose__v8f u[4][3], F[9], q[4], R[9], H[9];
        gather8(t, x, u);
        grad8(t, u, F);
        for (int i = 0; i < 4; i++)
            q[i] = LOAD8(ro->q[i]);
        /* skeletal lanes: the joints' blend; the others extract theirs
         * (a block of skeletal tets only extracts nothing) */
        const pose__v8i skel = *(const pose__v8i *)(const void *)t->skeletal;
        if (V8_ANY(skel)) {
            pose__v8f qs[4], Rs[9];
            skeletal8(t, joint_q, qs);
            pose__fem_quat_to_mat8(qs, Rs);
            if (V8_ANY(~skel))
                pose__fem_rotation8(F, q, R, steps);
            else
                for (int i = 0; i < 9; i++)
                    R[i] = Rs[i];
            for (int i = 0; i < 4; i++)
                q[i] = (pose__v8f)(((pose__v8i)qs[i] & skel) | ((pose__v8i)q[i] & ~skel));
            for (int i = 0; i < 9; i++)
                R[i] = (pose__v8f)(((pose__v8i)Rs[i] & skel) | ((pose__v8i)R[i] & ~skel));
        } else {
            pose__fem_rotation8(F, q, R, steps);
        }
        for (int i = 0; i < 4; i++)
            STORE8(ro->q[i], q[i]);
        for (int i = 0; i < 9; i++)
            STORE8(ro->r[i], R[i]);
        /* forces at x: H = R^T F - I */
        unrotate8(R, F, H);
        H[0] -= V8_SPLAT(1.0f);
        H[4] -= V8_SPLAT(1.0f);
        H[8] -= V8_SPLAT(1.0f);
        corners8(t, R, H, 1, f + k * rows, NULL);
        twist8(t, H, twist, flag + k * POSE__FEM_LANES);
        *(pose__v8i *)(void *)(flag + k * POSE__FEM_LANES) &= ~skel; /* R does not depend on x */
        /* K v with the new rotations: the warm start's product */
        gather8(t, v, u);
        grad8(t, u, F);
        unrotate8(R, F, H);
        corners8(t, R, H, 0, kv + k * rows, NULL);
        blocks8(t, R, blk + 2 * k * rows);
    }
}

void POSE__KV(pose__fem_dyn_product)(const pose__fem_dyn_tets *tets, const pose__fem_dyn_rot *rot,
                                     const float *u, float *out, float *energy, size_t b, size_t e)
{
    for (size_t k = b; k < e; k++) {
        const pose__fem_dyn_tets *t = tets + k;
        const pose__fem_dyn_rot *ro = rot + k;
        pose__v8f c[4][3], G[9], R[9], H[9], en;
        gather8(t, u, c);
        grad8(t, c, G);
        for (int i = 0; i < 9; i++)
            R[i] = LOAD8(ro->r[i]);
        unrotate8(R, G, H);
        corners8(t, R, H, 0, out + k * 12 * POSE__FEM_LANES, &en);
        STORE8(energy + k * POSE__FEM_LANES, en);
    }
}
