/* SPDX-License-Identifier: Apache-2.0 */
/* The dynamics' per-tet passes (fem_dynamics.h), on the simulated tets laid
 * out eight to a block, lane-major (structure of arrays): a block's indices,
 * shape gradients and moduli, and its rotations, load as whole vectors and
 * its corner outputs store as whole vectors, where the quasi-static solver's
 * 64-byte records cost a gather per field and a transpose per output. Only
 * the vertex values are gathered. Padding lanes of the last block have zero
 * moduli and gradients: their outputs are zero and nobody reads them.
 *
 * Corner outputs are 8-lane rows per block: forces and products 12 rows
 * (corner k's component a in row 3k + a), stiffness blocks 24 rows (corner
 * k's xx xy xz yy yz zz in rows 6k..6k+5). pose__fem_dyn_corner gives where
 * a mesh corner's values start; they are POSE__FEM_LANES apart.
 *
 * The stress is plain co-rotated linear elasticity, volume term included
 * (tr(R^T F) - 3, not the quasi-static solver's det F): force and warped
 * stiffness R K0 R^T then agree up to R's own derivative, which
 * fem_dyn_twist.h adds where it is large (the det F term's curvature, left
 * out of its Gauss-Newton stiffness, is of the size of the volume stiffness
 * itself once a tet inverts, and backward Euler integrated it explicitly:
 * the body's swing blew up).
 *
 * Compiled once per instruction set (fem_dyn_tets_body.h), chosen at run
 * time as rt_kernels.h's; every variant does the same IEEE operations, so
 * the results do not depend on the CPU either. */
#ifndef POSE_FEM_DYN_TETS_H
#define POSE_FEM_DYN_TETS_H

#include <stddef.h>
#include <stdint.h>

#include "fem_mesh.h"

#define POSE__FEM_LANES 8u

/** Eight tets' constants: 768 bytes (a multiple of 32: blocks stay aligned). */
typedef struct pose__fem_dyn_tets {
    uint32_t v[4][8];   /**< vertex of corner k, per lane */
    float b[9][8];      /**< pose__fem_tet.b, per lane */
    float vmu[8];       /**< rest volume * mu */
    float vlambda[8];   /**< rest volume * lambda (= kappa - 2 mu / 3) */
    uint32_t skeletal[8];   /**< all bits set: the tet turns with the skeleton, else 0 */
    uint32_t joint[4][8];   /**< a skeletal tet's joints (pose__fem_dyn_set_skeletal) */
    float weight[4][8];     /**< and their weights (summing to 1; 0 for unused) */
} pose__fem_dyn_tets;

/** Floats from one joint's rotation to the next in pose__fem_dyn_rotate's
 *  joint_q (the skinning palette, rt_skin.h's pose__skin_joint). */
#define POSE__FEM_JOINT_STRIDE 16u

/** Eight tets' rotations: the quaternion the next extraction starts from
 *  and its matrix (row-major), 416 bytes. */
typedef struct pose__fem_dyn_rot {
    float q[4][8];
    float r[9][8];
} pose__fem_dyn_rot;

/** Blocks of the mesh's simulated tets. */
static inline size_t pose__fem_dyn_blocks(const pose__fem_mesh *m)
{
    return (m->tet_count + POSE__FEM_LANES - 1) / POSE__FEM_LANES;
}

/** Offset of mesh corner c (tet * 4 + corner) in a 12-row output, or, with
 *  rows 24, in the stiffness blocks. */
static inline size_t pose__fem_dyn_corner(uint32_t c, size_t rows)
{
    return (size_t)(c >> 5) * rows * POSE__FEM_LANES + (size_t)(c & 3u) * (rows / 4) * POSE__FEM_LANES +
           ((c >> 2) & 7u);
}

/** Lay the mesh's tets out in blocks; rotations identity. */
void pose__fem_dyn_tets_build(const pose__fem_mesh *m, pose__fem_dyn_tets *tets,
                              pose__fem_dyn_rot *rot);
/** Every rotation back to identity (a restart). */
void pose__fem_dyn_rot_reset(const pose__fem_mesh *m, pose__fem_dyn_rot *rot);

/**
 * Tet t turns with the skeleton: its R is the blend of joints' rotations
 * (n <= 4 joints with weights summing to 1; n = 0: its own deformation's,
 * the default) instead of the rotation extracted from its deformation
 * gradient. Its energy is then quadratic in x, R K0 R^T its exact Hessian
 * (no twist is flagged), and no motion of its own can make R jump. For what
 * is not tissue: the tets a coarse bake puts outside the skin (between limbs
 * that touch, around the surface), which deep flexion stretches several
 * times over and turns inside out, where the extracted rotation changed
 * branch every few steps and the body never came to rest.
 */
void pose__fem_dyn_set_skeletal(pose__fem_dyn_tets *tets, size_t t, int n, const uint32_t *joints,
                                const float *weights);

/**
 * Blocks [b, e): rotations at x (at most `steps` extraction steps from the
 * last ones; for skeletal tets the blend of their joints' quaternions
 * {x y z w} at joint_q + POSE__FEM_JOINT_STRIDE j, read only when the blocks
 * have one), the elastic corner forces of co-rotated linear elasticity at x
 * into f, the products K v with the new rotations into kv (12 rows each),
 * the corners' diagonal stiffness blocks into blk (24 rows), and into flag
 * (one row of 8 per block) all bits set for each tet whose twist stiffness,
 * which K leaves out, may exceed (1 + twist) 2 vmu (fem_dyn_twist.h), else 0.
 */
void pose__fem_dyn_rotate(const pose__fem_dyn_tets *tets, pose__fem_dyn_rot *rot, const float *x,
                          const float *joint_q, const float *v, int steps, float twist, float *f,
                          float *kv, float *blk, uint32_t *flag, size_t b, size_t e);
/**
 * Blocks [b, e): corner products K u with the last rotations into out (12
 * rows), and each tet's u^T K u into energy (one row of 8 per block).
 */
void pose__fem_dyn_product(const pose__fem_dyn_tets *tets, const pose__fem_dyn_rot *rot,
                           const float *u, float *out, float *energy, size_t b, size_t e);

/* The variants behind the two above. */
#define POSE__FEM_DYN_VARIANT_DECL(sfx)                                                          \
    void pose__fem_dyn_rotate_##sfx(const pose__fem_dyn_tets *tets, pose__fem_dyn_rot *rot,      \
                                    const float *x, const float *joint_q, const float *v,         \
                                    int steps, float twist, float *f, float *kv, float *blk,     \
                                    uint32_t *flag, size_t b, size_t e);                         \
    void pose__fem_dyn_product_##sfx(const pose__fem_dyn_tets *tets,                             \
                                     const pose__fem_dyn_rot *rot, const float *u, float *out,   \
                                     float *energy, size_t b, size_t e);
POSE__FEM_DYN_VARIANT_DECL(generic)
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
POSE__FEM_DYN_VARIANT_DECL(avx2)
#endif

#endif /* POSE_FEM_DYN_TETS_H */
