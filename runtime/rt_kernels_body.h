/* SPDX-License-Identifier: Apache-2.0 */
/* The skinning and transfer kernels, written once over eight-lane vectors
 * and compiled once per variant: the including file defines POSE__KV(name)
 * to give the functions their variant suffix. */
#ifndef POSE__KV
#  error "define POSE__KV before including rt_kernels_body.h"
#endif

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "rt_kernels.h"
#include "rt_vec.h"

#define WSCALE (1.0f / 32768.0f)
#define PAL_STRIDE 16 /* floats per pose__skin_joint */

/* Joint indices of influence k for the lanes of block b. */
#define joint_row(m, b, k) ((m)->joints + ((b) * (m)->influences + (k)) * POSE__BLOCK)
/* Entry `off` of the palette rows of the joints in `row`. */
#define PAL(row, off) V8_GATHER(pf, row, PAL_STRIDE, off)

/* 1 when the eight lanes of joint row idx name the same joint: nearly every
 * row of a body (vertices come in spatial order, so a block lies in one
 * bone's region); its palette entries are then broadcast, not gathered lane
 * by lane (same values, far fewer loads and inserts). */
static POSE__INLINE int row_uniform(const uint16_t *idx)
{
    uint64_t lo, hi;
    memcpy(&lo, idx, 8);
    memcpy(&hi, idx + 4, 8);
    const uint64_t all = (uint64_t)idx[0] * 0x0001000100010001ull;
    return lo == all && hi == all;
}

/* out[i] = palette entry off + i of the rows' joints, i < n. */
static POSE__INLINE void pal_load(const float *pf, const uint16_t *idx, int uniform, int off,
                                  int n, pose__v8f *out)
{
    if (uniform) {
        const float *j = pf + (size_t)idx[0] * PAL_STRIDE + off;
        for (int i = 0; i < n; i++)
            out[i] = V8_SPLAT(j[i]);
    } else {
        for (int i = 0; i < n; i++)
            out[i] = PAL(idx, off + i);
    }
}

/* Weights of influence k for the lanes of block b (a macro: vectors are not
 * passed by value, whose ABI differs between the variants). */
#define block_weights(m, b, k)                                                       \
    (__builtin_convertvector(                                                        \
         *(const pose__v8u16 *)((m)->weights + ((b) * (m)->influences + (k)) * POSE__BLOCK), \
         pose__v8f) * WSCALE)

/* Write the lanes of block b as xyz triples at out + 24 b (only the lanes
 * below `count`). With AVX2 a full block is three aligned 32-byte stores,
 * non-temporal when `stream` (outputs nobody reads during pose_apply). */
static POSE__INLINE void store_lanes(float *restrict out, size_t b, size_t count,
                                     const pose__v8f *px, const pose__v8f *py,
                                     const pose__v8f *pz, int stream)
{
    size_t n = count - b * POSE__BLOCK;
    float *o = out + 3 * POSE__BLOCK * b;
#ifdef __AVX2__
    if (n >= 8 && ((uintptr_t)o & 31u) == 0) {
        /* 8x3 transpose: six in-lane shuffles give each 128-bit half its
         * own x y z x / y z x y / z x y z groups, three lane swaps join them */
        const __m256 x = (__m256)*px, y = (__m256)*py, z = (__m256)*pz;
        const __m256 xy = _mm256_shuffle_ps(x, y, _MM_SHUFFLE(2, 0, 2, 0)); /* x0 x2 y0 y2 */
        const __m256 yz = _mm256_shuffle_ps(y, z, _MM_SHUFFLE(3, 1, 3, 1)); /* y1 y3 z1 z3 */
        const __m256 zx = _mm256_shuffle_ps(z, x, _MM_SHUFFLE(3, 1, 2, 0)); /* z0 z2 x1 x3 */
        const __m256 r03 = _mm256_shuffle_ps(xy, zx, _MM_SHUFFLE(2, 0, 2, 0)); /* x0 y0 z0 x1 */
        const __m256 r14 = _mm256_shuffle_ps(yz, xy, _MM_SHUFFLE(3, 1, 2, 0)); /* y1 z1 x2 y2 */
        const __m256 r25 = _mm256_shuffle_ps(zx, yz, _MM_SHUFFLE(3, 1, 3, 1)); /* z2 x3 y3 z3 */
        const __m256 a = _mm256_permute2f128_ps(r03, r14, 0x20);
        const __m256 c = _mm256_permute2f128_ps(r25, r03, 0x30);
        const __m256 e = _mm256_permute2f128_ps(r14, r25, 0x31);
        if (stream) {
            _mm256_stream_ps(o, a);
            _mm256_stream_ps(o + 8, c);
            _mm256_stream_ps(o + 16, e);
        } else {
            _mm256_store_ps(o, a);
            _mm256_store_ps(o + 8, c);
            _mm256_store_ps(o + 16, e);
        }
        return;
    }
#else
    (void)stream;
#endif
    const pose__v8f x = *px, y = *py, z = *pz;
    if (n > 8)
        n = 8;
    for (size_t l = 0; l < n; l++) {
        o[3 * l + 0] = x[l];
        o[3 * l + 1] = y[l];
        o[3 * l + 2] = z[l];
    }
}

/* x, y, z of the tet vertices idx[0..7] (xyz interleaved at tp). */
#ifdef __AVX2__
/* One 16-byte load per lane (its 4th float belongs to the next vertex, or
 * to the slack the caller leaves after the array), then a transpose. */
#define LOAD_XYZ(tp, idx, X, Y, Z)                                                  \
    do {                                                                            \
        __m256 r0_ = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps((tp) + 3 * (size_t)(idx)[0])), \
                                          _mm_loadu_ps((tp) + 3 * (size_t)(idx)[4]), 1);        \
        __m256 r1_ = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps((tp) + 3 * (size_t)(idx)[1])), \
                                          _mm_loadu_ps((tp) + 3 * (size_t)(idx)[5]), 1);        \
        __m256 r2_ = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps((tp) + 3 * (size_t)(idx)[2])), \
                                          _mm_loadu_ps((tp) + 3 * (size_t)(idx)[6]), 1);        \
        __m256 r3_ = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps((tp) + 3 * (size_t)(idx)[3])), \
                                          _mm_loadu_ps((tp) + 3 * (size_t)(idx)[7]), 1);        \
        __m256 t0_ = _mm256_unpacklo_ps(r0_, r1_), t1_ = _mm256_unpackhi_ps(r0_, r1_); \
        __m256 t2_ = _mm256_unpacklo_ps(r2_, r3_), t3_ = _mm256_unpackhi_ps(r2_, r3_); \
        (X) = (pose__v8f)_mm256_shuffle_ps(t0_, t2_, 0x44);                         \
        (Y) = (pose__v8f)_mm256_shuffle_ps(t0_, t2_, 0xEE);                         \
        (Z) = (pose__v8f)_mm256_shuffle_ps(t1_, t3_, 0x44);                         \
    } while (0)
#else
#define LOAD_XYZ(tp, idx, X, Y, Z)                                                  \
    do {                                                                            \
        (X) = V8_GATHER(tp, idx, 3, 0);                                             \
        (Y) = V8_GATHER(tp, idx, 3, 1);                                             \
        (Z) = V8_GATHER(tp, idx, 3, 2);                                             \
    } while (0)
#endif

void POSE__KV(pose__skin_blocks)(int method, const pose__skin_mesh *m,
                                 const pose__skin_joint *palette, size_t begin, size_t end,
                                 float *restrict out)
{
    const float *pf = (const float *)palette;
    for (size_t b = begin; b < end; b++) {
        const float *rb = m->rest + 3 * POSE__BLOCK * b;
        const pose__v8f vx = *(const pose__v8f *)rb;
        const pose__v8f vy = *(const pose__v8f *)(rb + 8);
        const pose__v8f vz = *(const pose__v8f *)(rb + 16);
        const unsigned kb = m->active[b];
        const uint16_t *idx = joint_row(m, b, 0);
        int uni = row_uniform(idx);
        pose__v8f q0[4], qk[4], tk[4];
        pal_load(pf, idx, uni, 0, 4, q0);
        const pose__v8f q0x = q0[0], q0y = q0[1], q0z = q0[2], q0w = q0[3];
        pose__v8f ox, oy, oz, rx, ry, rz;
        if (kb == 1) {
            /* every lane bound to one joint: rigid, the same for all methods */
            pal_load(pf, idx, uni, 4, 3, tk);
            V8_ROTDISP(rx, ry, rz, q0x, q0y, q0z, q0w, vx, vy, vz);
            ox = vx + (rx + tk[0]);
            oy = vy + (ry + tk[1]);
            oz = vz + (rz + tk[2]);
        } else if (method == POSE__SKIN_LBS) {
            /* v' = v + sum w (R v - v + t) */
            pose__v8f dx = V8_SPLAT(0.0f), dy = dx, dz = dx;
            for (unsigned k = 0; k < kb; k++) {
                idx = joint_row(m, b, k);
                uni = row_uniform(idx);
                pose__v8f w = block_weights(m, b, k);
                pal_load(pf, idx, uni, 0, 4, qk);
                pal_load(pf, idx, uni, 4, 3, tk);
                V8_ROTDISP(rx, ry, rz, qk[0], qk[1], qk[2], qk[3], vx, vy, vz);
                dx += w * (rx + tk[0]);
                dy += w * (ry + tk[1]);
                dz += w * (rz + tk[2]);
            }
            ox = vx + dx;
            oy = vy + dy;
            oz = vz + dz;
        } else if (method == POSE__SKIN_DQS) {
            /* blend dual quaternions, signs aligned to the first joint's */
            pose__v8f bx = V8_SPLAT(0.0f), by = bx, bz = bx, bw = bx;
            pose__v8f ex = bx, ey = bx, ez = bx, ew = bx;
            for (unsigned k = 0; k < kb; k++) {
                idx = joint_row(m, b, k);
                uni = row_uniform(idx);
                pose__v8f dk[4];
                pal_load(pf, idx, uni, 0, 4, qk);
                pal_load(pf, idx, uni, 8, 4, dk);
                const pose__v8f qx = qk[0], qy = qk[1], qz = qk[2], qw = qk[3];
                pose__v8f dot = qx * q0x + qy * q0y + qz * q0z + qw * q0w;
                pose__v8f w = V8_NEG_WHERE(block_weights(m, b, k), dot);
                bx += w * qx; by += w * qy; bz += w * qz; bw += w * qw;
                ex += w * dk[0];
                ey += w * dk[1];
                ez += w * dk[2];
                ew += w * dk[3];
            }
            pose__v8f inv = 1.0f / V8_SQRT(bx * bx + by * by + bz * bz + bw * bw);
            bx *= inv; by *= inv; bz *= inv; bw *= inv;
            ex *= inv; ey *= inv; ez *= inv; ew *= inv;
            /* t = 2 (e b*).xyz = 2 (bw e - ew b + b x e) */
            pose__v8f tx = 2.0f * ((bw * ex - ew * bx) + (by * ez - bz * ey));
            pose__v8f ty = 2.0f * ((bw * ey - ew * by) + (bz * ex - bx * ez));
            pose__v8f tz = 2.0f * ((bw * ez - ew * bz) + (bx * ey - by * ex));
            V8_ROTDISP(rx, ry, rz, bx, by, bz, bw, vx, vy, vz);
            ox = vx + (rx + tx);
            oy = vy + (ry + ty);
            oz = vz + (rz + tz);
        } else {
            /* CoR: q = normalize(sum w q_j) aligned, t = (sum w M_j) c - R c:
             * v' = v + (R - I)(v - c) + sum w ((R_j - I) c + t_j) */
            const float *cb = m->cor + 3 * POSE__BLOCK * b;
            const pose__v8f cx = *(const pose__v8f *)cb;
            const pose__v8f cy = *(const pose__v8f *)(cb + 8);
            const pose__v8f cz = *(const pose__v8f *)(cb + 16);
            pose__v8f bx = V8_SPLAT(0.0f), by = bx, bz = bx, bw = bx;
            pose__v8f dx = bx, dy = bx, dz = bx;
            for (unsigned k = 0; k < kb; k++) {
                idx = joint_row(m, b, k);
                uni = row_uniform(idx);
                pose__v8f w = block_weights(m, b, k);
                pal_load(pf, idx, uni, 0, 4, qk);
                pal_load(pf, idx, uni, 4, 3, tk);
                const pose__v8f qx = qk[0], qy = qk[1], qz = qk[2], qw = qk[3];
                pose__v8f dot = qx * q0x + qy * q0y + qz * q0z + qw * q0w;
                pose__v8f ws = V8_NEG_WHERE(w, dot);
                bx += ws * qx; by += ws * qy; bz += ws * qz; bw += ws * qw;
                V8_ROTDISP(rx, ry, rz, qx, qy, qz, qw, cx, cy, cz);
                dx += w * (rx + tk[0]);
                dy += w * (ry + tk[1]);
                dz += w * (rz + tk[2]);
            }
            pose__v8f inv = 1.0f / V8_SQRT(bx * bx + by * by + bz * bz + bw * bw);
            bx *= inv; by *= inv; bz *= inv; bw *= inv;
            pose__v8f px = vx - cx, py = vy - cy, pz = vz - cz;
            V8_ROTDISP(rx, ry, rz, bx, by, bz, bw, px, py, pz);
            ox = vx + (rx + dx);
            oy = vy + (ry + dy);
            oz = vz + (rz + dz);
        }
        store_lanes(out, b, m->vertex_count, &ox, &oy, &oz, 0);
    }
}

/* Normalize the raw normals of blocks [b0, b0 + n) and store them. Kept
 * apart from the gathers: a short, independent loop the core can overlap,
 * instead of a sqrt + divide at the end of a long dependency chain. */
static POSE__INLINE void store_normals(const pose__transfer_mesh *m, const pose__v8f (*raw)[3],
                                       size_t b0, size_t n, float *restrict nrm, int stream)
{
    for (size_t i = 0; i < n; i++) {
        pose__v8f nx = raw[i][0], ny = raw[i][1], nz = raw[i][2];
        pose__v8f n2 = nx * nx + ny * ny + nz * nz;
        /* a flattened tet or a vertex without triangles has no normal: 0 */
        pose__v8f s = V8_AND_MASK(1.0f / V8_SQRT(n2), n2 > 1e-36f);
        nx *= s;
        ny *= s;
        nz *= s;
        store_lanes(nrm, b0 + i, m->vertex_count, &nx, &ny, &nz, stream);
    }
}

#define TRANSFER_BATCH 16 /* blocks whose raw normals wait in L1 */
#define TRANSFER_PREFETCH 4 /* blocks ahead whose tet corners are prefetched */
#define STREAM_BYTES (16u << 20) /* tissue outputs bigger than this are streamed */

size_t POSE__KV(pose__transfer_blocks)(const pose__transfer_mesh *m, const float *restrict tp,
                                       size_t begin, size_t end, float *restrict pos,
                                       float *restrict nrm, uint32_t *restrict flagged)
{
    pose__v8f raw[TRANSFER_BATCH][3];
    size_t nflagged = 0;
    /* Outputs larger than a last-level cache bypass it; small ones stay hot
     * for the caller. */
    const int stream = m->vertex_count * 24 > STREAM_BYTES;
    size_t batch_start = begin;
    for (size_t b = begin; b < end; b++) {
        const uint32_t *tv = m->tet_vertices + 4 * POSE__BLOCK * b;
        /* The tet corners a block reads are near those of the block before
         * (tissue vertices come in surface order) but not in a pattern the
         * hardware prefetcher follows: touch the first and last lane's
         * corners a few blocks ahead (~10 % off the pass, 1 or 2 threads). */
        if (b + TRANSFER_PREFETCH < end) {
            const uint32_t *pv = tv + 4 * POSE__BLOCK * TRANSFER_PREFETCH;
            for (int c = 0; c < 4; c++) {
                __builtin_prefetch(tp + 3 * (size_t)pv[POSE__BLOCK * c]);
                __builtin_prefetch(tp + 3 * (size_t)pv[POSE__BLOCK * c + POSE__BLOCK - 1]);
            }
        }
        pose__v8f v0x, v0y, v0z, e1x, e1y, e1z, e2x, e2y, e2z, e3x, e3y, e3z;
        LOAD_XYZ(tp, tv, v0x, v0y, v0z);
        LOAD_XYZ(tp, tv + 8, e1x, e1y, e1z);
        LOAD_XYZ(tp, tv + 16, e2x, e2y, e2z);
        LOAD_XYZ(tp, tv + 24, e3x, e3y, e3z);
        e1x -= v0x; e1y -= v0y; e1z -= v0z;
        e2x -= v0x; e2y -= v0y; e2z -= v0z;
        e3x -= v0x; e3y -= v0y; e3z -= v0z;
        const float *bb = m->bary + 3 * POSE__BLOCK * b;
        const pose__v8f b1 = *(const pose__v8f *)bb, b2 = *(const pose__v8f *)(bb + 8),
                        b3 = *(const pose__v8f *)(bb + 16);
        const pose__v8f px = v0x + (b1 * e1x + b2 * e2x + b3 * e3x);
        const pose__v8f py = v0y + (b1 * e1y + b2 * e2y + b3 * e3y);
        const pose__v8f pz = v0z + (b1 * e1z + b2 * e2z + b3 * e3z);
        store_lanes(pos, b, m->vertex_count, &px, &py, &pz, stream);
        if (!nrm)
            continue;
        const int16_t *kb = m->normal_key + 3 * POSE__BLOCK * b;
        const pose__v8f k1 = __builtin_convertvector(*(const pose__v8i16 *)kb, pose__v8f);
        const pose__v8f k2 = __builtin_convertvector(*(const pose__v8i16 *)(kb + 8), pose__v8f);
        const pose__v8f k3 = __builtin_convertvector(*(const pose__v8i16 *)(kb + 16), pose__v8f);
        /* cof(D') k = k1 (e2 x e3) + k2 (e3 x e1) + k3 (e1 x e2) */
        pose__v8f *r = raw[b - batch_start];
        const pose__v8f c23x = e2y * e3z - e2z * e3y, c23y = e2z * e3x - e2x * e3z,
                        c23z = e2x * e3y - e2y * e3x;
        r[0] = k1 * c23x + k2 * (e3y * e1z - e3z * e1y) + k3 * (e1y * e2z - e1z * e2y);
        r[1] = k1 * c23y + k2 * (e3z * e1x - e3x * e1z) + k3 * (e1z * e2x - e1x * e2z);
        r[2] = k1 * c23z + k2 * (e3x * e1y - e3y * e1x) + k3 * (e1x * e2y - e1y * e2x);
        /* det D' = e1 . (e2 x e3) <= 0: the tet is flat or inside out (det D > 0 at rest) */
        const pose__v8f det = e1x * c23x + e1y * c23y + e1z * c23z;
        const pose__v8i bad = det <= 0.0f;
        if (V8_ANY(bad)) {
            size_t count = m->vertex_count - b * POSE__BLOCK;
            for (size_t l = 0; l < 8 && l < count; l++)
                if (bad[l])
                    flagged[nflagged++] = (uint32_t)(b * POSE__BLOCK + l);
        }
        if (b + 1 - batch_start == TRANSFER_BATCH || b + 1 == end) {
            store_normals(m, (const pose__v8f(*)[3])raw, batch_start, b + 1 - batch_start, nrm,
                          stream);
            batch_start = b + 1;
        }
    }
#ifdef __AVX2__
    _mm_sfence(); /* order the streaming stores before the pool's hand-back */
#endif
    return nflagged;
}
