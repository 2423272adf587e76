/* SPDX-License-Identifier: Apache-2.0 */
/* Eight-lane float vectors (GCC/clang vector extensions) for the kernels.
 * The same source is compiled for the baseline target and, on x86-64, with
 * -mavx2; each variant performs the same IEEE operations in the same order
 * (no fused multiply-add), so results are bit-identical across variants. */
#ifndef POSE_RT_VEC_H
#define POSE_RT_VEC_H

#include <math.h>
#include <stdint.h>

#ifdef __AVX__
#  include <immintrin.h>
#endif

#if defined(__GNUC__) || defined(__clang__)
#  define POSE__INLINE inline __attribute__((always_inline))
#else
#  define POSE__INLINE inline
#endif

typedef float pose__v8f __attribute__((vector_size(32)));
typedef int32_t pose__v8i __attribute__((vector_size(32)));
typedef uint16_t pose__v8u16 __attribute__((vector_size(16)));
typedef int16_t pose__v8i16 __attribute__((vector_size(16)));
typedef uint8_t pose__v8u8 __attribute__((vector_size(8)));

#define V8_SPLAT(x) ((pose__v8f){(x), (x), (x), (x), (x), (x), (x), (x)})
/* Lane l takes base[idx[l] * stride + off]; idx points at 8 unsigned
 * indices in memory (read as scalars: address arithmetic stays in integer
 * registers instead of being extracted from a vector). */
#define V8_GATHER(base, idx, stride, off)                                           \
    ((pose__v8f){(base)[(size_t)(idx)[0] * (stride) + (off)],                       \
                 (base)[(size_t)(idx)[1] * (stride) + (off)],                       \
                 (base)[(size_t)(idx)[2] * (stride) + (off)],                       \
                 (base)[(size_t)(idx)[3] * (stride) + (off)],                       \
                 (base)[(size_t)(idx)[4] * (stride) + (off)],                       \
                 (base)[(size_t)(idx)[5] * (stride) + (off)],                       \
                 (base)[(size_t)(idx)[6] * (stride) + (off)],                       \
                 (base)[(size_t)(idx)[7] * (stride) + (off)]})
/* Flip the sign of w in the lanes where neg < 0 (exactly -w). */
#define V8_NEG_WHERE(w, neg)                                                        \
    ((pose__v8f)((pose__v8i)(w) ^ ((pose__v8i)((neg) < 0.0f) &                      \
                                   (pose__v8i)V8_SPLAT(-0.0f))))
/* Nonzero when some lane of the comparison mask m is set. */
#ifdef __AVX__
#  define V8_ANY(m) _mm256_movemask_ps((__m256)(m))
#else
#  define V8_ANY(m) (((m)[0] | (m)[1] | (m)[2] | (m)[3]) | ((m)[4] | (m)[5] | (m)[6] | (m)[7]))
#endif
/* Keep x where cond holds, else +0. */
#define V8_AND_MASK(x, cond) ((pose__v8f)((pose__v8i)(x) & (pose__v8i)(cond)))

#ifdef __AVX__
#  define V8_SQRT(x) ((pose__v8f)_mm256_sqrt_ps((__m256)(x)))
#else
#  define V8_SQRT(x)                                                                \
      ((pose__v8f){sqrtf((x)[0]), sqrtf((x)[1]), sqrtf((x)[2]), sqrtf((x)[3]),      \
                   sqrtf((x)[4]), sqrtf((x)[5]), sqrtf((x)[6]), sqrtf((x)[7])})
#endif

/* r = R(q) x - x = 2 (w (u x x) + u x (u x x)), u = q.xyz: exactly 0 when u = 0. */
#define V8_ROTDISP(rx, ry, rz, ux, uy, uz, uw, x, y, z)                             \
    do {                                                                            \
        pose__v8f cx_ = (uy) * (z) - (uz) * (y);                                    \
        pose__v8f cy_ = (uz) * (x) - (ux) * (z);                                    \
        pose__v8f cz_ = (ux) * (y) - (uy) * (x);                                    \
        pose__v8f dx_ = (uy) * cz_ - (uz) * cy_;                                    \
        pose__v8f dy_ = (uz) * cx_ - (ux) * cz_;                                    \
        pose__v8f dz_ = (ux) * cy_ - (uy) * cx_;                                    \
        (rx) = 2.0f * ((uw) * cx_ + dx_);                                           \
        (ry) = 2.0f * ((uw) * cy_ + dy_);                                           \
        (rz) = 2.0f * ((uw) * cz_ + dz_);                                           \
    } while (0)

#endif /* POSE_RT_VEC_H */
