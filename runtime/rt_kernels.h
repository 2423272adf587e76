/* SPDX-License-Identifier: Apache-2.0 */
/* Kernel variants (rt_kernels_body.h compiled per target) and their choice. */
#ifndef POSE_RT_KERNELS_H
#define POSE_RT_KERNELS_H

#include <stddef.h>
#include <stdint.h>

#include "rt_skin.h"
#include "rt_transfer.h"

void pose__skin_blocks_generic(int method, const pose__skin_mesh *m,
                               const pose__skin_joint *palette, size_t begin, size_t end,
                               float *out);
size_t pose__transfer_blocks_generic(const pose__transfer_mesh *m, const float *tp,
                                     size_t begin, size_t end, float *pos, float *nrm,
                                     uint32_t *flagged);
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#  define POSE__HAVE_AVX2_KERNELS 1
void pose__skin_blocks_avx2(int method, const pose__skin_mesh *m,
                            const pose__skin_joint *palette, size_t begin, size_t end,
                            float *out);
size_t pose__transfer_blocks_avx2(const pose__transfer_mesh *m, const float *tp, size_t begin,
                                  size_t end, float *pos, float *nrm, uint32_t *flagged);
#endif

/** 1 when the AVX2 variant is to be used (built, supported, not forced off). */
int pose__kernels_use_avx2(void);

#endif /* POSE_RT_KERNELS_H */
