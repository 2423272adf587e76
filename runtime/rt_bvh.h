/* SPDX-License-Identifier: Apache-2.0 */
/* A bounding-volume hierarchy over triangles whose vertices move: the tree's
 * topology is built once (at rest, sdk/src/contact_build.c), its boxes are
 * refitted to the posed vertices every frame, and queries run on it:
 * triangle pairs that intersect (within one tree or between two), the
 * winding number of a point (a ray along +x), and the nearest point.
 * Everything here reads the tree and writes nothing shared, so queries
 * split by part run in parallel and count the same whatever the thread
 * count. */
#ifndef POSE_RT_BVH_H
#define POSE_RT_BVH_H

#include <stddef.h>
#include <stdint.h>

/** Triangles per leaf at most. */
#define POSE__BVH_LEAF 4
/** Deepest tree the builder makes (the query stacks are sized by it). */
#define POSE__BVH_MAX_DEPTH 48

/** A node: a leaf holds items[first .. first + count), an inner node
 *  (count 0) has its children at first and first + 1. Nodes are stored
 *  parents before children. */
typedef struct pose__bvh_node {
    float lo[3], hi[3];
    uint32_t first, count;
} pose__bvh_node;

typedef struct pose__bvh {
    pose__bvh_node *nodes;
    uint32_t node_count;
    const uint32_t *triangles; /**< 3 per triangle, indices into the positions */
    uint32_t *items;           /**< triangle ids, leaf by leaf */
    uint32_t *leaves;          /**< the leaf nodes' indices (refit splits them by part) */
    uint32_t leaf_count;
    /** Optional (pose__bvh_index_corners): each leaf's triangles' distinct
     *  corners, leaf k's from corners[corner_begin[k]] to corners[corner_begin[k + 1]],
     *  so that the refit reads each vertex once; NULL: it reads triangles. */
    uint32_t *corner_begin, *corners;
    /** Self-intersection work split for threads: task i < split_pairs is
     *  the pair (children of inner node split_nodes[i]); the rest are the
     *  subtrees split_nodes[i] tested against themselves. Together they
     *  cover every pair of the tree once. */
    uint32_t *split_nodes;
    uint32_t split_pairs, split_count;
} pose__bvh;

/** Boxes of the leaves [begin, end) of leaves[] around the posed vertices
 *  (their distinct corners, where the tree has them). */
void pose__bvh_refit_leaves(pose__bvh *t, const float *positions, size_t begin, size_t end);
/** Boxes of the inner nodes from their children (after every leaf). */
void pose__bvh_refit_inner(pose__bvh *t);

/** Pairs of triangles of `t` that intersect and share no vertex, in the
 *  self-intersection task `task` (0 .. split_count - 1). */
size_t pose__bvh_self_task(const pose__bvh *t, const float *positions, uint32_t task);

/** A node whose triangles are not all of one part (pose__bvh_node_parts). */
#define POSE__BVH_MIXED UINT32_MAX

/** The part of each node of t: the part all its triangles share (tri_part,
 *  per triangle id, none POSE__BVH_MIXED), or POSE__BVH_MIXED. node_part
 *  holds node_count entries. */
void pose__bvh_node_parts(const pose__bvh *t, const uint32_t *tri_part, uint32_t *node_part);

/** As pose__bvh_self_task, counting only pairs of triangles of different
 *  parts; nodes of one part are not opened against themselves or each
 *  other (bone meshes against each other: the pairs within one bone are
 *  never looked at). */
size_t pose__bvh_self_task_parts(const pose__bvh *t, const float *positions, uint32_t task,
                                 const uint32_t *tri_part, const uint32_t *node_part);

/** Winding number at p of the triangles of t (a ray along +x). */
int pose__bvh_winding(const pose__bvh *t, const float *positions, const float *p);

/** As pose__bvh_winding, by the ray from p along d (any non-zero direction). */
int pose__bvh_winding_along(const pose__bvh *t, const float *positions, const float *p, const float *d);

/** Features of a triangle a nearest point lies on (vertex k, the edge from
 *  vertex k to k + 1, the inside): they choose its pseudo-normal. */
enum {
    POSE__NEAR_V0, POSE__NEAR_V1, POSE__NEAR_V2,
    POSE__NEAR_E01, POSE__NEAR_E12, POSE__NEAR_E20,
    POSE__NEAR_FACE,
};

/** The nearest point of a tree's triangles to a point. */
typedef struct pose__bvh_near {
    float point[3];
    uint32_t triangle; /**< UINT32_MAX when none is within reach */
    int feature;       /**< POSE__NEAR_* */
} pose__bvh_near;

/** Distance from p to the nearest triangle of t within max_dist (INFINITY
 *  and out->triangle = UINT32_MAX when none is). rt_bvh_nearest.c. */
float pose__bvh_nearest(const pose__bvh *t, const float *positions, const float *p, float max_dist,
                        pose__bvh_near *out);

/** Whether a triangle of t lies nearer to p than max_dist: exactly when
 *  pose__bvh_nearest(t, positions, p, max_dist, ...) finds one, but it
 *  stops at the first (nearer children first). rt_bvh_nearest.c. */
int pose__bvh_any_within(const pose__bvh *t, const float *positions, const float *p, float max_dist);

/** Squared distance from p to triangle abc. rt_bvh_nearest.c. */
float pose__point_tri_dist2(const float *p, const float *a, const float *b, const float *c);

#endif /* POSE_RT_BVH_H */
