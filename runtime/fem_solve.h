/* SPDX-License-Identifier: Apache-2.0 */
/* Quasi-static co-rotational FEM (design §2, Sujar et al. §5): from a
 * skinned pose, held vertices stay where skinning put them and the free ones
 * move to the elastic equilibrium. Each outer iteration takes every tet's
 * rotation from the polar decomposition of its deformation gradient, then
 * solves the warped linear system K_R dx = f(x) by Jacobi-preconditioned
 * conjugate gradients, matrix-free (one pass over the tets per product).
 *
 * Deterministic for any thread count: per-tet work writes its own corner
 * forces, vertices gather their corners in a fixed order, and dot products
 * are summed per chunk of POSE__FEM_CHUNK vertices, then chunk after chunk. */
#ifndef POSE_FEM_SOLVE_H
#define POSE_FEM_SOLVE_H

#include <stddef.h>
#include <stdint.h>

#include "fem_links.h"
#include "fem_mesh.h"
#include "rt_pool.h"

typedef struct pose__fem_params {
    int outer_iterations;  /**< co-rotational updates, >= 1 */
    int cg_iterations;     /**< most CG iterations per outer iteration */
    float tolerance;       /**< stop when |r| <= tolerance * |r| of the first outer iteration */
    float gravity[3];      /**< acceleration, rig units / s^2 */
    /** Couplings (pose.h pose_fem_coupling), or NULL: per vertex the
     *  stiffness of a zero-length spring pulling a free vertex toward
     *  target (3 per vertex; read where spring > 0). */
    const float *spring;
    const float *target;
    /** Soft-soft couplings (fem_links.h), or NULL; every end a free vertex. */
    const pose__fem_links *links;
} pose__fem_params;

typedef struct pose__fem_stats {
    int outer_iterations;
    int cg_iterations;         /**< summed over outer iterations */
    double residual;           /**< final |r| / first |r| (0 when the first was 0) */
    double seconds_rotations;  /**< polar decompositions and residual forces */
    double seconds_cg;         /**< CG iterations */
} pose__fem_stats;

/** Scratch a state keeps for the solver; pose__fem_work_size bytes. */
typedef struct pose__fem_work {
    float *rot;      /**< 20 per tet: rotation, cofactor of F (row-major), J - 1, pad */
    float *quat;     /**< 4 per tet: last rotation, where the next polar decomposition starts */
    float *corner;   /**< 12 per tet: corner forces of the last pass */
    float *dblk;     /**< 24 per tet: the corners' 3x3 stiffness blocks (6 each) */
    float *pre;      /**< 6 per vertex: inverse diagonal block (block Jacobi) */
    float *r, *z, *p, *ap; /**< 3 per vertex */
    float *gvol;     /**< 3 per vertex: gradient of the surface's volume */
    float *sgrad;    /**< 3 per surface vertex: the same per surface vertex */
    double *spos;    /**< 3 per surface vertex: its position (volume gradient) */
    double *partial; /**< 4 per chunk */
} pose__fem_work;

size_t pose__fem_work_size(const pose__fem_mesh *mesh);
/** Lay the work arrays out in `memory` and set every tet's rotation to identity. */
void pose__fem_work_init(const pose__fem_mesh *mesh, void *memory, pose__fem_work *out);
/** Reset the rotations the polar decompositions start from (pose_reset). */
void pose__fem_work_reset(const pose__fem_mesh *mesh, pose__fem_work *work);

/**
 * Move the free vertices of x (3 per vertex, interleaved) to the
 * equilibrium; held vertices are not written. pool may be NULL (caller
 * only). Allocates nothing.
 */
void pose__fem_solve(const pose__fem_mesh *mesh, pose__fem_work *work, pose__pool *pool,
                     const pose__fem_params *params, float *x, pose__fem_stats *stats);

/* ---- Pieces the dynamics (fem_dynamics.c) share. */

/** The skin volume term's gradient at x into work->gvol (serial); returns
 *  its force factor -stiffness (V - V0) (0 without a surface). */
double pose__fem_volume_gradient(const pose__fem_mesh *mesh, pose__fem_work *work, const float *x);
/** Vertex v's 3x3 stiffness block (xx xy xz yy yz zz), summed over its
 *  corners' blocks in work->dblk in the fixed corner order. */
void pose__fem_vertex_block(const pose__fem_mesh *mesh, const float *dblk, size_t v, double k[6]);
/** Inverse of a symmetric 3x3 block; -1 (out untouched) when singular. */
int pose__fem_invert_block(const double k[6], float out[6]);

/** Sum of vertex v's corner values (3 each) in the fixed corner order. */
static inline void pose__fem_gather(const pose__fem_mesh *m, const float *corner, size_t v,
                                    float out[3])
{
    float s[3] = {0, 0, 0};
    for (uint32_t k = m->corner_offset[v]; k < m->corner_offset[v + 1]; k++) {
        const float *f = corner + 3 * (size_t)m->corners[k];
        s[0] += f[0];
        s[1] += f[1];
        s[2] += f[2];
    }
    out[0] = s[0];
    out[1] = s[1];
    out[2] = s[2];
}

/** z = B r for a symmetric block B (6 floats). */
static inline void pose__fem_apply_block(const float *pre, const float r[3], float z[3])
{
    z[0] = pre[0] * r[0] + pre[1] * r[1] + pre[2] * r[2];
    z[1] = pre[1] * r[0] + pre[3] * r[1] + pre[4] * r[2];
    z[2] = pre[2] * r[0] + pre[4] * r[1] + pre[5] * r[2];
}

/** Elastic forces on every vertex at x with every tet's rotation taken
 *  from x (polar decomposition; not masked by held vertices). For tests. */
void pose__fem_forces(const pose__fem_mesh *mesh, pose__fem_work *work, const float *x,
                      float *forces);

#endif /* POSE_FEM_SOLVE_H */
