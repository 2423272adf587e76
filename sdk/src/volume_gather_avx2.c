/* SPDX-License-Identifier: Apache-2.0
 * pose__volume_gather_avx2: eight queued voxels at a time (compiled with
 * -mavx2, sdk/CMakeLists.txt; called only when the CPU has AVX2). Every
 * value comes from the same operations, in the same order, as
 * pose__volume_gather_generic. Empty on other architectures. */
#include "volume_internal.h"

#ifdef POSE__HAVE_AVX2_VOLUME
#  include <immintrin.h>

/* a + f (b - a), as the generic variant writes it */
static inline __m256 lerp8(__m256 a, __m256 b, __m256 f)
{
    return _mm256_add_ps(a, _mm256_mul_ps(f, _mm256_sub_ps(b, a)));
}

static inline __m256 gather8(const float *img, __m256i at)
{
    return _mm256_i32gather_ps(img, at, 4);
}

/* The generic variant's clamp: max(v, 0) takes 0 for NaN (the second
 * operand), then min(., hi). */
static inline __m256 clamp8(__m256 v, float hi)
{
    return _mm256_min_ps(_mm256_max_ps(v, _mm256_setzero_ps()), _mm256_set1_ps(hi));
}

/* The cell's lower corner: trunc, at most n - 2. */
static inline __m256i cell8(__m256 v, int last_cell)
{
    return _mm256_min_epi32(_mm256_cvttps_epi32(v), _mm256_set1_epi32(last_cell));
}

/* step where the fraction is at least one half, else 0 */
static inline __m256i step_if_up(__m256 f, int step)
{
    return _mm256_and_si256(_mm256_castps_si256(_mm256_cmp_ps(f, _mm256_set1_ps(0.5f), _CMP_GE_OQ)),
                            _mm256_set1_epi32(step));
}

unsigned pose__volume_gather_avx2(const pose_volume_desc *rest, const pose__vol_stage *st,
                                  float *oi, uint16_t *ol)
{
    const pose__vol_cells c = pose__vol_cells_of(&rest->grid);
    /* The label gather reads 32 bits at a 16-bit label: the image's last
     * voxel would read past its end, so a batch that holds it goes to the
     * generic variant (volumes hold at most 2^31 voxels: int32 indexes). */
    const __m256i vlast = _mm256_set1_epi32((int)(c.plane * rest->grid.nz - 2));
    const __m256i vplane = _mm256_set1_epi32((int)c.plane), vrow = _mm256_set1_epi32((int)c.row),
                  sx = _mm256_set1_epi32((int)c.step[0]), sy = _mm256_set1_epi32((int)c.step[1]),
                  sz = _mm256_set1_epi32((int)c.step[2]);
    const __m256 lo = _mm256_set1_ps(-0.5f), hx = _mm256_set1_ps(c.out[0]),
                 hy = _mm256_set1_ps(c.out[1]), hz = _mm256_set1_ps(c.out[2]);
    const float *img = rest->intensity;
    const int *lb = (const int *)(const void *)rest->labels;
    const unsigned n8 = st->n & ~7u;
    for (unsigned e = 0; e < n8; e += 8) {
        __m256 x = _mm256_loadu_ps(st->x + e), y = _mm256_loadu_ps(st->y + e),
               z = _mm256_loadu_ps(st->z + e);
        const __m256 out = _mm256_or_ps(
            _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(x, lo, _CMP_LT_OQ), _mm256_cmp_ps(y, lo, _CMP_LT_OQ)),
                         _mm256_or_ps(_mm256_cmp_ps(z, lo, _CMP_LT_OQ), _mm256_cmp_ps(x, hx, _CMP_GT_OQ))),
            _mm256_or_ps(_mm256_cmp_ps(y, hy, _CMP_GT_OQ), _mm256_cmp_ps(z, hz, _CMP_GT_OQ)));
        x = clamp8(x, c.top[0]), y = clamp8(y, c.top[1]), z = clamp8(z, c.top[2]);
        const __m256i xi = cell8(x, c.last_cell[0]), yi = cell8(y, c.last_cell[1]),
                      zi = cell8(z, c.last_cell[2]);
        const __m256 fx = _mm256_sub_ps(x, _mm256_cvtepi32_ps(xi)),
                     fy = _mm256_sub_ps(y, _mm256_cvtepi32_ps(yi)),
                     fz = _mm256_sub_ps(z, _mm256_cvtepi32_ps(zi));
        const __m256i base = _mm256_add_epi32(
            _mm256_add_epi32(_mm256_mullo_epi32(zi, vplane), _mm256_mullo_epi32(yi, vrow)), xi);
        const __m256i near = _mm256_add_epi32(
            _mm256_add_epi32(base, step_if_up(fx, (int)c.step[0])),
            _mm256_add_epi32(step_if_up(fy, (int)c.step[1]), step_if_up(fz, (int)c.step[2])));
        if (_mm256_movemask_epi8(_mm256_cmpgt_epi32(near, vlast)))
            return e; /* the rest, generic */
        const __m256i labels = _mm256_blendv_epi8(_mm256_i32gather_epi32(lb, near, 2),
                                                  _mm256_set1_epi32(rest->label_background),
                                                  _mm256_castps_si256(out));
        const __m256i b_y = _mm256_add_epi32(base, sy), b_z = _mm256_add_epi32(base, sz),
                      b_yz = _mm256_add_epi32(b_y, sz);
        const __m256 c00 = lerp8(gather8(img, base), gather8(img, _mm256_add_epi32(base, sx)), fx);
        const __m256 c10 = lerp8(gather8(img, b_y), gather8(img, _mm256_add_epi32(b_y, sx)), fx);
        const __m256 c01 = lerp8(gather8(img, b_z), gather8(img, _mm256_add_epi32(b_z, sx)), fx);
        const __m256 c11 = lerp8(gather8(img, b_yz), gather8(img, _mm256_add_epi32(b_yz, sx)), fx);
        const __m256 v = _mm256_blendv_ps(lerp8(lerp8(c00, c10, fy), lerp8(c01, c11, fy), fz),
                                          _mm256_set1_ps(rest->intensity_background), out);
        float vs[8];
        int ls[8];
        _mm256_storeu_ps(vs, v);
        _mm256_storeu_si256((__m256i *)(void *)ls, labels);
        for (int l = 0; l < 8; l++) {
            const uint32_t at = st->at[e + (unsigned)l];
            oi[at] = vs[l];
            ol[at] = (uint16_t)ls[l]; /* the low half: little-endian x86 */
        }
    }
    return n8;
}
#else
typedef int pose__no_avx2_gather; /* ISO C wants a non-empty file */
#endif
