/* SPDX-License-Identifier: Apache-2.0 */
#include "rt_skin.h"

#include "rt_kernels.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

static int g_force_generic;

#ifdef POSE__HAVE_AVX2_KERNELS
/* POSE_KERNELS=generic in the environment forces the generic variant too,
 * so a whole test suite or benchmark can be run through it on an AVX2
 * machine. Read once (-1: not yet). */
static _Atomic int g_env_generic = -1;

static int env_generic(void)
{
    int v = atomic_load_explicit(&g_env_generic, memory_order_relaxed);
    if (v < 0) {
        const char *e = getenv("POSE_KERNELS");
        v = e && !strcmp(e, "generic");
        atomic_store_explicit(&g_env_generic, v, memory_order_relaxed);
    }
    return v;
}
#endif

void pose__kernels_force_generic(int on)
{
    g_force_generic = on;
}

int pose__kernels_use_avx2(void)
{
#ifdef POSE__HAVE_AVX2_KERNELS
    return !g_force_generic && !env_generic() && __builtin_cpu_supports("avx2");
#else
    return 0;
#endif
}

const char *pose__kernels_variant(void)
{
    return pose__kernels_use_avx2() ? "avx2" : "generic";
}

void pose__skin_palette(size_t joint_count, const pose__xform *skin, pose__skin_joint *out)
{
    for (size_t j = 0; j < joint_count; j++) {
        const pose__xform *x = &skin[j];
        pose__skin_joint *p = &out[j];
        for (int c = 0; c < 4; c++)
            p->q[c] = x->q[c];
        for (int c = 0; c < 3; c++)
            p->t[c] = x->t[c];
        p->t[3] = 0.0f;
        const float t[4] = {x->t[0], x->t[1], x->t[2], 0.0f};
        pose__quat_mul(p->d, t, x->q);
        for (int c = 0; c < 4; c++) {
            p->d[c] *= 0.5f;
            p->pad[c] = 0.0f;
        }
    }
}

void pose__skin(int method, const pose__skin_mesh *mesh, const pose__skin_joint *palette,
                size_t begin, size_t end, float *out)
{
    if (begin >= end)
        return;
#ifdef POSE__HAVE_AVX2_KERNELS
    if (pose__kernels_use_avx2()) {
        pose__skin_blocks_avx2(method, mesh, palette, begin, end, out);
        return;
    }
#endif
    pose__skin_blocks_generic(method, mesh, palette, begin, end, out);
}

size_t pose__skin_bytes(int method, const pose__skin_mesh *m)
{
    size_t bytes = 0;
    for (size_t b = 0; b < m->block_count; b++) {
        size_t kb = m->active[b];
        bytes += 1 + 3 * POSE__BLOCK * 4 /* rest */ + 3 * POSE__BLOCK * 4 /* out */;
        bytes += kb * POSE__BLOCK * 2; /* joints */
        if (kb > 1) {
            bytes += kb * POSE__BLOCK * 2; /* weights */
            if (method == POSE__SKIN_COR)
                bytes += 3 * POSE__BLOCK * 4;
        }
    }
    return bytes;
}
