/* SPDX-License-Identifier: Apache-2.0 */
/* Soft-soft couplings (pose.h pose_fem_soft_coupling; Otaduy et al. §4.2,
 * §5.2): zero-length springs between a simulated vertex a and a point of
 * the tet mesh p = sum_c w_c x_c (up to 4 corners: a node pair is one
 * corner of weight 1, a point inside another part's tet its 4 corners
 * with their barycentric weights, so the spring has zero length at rest).
 * Energy 1/2 k |x_a - p|^2, so with d = y_a - p(y) the stiffness product
 * K_l y is k d at a and -k w_c d at corner c; its diagonal blocks k and
 * k w_c^2 go into the block preconditioners.
 *
 * Products are formed by one thread, spring after spring, between the
 * solvers' parallel passes (springs are few: a scatter in a fixed order
 * gives the same bits for any thread count, and the passes may then read
 * any vertex's product). */
#ifndef POSE_FEM_LINKS_H
#define POSE_FEM_LINKS_H

#include <stddef.h>
#include <stdint.h>

typedef struct pose__fem_links {
    size_t count;            /**< springs */
    const uint32_t *node;    /**< count: the vertex a */
    const uint32_t *corner;  /**< 4 per spring: the point's corners (weight 0: unused) */
    const float *weight;     /**< 4 per spring: their weights, summing to 1 */
    const float *k;          /**< per spring: stiffness */
    size_t touched_count;    /**< vertices a spring reaches (a node or a weighted corner) */
    const uint32_t *touched; /**< ascending */
    const float *diag;       /**< per mesh vertex: the springs' share of its block's
                                  diagonal (0 where none reaches) */
    /** Scratch, 3 per mesh vertex each, zero where no spring reaches: the
     *  products the solvers form (K_l x and K_l v in the dynamics'
     *  assembly, then K_l u per CG iteration). */
    float *out, *out2;
} pose__fem_links;

/** out = K_l (a + s b) at the touched vertices (b may be NULL: K_l a). */
void pose__fem_links_product(const pose__fem_links *l, const float *a, const float *b, float s,
                             float *out);

#endif /* POSE_FEM_LINKS_H */
