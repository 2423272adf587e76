/* SPDX-License-Identifier: Apache-2.0 */
/* The dynamics' tet blocks (fem_dyn_tets.h): layout and the variants' choice. */
#include "fem_dyn_tets.h"

#include <string.h>

#include "rt_kernels.h"

void pose__fem_dyn_rot_reset(const pose__fem_mesh *m, pose__fem_dyn_rot *rot)
{
    const size_t nb = pose__fem_dyn_blocks(m);
    memset(rot, 0, nb * sizeof *rot);
    for (size_t k = 0; k < nb; k++)
        for (unsigned l = 0; l < POSE__FEM_LANES; l++)
            rot[k].q[3][l] = rot[k].r[0][l] = rot[k].r[4][l] = rot[k].r[8][l] = 1.0f;
}

void pose__fem_dyn_tets_build(const pose__fem_mesh *m, pose__fem_dyn_tets *tets,
                              pose__fem_dyn_rot *rot)
{
    const size_t nb = pose__fem_dyn_blocks(m);
    memset(tets, 0, nb * sizeof *tets); /* padding lanes: vertex 0, no stiffness */
    for (size_t t = 0; t < m->tet_count; t++) {
        const pose__fem_tet *s = &m->tets[t];
        pose__fem_dyn_tets *d = &tets[t / POSE__FEM_LANES];
        const size_t l = t % POSE__FEM_LANES;
        for (int k = 0; k < 4; k++)
            d->v[k][l] = s->v[k];
        for (int k = 0; k < 9; k++)
            d->b[k][l] = s->b[k];
        d->vmu[l] = s->vmu;
        d->vlambda[l] = s->vkappa - (2.0f / 3.0f) * s->vmu;
    }
    pose__fem_dyn_rot_reset(m, rot);
}

void pose__fem_dyn_set_skeletal(pose__fem_dyn_tets *tets, size_t t, int n, const uint32_t *joints,
                                const float *weights)
{
    pose__fem_dyn_tets *d = &tets[t / POSE__FEM_LANES];
    const size_t l = t % POSE__FEM_LANES;
    d->skeletal[l] = n > 0 ? UINT32_MAX : 0u;
    for (int i = 0; i < 4; i++) {
        d->joint[i][l] = i < n ? joints[i] : (n > 0 ? joints[0] : 0u);
        d->weight[i][l] = i < n ? weights[i] : 0.0f;
    }
}

void pose__fem_dyn_rotate(const pose__fem_dyn_tets *tets, pose__fem_dyn_rot *rot, const float *x,
                          const float *joint_q, const float *v, int steps, float twist, float *f,
                          float *kv, float *blk, uint32_t *flag, size_t b, size_t e)
{
#ifdef POSE__HAVE_AVX2_KERNELS
    if (pose__kernels_use_avx2()) {
        pose__fem_dyn_rotate_avx2(tets, rot, x, joint_q, v, steps, twist, f, kv, blk, flag, b, e);
        return;
    }
#endif
    pose__fem_dyn_rotate_generic(tets, rot, x, joint_q, v, steps, twist, f, kv, blk, flag, b, e);
}

void pose__fem_dyn_product(const pose__fem_dyn_tets *tets, const pose__fem_dyn_rot *rot,
                           const float *u, float *out, float *energy, size_t b, size_t e)
{
#ifdef POSE__HAVE_AVX2_KERNELS
    if (pose__kernels_use_avx2()) {
        pose__fem_dyn_product_avx2(tets, rot, u, out, energy, b, e);
        return;
    }
#endif
    pose__fem_dyn_product_generic(tets, rot, u, out, energy, b, e);
}
