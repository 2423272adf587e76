/* SPDX-License-Identifier: Apache-2.0 */
/* Compiler helpers for the kernels. */
#ifndef POSE_RT_SIMD_H
#define POSE_RT_SIMD_H

#if defined(__GNUC__) || defined(__clang__)
#  define POSE__INLINE inline __attribute__((always_inline))
#else
#  define POSE__INLINE inline
#endif

#endif /* POSE_RT_SIMD_H */
