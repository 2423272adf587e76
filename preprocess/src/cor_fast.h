/* SPDX-License-Identifier: Apache-2.0
 *
 * Centres of rotation per tet vertex (Le & Hodgins 2016, adapted to tets as
 * in design §2):
 *   s(wp, ws) = Σ_{i≠j} wp_i wp_j ws_i ws_j exp(-(wp_i ws_j - ws_i wp_j)² / σ²)
 *   cor_p = Σ_t s(wp, w̄_t) V_t c_t / Σ_t s(wp, w̄_t) V_t
 * with w̄_t the mean of the tet's vertex weights, V_t its volume, c_t its
 * centroid. Vertices bound to one joint (and any vertex whose sums vanish)
 * get their own position: they move rigidly, where any centre is exact.
 *
 * The fast path exploits sparsity and the formula's structure. s is a sum
 * over joint pairs (i, j) shared by both vectors, and each pair's term
 * depends on the tet only through (w̄_i, w̄_j). So tets are grouped by joint
 * pair (a tet with joints {a,b,c} joins pairs ab, ac, bc; tets with one joint
 * join none) and, within a pair, binned on a grid of (w̄_i, w̄_j) with step
 * `tolerance`. Each bin keeps Σ V, Σ V c, its volume-weighted mean weights
 * and the first moments Σ V c (w̄ - mean), so the term is evaluated once
 * per bin with a first-order correction: the binning error is second order
 * in the step. The vertex side is binned the same way: per pair, vertices
 * whose (w_i, w_j) share a cell share one evaluation at their mean, with the
 * derivatives along w_i, w_j for each vertex's own offset. Evaluations grow
 * with (pairs x bins x cells), which saturates, not with the mesh size.
 * Cells are split across threads.
 */
#ifndef POSE_PP_COR_FAST_H
#define POSE_PP_COR_FAST_H

#include "pp_types.h"
#include "weights_fem.h"

typedef struct pp_cor_options {
    double sigma;     /**< σ; 0 = 0.1 */
    double tolerance; /**< bin step in weight space; 0 = 1/128 (deviation from the direct
                           formula ~2e-5 of the model size on the test bars); < 0 = exact (one bin per
                           distinct weight pair: the direct formula, reordered) */
    double cell_tolerance; /**< vertex cell step; 0 = tolerance */
    int threads;      /**< <= 1 runs on the caller's thread */
} pp_cor_options;

typedef struct pp_cor_report {
    size_t vertices_with_cor; /**< vertices with two or more joints */
    size_t tets_used;         /**< tets with two or more joints */
    size_t pairs;             /**< joint pairs that occur in some tet */
    size_t bins;              /**< (pair, tet weight cell) bins */
    size_t cells;             /**< (pair, vertex weight cell) evaluations */
    size_t evaluations;       /**< pair terms evaluated in all */
    double seconds;
} pp_cor_report;

/** Fast centres into cor[3 * vertex_count]. */
int pp_cor_compute(const pp_tetmesh *mesh, const pp_weights *w, const pp_cor_options *opt,
                   float *cor, pp_cor_report *rep, char *err, size_t err_size);

/** The direct O(vertices x tets) formula, for tests and small meshes. */
int pp_cor_naive(const pp_tetmesh *mesh, const pp_weights *w, double sigma, float *cor);
/** The direct formula for `count` chosen vertices (cor[3 * i] for vertices[i]);
 *  vertices = NULL means 0..count-1. For spot checks on large meshes. */
int pp_cor_naive_vertices(const pp_tetmesh *mesh, const pp_weights *w, double sigma,
                          const uint32_t *vertices, size_t count, float *cor);

#endif /* POSE_PP_COR_FAST_H */
