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

unsigned pose__volume_gather_avx2(const pose_volume_desc *rest, const pose__vol_stage *st,
                                  float *oi, uint16_t *ol)
{
    const int sy = (int)rest->grid.nx, sz = (int)(rest->grid.nx * rest->grid.ny);
    /* The label gather reads 32 bits at a 16-bit label: the image's last
     * voxel would read past its end, so a batch that holds it goes to the
     * generic variant (volumes hold at most 2^31 voxels: int32 indexes). */
    const int last = (int)((size_t)sz * rest->grid.nz - 1);
    const __m256i vsy = _mm256_set1_epi32(sy), vsz = _mm256_set1_epi32(sz),
                  one = _mm256_set1_epi32(1), vlast = _mm256_set1_epi32(last - 1);
    const __m256 half = _mm256_set1_ps(0.5f);
    const float *img = rest->intensity;
    const int *lb = (const int *)(const void *)rest->labels;
    const unsigned n8 = st->n & ~7u;
    for (unsigned e = 0; e < n8; e += 8) {
        const __m256 x = _mm256_loadu_ps(st->x + e), y = _mm256_loadu_ps(st->y + e),
                     z = _mm256_loadu_ps(st->z + e);
        const __m256i xi = _mm256_cvttps_epi32(x), yi = _mm256_cvttps_epi32(y),
                      zi = _mm256_cvttps_epi32(z);
        const __m256 fx = _mm256_sub_ps(x, _mm256_cvtepi32_ps(xi)),
                     fy = _mm256_sub_ps(y, _mm256_cvtepi32_ps(yi)),
                     fz = _mm256_sub_ps(z, _mm256_cvtepi32_ps(zi));
        const __m256i base = _mm256_add_epi32(
            _mm256_add_epi32(_mm256_mullo_epi32(zi, vsz), _mm256_mullo_epi32(yi, vsy)), xi);
        const __m256i up_x = _mm256_castps_si256(_mm256_cmp_ps(fx, half, _CMP_GE_OQ)),
                      up_y = _mm256_castps_si256(_mm256_cmp_ps(fy, half, _CMP_GE_OQ)),
                      up_z = _mm256_castps_si256(_mm256_cmp_ps(fz, half, _CMP_GE_OQ));
        const __m256i near = _mm256_add_epi32(
            _mm256_add_epi32(base, _mm256_and_si256(up_x, one)),
            _mm256_add_epi32(_mm256_and_si256(up_y, vsy), _mm256_and_si256(up_z, vsz)));
        if (_mm256_movemask_epi8(_mm256_cmpgt_epi32(near, vlast)))
            return e; /* the rest, generic */
        const __m256i labels = _mm256_i32gather_epi32(lb, near, 2);
        const __m256i b_y = _mm256_add_epi32(base, vsy), b_z = _mm256_add_epi32(base, vsz),
                      b_yz = _mm256_add_epi32(b_y, vsz);
        const __m256 c00 = lerp8(gather8(img, base), gather8(img, _mm256_add_epi32(base, one)), fx);
        const __m256 c10 = lerp8(gather8(img, b_y), gather8(img, _mm256_add_epi32(b_y, one)), fx);
        const __m256 c01 = lerp8(gather8(img, b_z), gather8(img, _mm256_add_epi32(b_z, one)), fx);
        const __m256 c11 = lerp8(gather8(img, b_yz), gather8(img, _mm256_add_epi32(b_yz, one)), fx);
        const __m256 v = lerp8(lerp8(c00, c10, fy), lerp8(c01, c11, fy), fz);
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
