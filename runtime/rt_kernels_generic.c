/* SPDX-License-Identifier: Apache-2.0 */
/* Kernels for the baseline target (SSE2 on x86-64, whatever the compiler
 * targets elsewhere). */
#define POSE__KV(name) name##_generic
#include "rt_kernels_body.h"
