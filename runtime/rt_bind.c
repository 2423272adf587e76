/* SPDX-License-Identifier: Apache-2.0 */
/* Multi-anchor binding kernels (rt_bind.h). */
#include "rt_bind.h"

#include <math.h>
#include <string.h>

/* Cofactor matrix of X (row-major) and det X. X^-T = cof(X) / det X. */
static double cofactor(const double X[9], double C[9])
{
    C[0] = X[4] * X[8] - X[5] * X[7];
    C[1] = X[5] * X[6] - X[3] * X[8];
    C[2] = X[3] * X[7] - X[4] * X[6];
    C[3] = X[2] * X[7] - X[1] * X[8];
    C[4] = X[0] * X[8] - X[2] * X[6];
    C[5] = X[1] * X[6] - X[0] * X[7];
    C[6] = X[1] * X[5] - X[2] * X[4];
    C[7] = X[2] * X[3] - X[0] * X[5];
    C[8] = X[0] * X[4] - X[1] * X[3];
    return X[0] * C[0] + X[1] * C[1] + X[2] * C[2];
}

/* Columns 0 and 1 of F orthonormalized, the third their cross product:
 * always a rotation (identity when F is degenerate). */
static void gram_schmidt(const double F[9], double R[9])
{
    double x[3] = {F[0], F[3], F[6]}, y[3] = {F[1], F[4], F[7]};
    double lx = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    if (!(lx > 1e-30)) {
        static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        memcpy(R, I, sizeof I);
        return;
    }
    for (int k = 0; k < 3; k++)
        x[k] /= lx;
    double d = x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    for (int k = 0; k < 3; k++)
        y[k] -= d * x[k];
    double ly = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    if (!(ly > 1e-30 * lx)) { /* column 1 parallel to column 0: any normal */
        double a[3] = {fabs(x[0]) < 0.9 ? 1.0 : 0.0, fabs(x[0]) < 0.9 ? 0.0 : 1.0, 0.0};
        d = a[0] * x[0] + a[1] * x[1];
        for (int k = 0; k < 3; k++)
            y[k] = a[k] - d * x[k];
        ly = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    }
    for (int k = 0; k < 3; k++)
        y[k] /= ly;
    double z[3] = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]};
    for (int r = 0; r < 3; r++) {
        R[3 * r + 0] = x[r];
        R[3 * r + 1] = y[r];
        R[3 * r + 2] = z[r];
    }
}

void pose__bind_rotation(const float F[9], float R[9])
{
    double X[9], C[9], out[9];
    for (int k = 0; k < 9; k++)
        X[k] = F[k];
    double det = cofactor(X, C);
    if (!(det > 1e-30) || !isfinite(det)) {
        gram_schmidt(X, out);
    } else {
        /* Newton iteration X <- (g X + X^-T / g) / 2: quadratic convergence,
         * and an orthogonal F (a rigid move) is a fixed point to rounding.
         * Higham's scaling g = |det X|^(-1/3) on the first step only takes
         * out the volume change skinning makes; after it the iterate is
         * near orthogonal, where scaling gains nothing and costs a cube
         * root a step. Stops at float precision (the frame is stored as
         * float). */
        double g = 1.0 / cbrt(det);
        for (int it = 0; it < 20; it++) {
            double change = 0.0;
            for (int k = 0; k < 9; k++) {
                double x = 0.5 * (g * X[k] + C[k] / (g * det));
                change = fmax(change, fabs(x - X[k]));
                X[k] = x;
            }
            if (change < 1e-8)
                break;
            det = cofactor(X, C);
            g = 1.0;
        }
        memcpy(out, X, sizeof out);
    }
    for (int k = 0; k < 9; k++)
        R[k] = (float)out[k];
}

/* Posed frame f: R[9] row-major, then t[3] (a node's posed position). */
static void frame_of(const pose__bind_mesh *mesh, const float *tet_positions,
                     const pose__xform *skin, size_t f, float *R)
{
    float *t = R + 9;
    if (f >= mesh->node_frames) {
        const pose__xform *x = &skin[mesh->joints[f - mesh->node_frames]];
        pose__quat_to_matrix(x->q, R);
        memcpy(t, x->t, 3 * sizeof(float));
        return;
    }
    /* F = (sum d' d^T) (sum d d^T)^-1 over the edges d to the neighbours */
    const float *c = tet_positions + 3 * (size_t)mesh->node[f];
    float A[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    for (uint32_t i = mesh->nbr_offset[f]; i < mesh->nbr_offset[f + 1]; i++) {
        const float *u = tet_positions + 3 * (size_t)mesh->nbr[i], *d = mesh->nbr_rest + 3 * (size_t)i;
        const float e[3] = {u[0] - c[0], u[1] - c[1], u[2] - c[2]};
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++)
                A[3 * r + k] += e[r] * d[k];
    }
    const float *Q = mesh->aqq_inv + 9 * f;
    float F[9];
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++)
            F[3 * r + k] = A[3 * r] * Q[k] + A[3 * r + 1] * Q[3 + k] + A[3 * r + 2] * Q[6 + k];
    pose__bind_rotation(F, R);
    memcpy(t, c, 3 * sizeof(float));
}

void pose__bind_frames(const pose__bind_mesh *mesh, const float *tet_positions,
                       const pose__xform *skin, size_t begin, size_t end, float *frames)
{
    for (size_t f = begin; f < end; f++)
        frame_of(mesh, tet_positions, skin, f, frames + POSE__BIND_FRAME * f);
}

/* Vertex v from its anchors' posed frames R[k] (POSE__BIND_FRAME floats each). */
static void blend_vertex(const pose__bind_mesh *mesh, size_t v, const float *const *R,
                         const float *tet_positions, float *dst)
{
    const pose__bind_vertex *x = &mesh->vertex[v];
    const pose__bind_anchor *a = mesh->anchor + v * mesh->anchors;
    float foot[3] = {0.0f, 0.0f, 0.0f}, p[3] = {0.0f, 0.0f, 0.0f};
    if (x->corner[0] != POSE__BIND_NO_FOOT) {
        const float *v0 = tet_positions + 3 * (size_t)x->corner[0];
        const float *v1 = tet_positions + 3 * (size_t)x->corner[1];
        const float *v2 = tet_positions + 3 * (size_t)x->corner[2];
        const float *v3 = tet_positions + 3 * (size_t)x->corner[3];
        for (int d = 0; d < 3; d++)
            foot[d] = v0[d] + x->b[0] * (v1[d] - v0[d]) + x->b[1] * (v2[d] - v0[d]) +
                      x->b[2] * (v3[d] - v0[d]);
    }
    for (unsigned k = 0; k < mesh->anchors; k++) {
        const int node = a[k].frame < mesh->node_frames;
        const float *M = R[k], *base = node ? foot : M + 9, *r = node ? x->r : x->p, w = a[k].weight;
        for (int d = 0; d < 3; d++)
            p[d] += w * (base[d] + M[3 * d] * r[0] + M[3 * d + 1] * r[1] + M[3 * d + 2] * r[2]);
    }
    dst[0] = p[0];
    dst[1] = p[1];
    dst[2] = p[2];
}

void pose__bind_blend(const pose__bind_mesh *mesh, const float *frames, const float *tet_positions,
                      size_t begin, size_t end, float *out)
{
    const float *R[POSE__BIND_MAX_ANCHORS];
    for (size_t v = begin; v < end; v++) {
        for (unsigned k = 0; k < mesh->anchors; k++)
            R[k] = frames + POSE__BIND_FRAME * (size_t)mesh->anchor[v * mesh->anchors + k].frame;
        blend_vertex(mesh, v, R, tet_positions, out + 3 * v);
    }
}

void pose__bind_place(const pose__bind_mesh *mesh, const float *tet_positions,
                      const pose__xform *skin, size_t begin, size_t end, const uint32_t *index,
                      float *out)
{
    /* Neighbouring vertices share most anchors, and vertices numbered close
     * together lie close together: a small direct-mapped cache of posed
     * frames saves most of the work (it changes no result, only whether a
     * frame is computed again). */
    enum { SLOTS = 64 };
    float cache[SLOTS][POSE__BIND_FRAME], frame[POSE__BIND_MAX_ANCHORS][POSE__BIND_FRAME];
    uint32_t key[SLOTS];
    memset(key, 0xff, sizeof key);
    const float *R[POSE__BIND_MAX_ANCHORS];
    for (size_t v = begin; v < end; v++) {
        for (unsigned k = 0; k < mesh->anchors; k++) {
            const uint32_t f = mesh->anchor[v * mesh->anchors + k].frame, slot = f % SLOTS;
            if (key[slot] != f) {
                frame_of(mesh, tet_positions, skin, f, cache[slot]);
                key[slot] = f;
            }
            memcpy(frame[k], cache[slot], sizeof frame[k]); /* a later anchor may evict it */
            R[k] = frame[k];
        }
        blend_vertex(mesh, v, R, tet_positions, out + 3 * (size_t)index[v]);
    }
}
