/* SPDX-License-Identifier: Apache-2.0
 *
 * Assembly of the FEM Laplacian for weights_fem.c: the free-vertex block as
 * an upper-triangular CHOLMOD matrix, and the coupling to fixed (bone)
 * vertices as a sparse list from which right-hand sides are scattered.
 */
#ifndef POSE_PP_WEIGHTS_MATRIX_H
#define POSE_PP_WEIGHTS_MATRIX_H

#include "pp_types.h"

#include <cholmod.h>
#include <stdint.h>

/** One coupling term: rhs[row, joint] -= value (W_joint = 1 on that bone vertex). */
typedef struct pp_coupling {
    uint32_t row;   /**< free-vertex index */
    uint32_t joint;
    double value;   /**< A_row,fixed */
} pp_coupling;

typedef struct pp_laplacian {
    cholmod_sparse *A;     /**< n_free x n_free, stype = 1 (upper part stored) */
    pp_coupling *coupling; /**< one term per (row, joint), all <= 0 */
    size_t coupling_count;
    size_t clipped;        /**< positive off-diagonal entries moved to the diagonal */
} pp_laplacian;

/**
 * Assemble with linear shape functions: A_ab = Σ_t V_t ∇φ_a·∇φ_b, then,
 * with lump_obtuse, make it an M-matrix: each positive off-diagonal entry (an obtuse tet's
 * edge) is moved onto the diagonal of its rows, keeping zero row sums, so
 * the solution obeys the discrete maximum principle (weights in [0, 1]).
 * free_index[v] is the vertex's row among the free vertices, or -1 for a
 * fixed vertex whose joint is fixed_joint[v]. Degenerate tets contribute
 * nothing. Returns 0 on success, -1 when out of memory.
 */
int pp_laplacian_assemble(const pp_tetmesh *m, const int32_t *free_index, size_t n_free,
                          const int32_t *fixed_joint, int lump_obtuse, pp_laplacian *out,
                          cholmod_common *c);
void pp_laplacian_free(pp_laplacian *l, cholmod_common *c);

/** Local stiffness of one tet: k[a][b] = V ∇φ_a·∇φ_b; returns V (0 if degenerate). */
double pp_tet_local_stiffness(const float *p0, const float *p1, const float *p2, const float *p3,
                        double k[4][4]);

#endif /* POSE_PP_WEIGHTS_MATRIX_H */
