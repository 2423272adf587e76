/* SPDX-License-Identifier: Apache-2.0 */
#include "rt_skin.h"

#include "rt_simd.h"

#define WSCALE (1.0f / 32768.0f)

void pose__skin_palette(size_t joint_count, const pose__xform *skin, pose__skin_joint *out)
{
    for (size_t j = 0; j < joint_count; j++) {
        const pose__xform *x = &skin[j];
        pose__skin_joint *p = &out[j];
        float r[9];
        pose__quat_to_mat3(r, x->q);
        for (int row = 0; row < 3; row++) {
            p->m[4 * row + 0] = r[3 * row + 0];
            p->m[4 * row + 1] = r[3 * row + 1];
            p->m[4 * row + 2] = r[3 * row + 2];
            p->m[4 * row + 3] = x->t[row];
        }
        for (int c = 0; c < 4; c++)
            p->q[c] = x->q[c];
        const float t[4] = {x->t[0], x->t[1], x->t[2], 0.0f};
        pose__quat_mul(p->d, t, x->q);
        for (int c = 0; c < 4; c++)
            p->d[c] *= 0.5f;
    }
}

/* The kernels below are written once and instantiated for each K (so the
 * influence loops unroll) and for 8- or 16-bit joint indices. */
#define JOINT(mesh, idx, wide) ((wide) ? (mesh)->joints16[idx] : (mesh)->joints8[idx])

static POSE__INLINE void lbs_range(const pose__skin_mesh *mesh, const pose__skin_joint *pal,
                                   size_t begin, size_t end, float *restrict out,
                                   const unsigned K, const int wide)
{
    const float *restrict rest = mesh->rest;
    const uint16_t *restrict wts = mesh->weights;
    for (size_t i = begin; i < end; i++) {
        float m[12] = {0};
        for (unsigned k = 0; k < K; k++) {
            const float *pm = pal[JOINT(mesh, i * K + k, wide)].m;
            float w = (float)wts[i * K + k] * WSCALE;
            for (int r = 0; r < 12; r++)
                m[r] += w * pm[r];
        }
        float x = rest[3 * i], y = rest[3 * i + 1], z = rest[3 * i + 2];
        out[3 * i + 0] = m[0] * x + m[1] * y + m[2] * z + m[3];
        out[3 * i + 1] = m[4] * x + m[5] * y + m[6] * z + m[7];
        out[3 * i + 2] = m[8] * x + m[9] * y + m[10] * z + m[11];
    }
}

/* Blend the rotations of a vertex's joints with signs aligned to its first
 * (largest) joint's: q and -q are the same rotation, and blending across the
 * antipode would cancel them (the "candy wrapper" of naive blending). */
static POSE__INLINE float align_sign(const float *q, const float *q0, float w)
{
    float dot = q[0] * q0[0] + q[1] * q0[1] + q[2] * q0[2] + q[3] * q0[3];
    return dot < 0.0f ? -w : w;
}

static POSE__INLINE void dqs_range(const pose__skin_mesh *mesh, const pose__skin_joint *pal,
                                   size_t begin, size_t end, float *restrict out,
                                   const unsigned K, const int wide)
{
    const float *restrict rest = mesh->rest;
    const uint16_t *restrict wts = mesh->weights;
    for (size_t i = begin; i < end; i++) {
        const float *q0 = pal[JOINT(mesh, i * K, wide)].q;
        float b[4] = {0}, e[4] = {0};
        for (unsigned k = 0; k < K; k++) {
            const pose__skin_joint *p = &pal[JOINT(mesh, i * K + k, wide)];
            float w = align_sign(p->q, q0, (float)wts[i * K + k] * WSCALE);
            for (int c = 0; c < 4; c++) {
                b[c] += w * p->q[c];
                e[c] += w * p->d[c];
            }
        }
        float n2 = b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3];
        if (n2 != 1.0f) {
            float s = 1.0f / sqrtf(n2);
            for (int c = 0; c < 4; c++) {
                b[c] *= s;
                e[c] *= s;
            }
        }
        float r[9];
        pose__quat_to_mat3(r, b);
        /* t = 2 (e b*).xyz */
        float tx = 2.0f * (b[3] * e[0] - e[3] * b[0] + b[1] * e[2] - b[2] * e[1]);
        float ty = 2.0f * (b[3] * e[1] - e[3] * b[1] + b[2] * e[0] - b[0] * e[2]);
        float tz = 2.0f * (b[3] * e[2] - e[3] * b[2] + b[0] * e[1] - b[1] * e[0]);
        float x = rest[3 * i], y = rest[3 * i + 1], z = rest[3 * i + 2];
        out[3 * i + 0] = r[0] * x + r[1] * y + r[2] * z + tx;
        out[3 * i + 1] = r[3] * x + r[4] * y + r[5] * z + ty;
        out[3 * i + 2] = r[6] * x + r[7] * y + r[8] * z + tz;
    }
}

static POSE__INLINE void cor_range(const pose__skin_mesh *mesh, const pose__skin_joint *pal,
                                   size_t begin, size_t end, float *restrict out,
                                   const unsigned K, const int wide)
{
    const float *restrict rest = mesh->rest;
    const float *restrict cor = mesh->cor;
    const uint16_t *restrict wts = mesh->weights;
    for (size_t i = begin; i < end; i++) {
        const float *q0 = pal[JOINT(mesh, i * K, wide)].q;
        float q[4] = {0}, m[12] = {0};
        for (unsigned k = 0; k < K; k++) {
            const pose__skin_joint *p = &pal[JOINT(mesh, i * K + k, wide)];
            float w = (float)wts[i * K + k] * WSCALE;
            float ws = align_sign(p->q, q0, w);
            for (int c = 0; c < 4; c++)
                q[c] += ws * p->q[c];
            for (int r = 0; r < 12; r++)
                m[r] += w * p->m[r];
        }
        float n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
        if (n2 != 1.0f) {
            float s = 1.0f / sqrtf(n2);
            for (int c = 0; c < 4; c++)
                q[c] *= s;
        }
        float r[9];
        pose__quat_to_mat3(r, q);
        float cx = cor[3 * i], cy = cor[3 * i + 1], cz = cor[3 * i + 2];
        /* t = (sum w M) cor - R cor: exactly 0 at rest, so rest is exact. */
        float tx = (m[0] * cx + m[1] * cy + m[2] * cz + m[3]) - (r[0] * cx + r[1] * cy + r[2] * cz);
        float ty = (m[4] * cx + m[5] * cy + m[6] * cz + m[7]) - (r[3] * cx + r[4] * cy + r[5] * cz);
        float tz = (m[8] * cx + m[9] * cy + m[10] * cz + m[11]) - (r[6] * cx + r[7] * cy + r[8] * cz);
        float x = rest[3 * i], y = rest[3 * i + 1], z = rest[3 * i + 2];
        out[3 * i + 0] = r[0] * x + r[1] * y + r[2] * z + tx;
        out[3 * i + 1] = r[3] * x + r[4] * y + r[5] * z + ty;
        out[3 * i + 2] = r[6] * x + r[7] * y + r[8] * z + tz;
    }
}

#define POSE__DISPATCH_K(fn, K)                                                       \
    static void fn##_##K##_8(const pose__skin_mesh *m, const pose__skin_joint *p,     \
                             size_t b, size_t e, float *o)                            \
    { fn(m, p, b, e, o, K, 0); }                                                      \
    static void fn##_##K##_16(const pose__skin_mesh *m, const pose__skin_joint *p,    \
                              size_t b, size_t e, float *o)                           \
    { fn(m, p, b, e, o, K, 1); }
#define POSE__DISPATCH_ALL(fn)                                                        \
    POSE__DISPATCH_K(fn, 1) POSE__DISPATCH_K(fn, 2) POSE__DISPATCH_K(fn, 3)           \
    POSE__DISPATCH_K(fn, 4) POSE__DISPATCH_K(fn, 5) POSE__DISPATCH_K(fn, 6)           \
    POSE__DISPATCH_K(fn, 7) POSE__DISPATCH_K(fn, 8)
POSE__DISPATCH_ALL(lbs_range)
POSE__DISPATCH_ALL(dqs_range)
POSE__DISPATCH_ALL(cor_range)

typedef void (*range_fn)(const pose__skin_mesh *, const pose__skin_joint *, size_t, size_t,
                         float *);
#define POSE__ROW(fn)                                                                 \
    {fn##_1_8, fn##_2_8, fn##_3_8, fn##_4_8, fn##_5_8, fn##_6_8, fn##_7_8, fn##_8_8}, \
    {fn##_1_16, fn##_2_16, fn##_3_16, fn##_4_16, fn##_5_16, fn##_6_16, fn##_7_16, fn##_8_16}
/* [method][wide][K - 1] */
static const range_fn k_kernels[3][2][8] = {
    {POSE__ROW(lbs_range)},
    {POSE__ROW(dqs_range)},
    {POSE__ROW(cor_range)},
};

void pose__skin(int method, const pose__skin_mesh *mesh, const pose__skin_joint *palette,
                size_t begin, size_t end, float *out)
{
    if (begin >= end)
        return;
    int wide = mesh->joints8 == NULL;
    k_kernels[method][wide][mesh->influences - 1](mesh, palette, begin, end, out);
}
