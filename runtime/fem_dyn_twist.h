/* SPDX-License-Identifier: Apache-2.0 */
/* The rotation's derivative in the dynamics' stiffness, for the tets that
 * need it (McAdams et al. 2011; Smith et al. 2019, "Analytic eigensystems
 * for isotropic distortion energies").
 *
 * The co-rotated force is the exact gradient of its energy, but the warped
 * stiffness R K0 R^T leaves out dR/dx. In the frame of S = R^T F (R as
 * Irving's, maximizing tr(R^T F), so an inverted tet's S has one negative
 * eigenvalue) the energy's Hessian differs from R K0 R^T only in the three
 * twists R [n]x (n one of S's axes): R K0 R^T gives them no stiffness, the
 * energy 2 mu + c / s_k with s_k = tr S - sigma_k (the sum of the other two
 * sigmas) and c = 2 lambda (tr S - 3) - 4 mu. A tet stretched in volume
 * (c > 0) and flattened (s_k -> 0) has an unbounded twist stiffness, which
 * backward Euler then integrated explicitly: a vertex flipping every step.
 *
 * So for every flagged tet (fem_dyn_tets.h: those whose twist stiffness
 * may exceed (1 + POSE__FEM_TWIST) 2 mu V) the step adds the twists' terms,
 * projected to be positive semi-definite (negative ones left out): with w
 * the axial vector of skew(R^T grad u), the tet's stress in the product
 * gains R [K w]x (corner k: R [K w]x g_k) with the 3x3 symmetric
 * K = sum_k max(0, V (2 mu + c / s_k)) n_k n_k^T, and u^T K u gains
 * 2 w^T K w. A flagged tet whose R is a saddle of tr(R^T F)
 * (some s_k <= 0, where the extraction stops too) has the next step's
 * extraction start at the maximum. Scalar code shared by every kernel
 * variant, run per group of blocks inside the passes that own their rows,
 * before the vertex sums: the same bits for any variant and thread count. */
#ifndef POSE_FEM_DYN_TWIST_H
#define POSE_FEM_DYN_TWIST_H

#include <stddef.h>
#include <stdint.h>

#include "fem_dyn_tets.h"

/** Flag threshold: a tet's twists are added when their stiffness may exceed
 *  (1 + POSE__FEM_TWIST) times its shear stiffness 2 mu V. On the baked
 *  body 16 flags tens to about 1200 of its 26 k soft tets per step (4
 *  flagged three to ten times more and took 12 % more CG iterations; with
 *  64 the knees did not settle). */
#define POSE__FEM_TWIST 16.0f

/** One flagged tet: its index and K (xx xy xz yy yz zz, in S's frame). */
typedef struct pose__fem_twist {
    uint32_t tet;
    float k[6];
    float pad;
} pose__fem_twist;

/**
 * Blocks [b, e) after pose__fem_dyn_rotate: for every tet whose flag is set,
 * its K into list (in tet order; returns how many, at most 8 (e - b)), its
 * K v added to kv and its corners' diagonal blocks to blk.
 */
size_t pose__fem_dyn_twist_build(const pose__fem_dyn_tets *tets, pose__fem_dyn_rot *rot,
                                 const uint32_t *flag, const float *x, const float *v, float *kv,
                                 float *blk, size_t b, size_t e, pose__fem_twist *list);
/** The n listed tets' K u added to out (12 rows per block) and their
 *  u^T K u to energy (per tet). */
void pose__fem_dyn_twist_product(const pose__fem_dyn_tets *tets, const pose__fem_dyn_rot *rot,
                                 const pose__fem_twist *list, size_t n, const float *u, float *out,
                                 float *energy);

#endif /* POSE_FEM_DYN_TWIST_H */
