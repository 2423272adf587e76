/* SPDX-License-Identifier: Apache-2.0 */
/* The dynamics' tet passes compiled with -mavx2 (runtime/CMakeLists.txt);
 * called only when the CPU has AVX2. Empty on other architectures. */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#  define POSE__KV(name) name##_avx2
#  include "fem_dyn_tets_body.h"
#else
typedef int pose__no_avx2_fem_kernels; /* ISO C wants a non-empty file */
#endif
