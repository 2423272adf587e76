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
 * The fast path exploits sparsity: s is non-zero only when both weight
 * vectors share two joints. Tets with fewer than two joints are dropped;
 * the rest are clustered by joint set and weights quantized to `tolerance`
 * (volume-weighted mean weights, summed V and V·c per cluster); clusters
 * are listed per joint pair, and a vertex visits only the clusters of its
 * own pairs, each once. Vertices whose quantized weights coincide share
 * one evaluation. Work is split across threads by vertex ranges.
 */
#ifndef POSE_PP_COR_FAST_H
#define POSE_PP_COR_FAST_H

#include "pp_types.h"
#include "weights_fem.h"

typedef struct pp_cor_options {
    double sigma;     /**< σ; 0 = 0.1 */
    double tolerance; /**< weight quantum for clustering; 0 = 1e-4 (max deviation from the
                           direct formula ~1e-4 of the model size); < 0 = no clustering */
    int threads;      /**< <= 1 runs on the caller's thread */
} pp_cor_options;

typedef struct pp_cor_report {
    size_t vertices_with_cor; /**< vertices with two or more joints */
    size_t tets_used;         /**< tets with two or more joints */
    size_t clusters;          /**< tet clusters after quantization */
    size_t evaluations;       /**< distinct vertex weight vectors evaluated */
    double seconds;
} pp_cor_report;

/** Fast centres into cor[3 * vertex_count]. */
int pp_cor_compute(const pp_tetmesh *mesh, const pp_weights *w, const pp_cor_options *opt,
                   float *cor, pp_cor_report *rep, char *err, size_t err_size);

/** The direct O(vertices x tets) formula, for tests and small meshes. */
int pp_cor_naive(const pp_tetmesh *mesh, const pp_weights *w, double sigma, float *cor);

#endif /* POSE_PP_COR_FAST_H */
