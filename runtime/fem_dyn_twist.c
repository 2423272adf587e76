/* SPDX-License-Identifier: Apache-2.0 */
/* The rotation's derivative for the flagged tets (fem_dyn_twist.h). */
#include "fem_dyn_twist.h"

#include <math.h>

/* Smallest s_k the twist stiffness is taken at: a tet flattened further
 * (or whose R is short of the maximum, s_k <= 0) gets the stiffness of
 * s_k = 0.01, about 100 lambda at a doubled volume, instead of infinity. */
#define TWIST_S_FLOOR 1e-2

/* Jacobi sweeps of the 3x3 eigensolver; it converges quadratically and
 * stops once the off-diagonal vanishes against the diagonal. */
#define JACOBI_SWEEPS 12

/* Eigenvalues w and eigenvectors (the columns of n) of symmetric a (cyclic
 * Jacobi: a fixed order of rotations, so fixed bits). */
static void eigen3(double a[3][3], double w[3], double n[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            n[i][j] = i == j ? 1.0 : 0.0;
    for (int sweep = 0; sweep < JACOBI_SWEEPS; sweep++) {
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        const double dia = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if (!(off > 1e-30 * dia))
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (a[p][q] == 0.0)
                    continue;
                const double th = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t = (th >= 0.0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
                const double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; k++) {
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) {
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                    const double nkp = n[k][p], nkq = n[k][q];
                    n[k][p] = c * nkp - s * nkq;
                    n[k][q] = s * nkp + c * nkq;
                }
            }
    }
    for (int k = 0; k < 3; k++)
        w[k] = a[k][k];
}

/* Tet t's rotation (row-major) and shape gradients g[k] of its 4 corners. */
static void tet_frame(const pose__fem_dyn_tets *tets, const pose__fem_dyn_rot *rot, size_t t,
                      double R[9], double g[4][3])
{
    const pose__fem_dyn_tets *bt = tets + t / POSE__FEM_LANES;
    const size_t l = t % POSE__FEM_LANES;
    for (int i = 0; i < 9; i++)
        R[i] = rot[t / POSE__FEM_LANES].r[i][l];
    for (int a = 0; a < 3; a++) {
        g[0][a] = 0.0;
        for (int k = 1; k < 4; k++) {
            g[k][a] = bt->b[3 * (k - 1) + a][l];
            g[0][a] -= g[k][a];
        }
    }
}

/* H = R^T grad u for tet t, u a per-vertex field. */
static void tet_unrotated_gradient(const pose__fem_dyn_tets *tets, size_t t, const double R[9],
                                   const double g[4][3], const float *u, double H[9])
{
    const pose__fem_dyn_tets *bt = tets + t / POSE__FEM_LANES;
    const size_t l = t % POSE__FEM_LANES;
    double G[9] = {0};
    for (int k = 0; k < 4; k++) {
        const float *uk = u + 3 * (size_t)bt->v[k][l];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                G[3 * r + c] += (double)uk[r] * g[k][c];
    }
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            H[3 * r + c] = R[r] * G[c] + R[3 + r] * G[3 + c] + R[6 + r] * G[6 + c];
}

/* K u of tet t into its corners of out (added); returns u^T K u. */
static double tet_product(const pose__fem_dyn_tets *tets, const pose__fem_dyn_rot *rot, size_t t,
                          const float k[6], const float *u, float *out)
{
    double R[9], g[4][3], H[9];
    tet_frame(tets, rot, t, R, g);
    tet_unrotated_gradient(tets, t, R, g, u, H);
    /* w: axial vector of skew(H); z = K w */
    const double w[3] = {0.5 * (H[7] - H[5]), 0.5 * (H[2] - H[6]), 0.5 * (H[3] - H[1])};
    const double z[3] = {k[0] * w[0] + k[1] * w[1] + k[2] * w[2],
                         k[1] * w[0] + k[3] * w[1] + k[4] * w[2],
                         k[2] * w[0] + k[4] * w[1] + k[5] * w[2]};
    /* P = R [z]x; corner k gets P g_k */
    const double Z[9] = {0.0, -z[2], z[1], z[2], 0.0, -z[0], -z[1], z[0], 0.0};
    double P[9];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            P[3 * r + c] = R[3 * r] * Z[c] + R[3 * r + 1] * Z[3 + c] + R[3 * r + 2] * Z[6 + c];
    float *o = out + (t / POSE__FEM_LANES) * 12 * POSE__FEM_LANES + t % POSE__FEM_LANES;
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 3; r++)
            o[(3 * c + r) * POSE__FEM_LANES] +=
                (float)(P[3 * r] * g[c][0] + P[3 * r + 1] * g[c][1] + P[3 * r + 2] * g[c][2]);
    return 2.0 * (w[0] * z[0] + w[1] * z[1] + w[2] * z[2]);
}

/* Unit quaternion (x y z w) of rotation R (Shepperd: from the largest of
 * its four squares). */
static void quat_of(const double R[9], float q[4])
{
    const double t = R[0] + R[4] + R[8];
    double x, y, z, w;
    if (t >= R[0] && t >= R[4] && t >= R[8]) {
        const double s = 2.0 * sqrt(1.0 + t);
        w = 0.25 * s, x = (R[7] - R[5]) / s, y = (R[2] - R[6]) / s, z = (R[3] - R[1]) / s;
    } else if (R[0] >= R[4] && R[0] >= R[8]) {
        const double s = 2.0 * sqrt(1.0 + R[0] - R[4] - R[8]);
        x = 0.25 * s, w = (R[7] - R[5]) / s, y = (R[1] + R[3]) / s, z = (R[2] + R[6]) / s;
    } else if (R[4] >= R[8]) {
        const double s = 2.0 * sqrt(1.0 + R[4] - R[0] - R[8]);
        y = 0.25 * s, w = (R[2] - R[6]) / s, x = (R[1] + R[3]) / s, z = (R[5] + R[7]) / s;
    } else {
        const double s = 2.0 * sqrt(1.0 + R[8] - R[0] - R[4]);
        z = 0.25 * s, w = (R[3] - R[1]) / s, x = (R[2] + R[6]) / s, y = (R[5] + R[7]) / s;
    }
    q[0] = (float)x, q[1] = (float)y, q[2] = (float)z, q[3] = (float)w;
}

/* R when S = R^T F's eigenvalues sigma (axes n) do not make R the maximum
 * of tr(R^T F) (some s_k <= 0: the extraction, which stops wherever R^T F
 * is symmetric, sits on a saddle): R n D D' n^T with D their signs and D'
 * the maximum's, a minus at the smallest |sigma| only where det F < 0
 * (Irving et al. 2004). Written as the quaternion the next step's
 * extraction starts from. */
static void restart_at_maximum(const double R[9], const double sigma[3], const double n[3][3],
                               float q[4])
{
    int smallest = 0;
    for (int a = 1; a < 3; a++)
        if (fabs(sigma[a]) < fabs(sigma[smallest]))
            smallest = a;
    const int inverted = sigma[0] * sigma[1] * sigma[2] < 0.0;
    double d[3], Q[9], Rn[9];
    for (int a = 0; a < 3; a++)
        d[a] = (sigma[a] < 0.0 ? -1.0 : 1.0) * (inverted && a == smallest ? -1.0 : 1.0);
    for (int r = 0; r < 3; r++) /* Q = n diag(d) n^T */
        for (int c = 0; c < 3; c++)
            Q[3 * r + c] =
                n[r][0] * d[0] * n[c][0] + n[r][1] * d[1] * n[c][1] + n[r][2] * d[2] * n[c][2];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            Rn[3 * r + c] = R[3 * r] * Q[c] + R[3 * r + 1] * Q[3 + c] + R[3 * r + 2] * Q[6 + c];
    quat_of(Rn, q);
}

/* Tet t's K (the projected twist stiffness, in S's frame) at x; when R is
 * not the maximum, the next step's extraction restarts at it. */
static void tet_twist(const pose__fem_dyn_tets *tets, pose__fem_dyn_rot *rot, size_t t,
                      const float *x, float k[6])
{
    const pose__fem_dyn_tets *bt = tets + t / POSE__FEM_LANES;
    const size_t l = t % POSE__FEM_LANES;
    double R[9], g[4][3], H[9];
    tet_frame(tets, rot, t, R, g);
    tet_unrotated_gradient(tets, t, R, g, x, H); /* S = R^T F */
    double S[3][3], sigma[3], n[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            S[r][c] = 0.5 * (H[3 * r + c] + H[3 * c + r]);
    eigen3(S, sigma, n);
    const double tr = sigma[0] + sigma[1] + sigma[2];
    const double vmu = bt->vmu[l], c = 2.0 * bt->vlambda[l] * (tr - 3.0) - 4.0 * vmu;
    double K[6] = {0};
    int saddle = 0;
    for (int a = 0; a < 3; a++) {
        const double s = tr - sigma[a];
        saddle |= !(s > 0.0);
        const double lam = 2.0 * vmu + c / (s > TWIST_S_FLOOR ? s : TWIST_S_FLOOR);
        if (!(lam > 0.0))
            continue; /* the projection: a softening twist is left out */
        const double m[3] = {n[0][a], n[1][a], n[2][a]};
        K[0] += lam * m[0] * m[0];
        K[1] += lam * m[0] * m[1];
        K[2] += lam * m[0] * m[2];
        K[3] += lam * m[1] * m[1];
        K[4] += lam * m[1] * m[2];
        K[5] += lam * m[2] * m[2];
    }
    for (int e = 0; e < 6; e++)
        k[e] = (float)K[e];
    if (saddle) {
        float q[4];
        restart_at_maximum(R, sigma, n, q);
        for (int i = 0; i < 4; i++)
            rot[t / POSE__FEM_LANES].q[i][l] = q[i];
    }
}

/* Tet t's corners' diagonal blocks of its K added to blk (24 rows per
 * block): moving corner c by d alone gives w = N d / 2, N = [g_c]x R^T, so
 * the block is N^T K N / 2. */
static void tet_blocks(const pose__fem_dyn_tets *tets, const pose__fem_dyn_rot *rot, size_t t,
                       const float k[6], float *blk)
{
    double R[9], g[4][3];
    tet_frame(tets, rot, t, R, g);
    const double K[3][3] = {{k[0], k[1], k[2]}, {k[1], k[3], k[4]}, {k[2], k[4], k[5]}};
    float *o = blk + (t / POSE__FEM_LANES) * 24 * POSE__FEM_LANES + t % POSE__FEM_LANES;
    for (int c = 0; c < 4; c++) {
        const double *q = g[c];
        const double X[9] = {0.0, -q[2], q[1], q[2], 0.0, -q[0], -q[1], q[0], 0.0};
        double N[3][3], KN[3][3];
        for (int r = 0; r < 3; r++)
            for (int j = 0; j < 3; j++) /* (R^T)[m][j] = R[j][m] */
                N[r][j] =
                    X[3 * r] * R[3 * j] + X[3 * r + 1] * R[3 * j + 1] + X[3 * r + 2] * R[3 * j + 2];
        for (int r = 0; r < 3; r++)
            for (int j = 0; j < 3; j++)
                KN[r][j] = K[r][0] * N[0][j] + K[r][1] * N[1][j] + K[r][2] * N[2][j];
        static const int ij[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
        for (int e = 0; e < 6; e++) {
            const int i = ij[e][0], j = ij[e][1];
            o[(6 * c + e) * POSE__FEM_LANES] +=
                (float)(0.5 * (N[0][i] * KN[0][j] + N[1][i] * KN[1][j] + N[2][i] * KN[2][j]));
        }
    }
}

size_t pose__fem_dyn_twist_build(const pose__fem_dyn_tets *tets, pose__fem_dyn_rot *rot,
                                 const uint32_t *flag, const float *x, const float *v, float *kv,
                                 float *blk, size_t b, size_t e, pose__fem_twist *list)
{
    size_t n = 0;
    for (size_t t = b * POSE__FEM_LANES; t < e * POSE__FEM_LANES; t++) {
        if (!flag[t])
            continue;
        pose__fem_twist *tw = &list[n++];
        tw->tet = (uint32_t)t;
        tw->pad = 0.0f;
        tet_twist(tets, rot, t, x, tw->k);
        tet_product(tets, rot, t, tw->k, v, kv);
        tet_blocks(tets, rot, t, tw->k, blk);
    }
    return n;
}

void pose__fem_dyn_twist_product(const pose__fem_dyn_tets *tets, const pose__fem_dyn_rot *rot,
                                 const pose__fem_twist *list, size_t n, const float *u, float *out,
                                 float *energy)
{
    for (size_t i = 0; i < n; i++)
        energy[list[i].tet] += (float)tet_product(tets, rot, list[i].tet, list[i].k, u, out);
}
