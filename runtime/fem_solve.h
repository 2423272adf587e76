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

#include "fem_mesh.h"
#include "rt_pool.h"

typedef struct pose__fem_params {
    int outer_iterations;  /**< co-rotational updates, >= 1 */
    int cg_iterations;     /**< most CG iterations per outer iteration */
    float tolerance;       /**< stop when |r| <= tolerance * |r| of the first outer iteration */
    float gravity[3];      /**< acceleration, rig units / s^2 */
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

/** Elastic forces on every vertex at x with every tet's rotation taken
 *  from x (polar decomposition; not masked by held vertices). For tests. */
void pose__fem_forces(const pose__fem_mesh *mesh, pose__fem_work *work, const float *x,
                      float *forces);

#endif /* POSE_FEM_SOLVE_H */
