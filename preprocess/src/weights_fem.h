/* SPDX-License-Identifier: Apache-2.0
 *
 * Harmonic skinning weights on the tet mesh (design §2). For each joint j,
 * Laplace's equation with linear tets: the stiffness matrix
 * A_ab = Σ_t V_t ∇φ_a·∇φ_b, Dirichlet W_j = 1 on the vertices of tets
 * labelled bone j and 0 on those of other bones. The free-vertex block of A
 * is the same SPD matrix for every joint: CHOLMOD factors it once (fill-
 * reducing ordering, supernodal when it pays) and solves all joints' right-
 * hand sides together as a dense multi-column block.
 *
 * Vertices touching two bones' tets (bones that meet in the voxel image)
 * take the bone with more incident tets. Free regions that reach no bone
 * (islands of soft tissue) would make A singular; each is pinned to the
 * joint of the nearest bone vertex and counted in the report.
 */
#ifndef POSE_PP_WEIGHTS_FEM_H
#define POSE_PP_WEIGHTS_FEM_H

#include "pp_types.h"

#include <pose/pose.h>

#include <stddef.h>
#include <stdint.h>

#define PP_MAX_INFLUENCES 8

typedef struct pp_weight_options {
    unsigned influences; /**< K kept per vertex, 1..8; 0 = 4 */
    unsigned block;      /**< right-hand sides per solve; 0 = all joints at once */
    int plain_fem;       /**< keep obtuse tets' positive Laplacian entries (the plain FEM
                              operator: weights may leave [0, 1], then are clamped); 0 =
                              lump them onto the diagonal (weights_matrix.h) */
} pp_weight_options;

typedef struct pp_weights {
    unsigned influences;
    size_t vertex_count;
    uint16_t *joints; /**< K * vertex_count, strongest first */
    float *weights;   /**< K * vertex_count, >= 0, summing to 1 */
} pp_weights;

/** What the solve found; the checks the design asks for (maximum principle,
 *  partition of unity) are measured on the raw solution, before top-K. */
typedef struct pp_weight_report {
    size_t free_vertices, fixed_vertices;
    size_t conflict_vertices;   /**< touching tets of two bones */
    size_t floating_regions, floating_vertices; /**< pinned islands */
    size_t empty_joints;        /**< joints with no bone tet (their weight is 0) */
    size_t factor_nnz;
    int supernodal;
    double min_weight;          /**< raw minimum (>= -tiny: maximum principle) */
    double max_weight;          /**< raw maximum (<= 1 + tiny) */
    double max_sum_error;       /**< max |Σ_j W_j - 1| over vertices (raw) */
    double max_dropped;         /**< largest weight removed by keeping K */
    size_t clipped_entries;     /**< positive off-diagonal Laplacian entries (obtuse tets)
                                     moved to the diagonal to keep the maximum principle
                                     (weights_matrix.h) */
    double seconds_assemble, seconds_factor, seconds_solve;
} pp_weight_report;

/**
 * Compute weights for joints 0..joint_count-1 on a labelled tet mesh
 * (labels 0 soft, j + 1 bone of joint j). Fails with a message when a label
 * names no joint, no tet is labelled bone, or the factorization fails.
 */
int pp_weights_compute(const pp_tetmesh *mesh, size_t joint_count, const pp_weight_options *opt,
                       pp_weights *out, pp_weight_report *report, char *err, size_t err_size);
void pp_weights_free(pp_weights *w);

/** Weight of joint j at vertex v (0 when not among its K). */
float pp_weights_get(const pp_weights *w, size_t v, unsigned joint);

#endif /* POSE_PP_WEIGHTS_FEM_H */
