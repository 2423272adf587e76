/* SPDX-License-Identifier: Apache-2.0 */
/* Skin pushed out of bone at the end of pose_apply (pose/contact.h,
 * pose_set_contact_response): the data built when it is first enabled
 * (contact_push_build.c) and the pass (contact_push.c).
 *
 * Bones move rigidly with their joint (skinning transform rest -> posed),
 * so each bone keeps its rest mesh and is queried in its own rest frame:
 * a BVH for the exact nearest triangle, angle-weighted pseudo-normals
 * (Baerentzen & Aanaes 2005) for the sign of the distance, and a coarse
 * grid that tells at once whether a point can be within the margin of
 * the bone or inside it. Skin vertices are grouped in clusters of nearby
 * vertices (at rest); per frame a cluster's bounding sphere is tested
 * against each bone's before any vertex is. */
#ifndef POSE_CONTACT_PUSH_H
#define POSE_CONTACT_PUSH_H

#include <stddef.h>
#include <stdint.h>

#include "pose/contact.h"
#include "rt_bvh.h"

/** Skin vertices per cluster. */
#define POSE__PUSH_CLUSTER 32
/** Skin vertices per group (a cluster's part, tested before its vertices). */
#define POSE__PUSH_GROUP 4
/** Items of the pass (runs of clusters; pose__pool_run_items gives them to
 *  whichever thread is free: the work gathers where skin lies on bone). */
#define POSE__PUSH_ITEMS 128


/** Grid cell states (pose__push_bone.grid codes OUT cells with their gap). */
enum {
    POSE__CELL_IN = 0,       /**< every point inside, deeper than the margin */
    POSE__CELL_NEAR_IN = 1,  /**< inside; a triangle touches the cell grown by the margin */
    POSE__CELL_SURF = 2,     /**< a triangle crosses the cell */
    POSE__CELL_NEAR_OUT = 3, /**< outside; a triangle touches the cell grown by the margin */
    POSE__CELL_OUT = 4,      /**< every point farther than the margin outside */
};

typedef struct pose__push_bone {
    int joint;
    const float *rest;   /**< the tissue's rest positions (the rig's) */
    pose__bvh tree;      /**< over its triangles, at rest */
    float *face_n;       /**< 3 per triangle: unit normal */
    float *edge_n;       /**< 9 per triangle: pseudo-normal of edge k -> k + 1 */
    float *vert_n;       /**< 3 per vertex: angle-weighted pseudo-normal */
    float center[3], radius; /**< bounding sphere at rest */
    float lo[3], hi[3];  /**< the grid's box at rest */
    float cell;          /**< grid spacing */
    float inv_cell;      /**< 1 / cell */
    int dim[3];
    int bricks[3];       /**< bricks of 4 x 4 x 4 cells per axis */
    uint8_t *grid;       /**< per cell, brick by brick (64 bytes each, x fastest
                              within and across bricks): its POSE__CELL_* state, or for
                              an OUT cell POSE__CELL_OUT - 1 + gap, where gap (>= 1,
                              capped) is the Chebyshev distance in cells to the nearest
                              cell that is not OUT */
    uint8_t *brick_gap;  /**< per brick, the least gap of its cells (0 when one is not OUT):
                              the clusters' test reads this small map, not the grid */
} pose__push_bone;

typedef struct pose__push {
    pose_allocator allocator;
    float margin;
    pose__push_bone *bones;
    size_t bone_count;
    uint32_t *order;        /**< skin vertices (indices into all tissue vertices), cluster by cluster */
    uint8_t *skip;          /**< per entry of order: inside a bone at rest (anatomy: left alone) */
    size_t vertex_count, cluster_count;
    float *frames;          /**< per bone per frame: rotation (9, row-major) and translation */
    float *bone_spheres;    /**< per bone per frame: posed centre and radius */
    size_t pushed[POSE__PUSH_ITEMS]; /**< per item of the last pass */
    float max_push[POSE__PUSH_ITEMS];
    double build_seconds;
} pose__push;

struct pose_state;

/** Build everything for the state's rig with the state's allocator (0, or
 *  a pose_status failure with the error set). */
pose_status pose__push_build(pose__push *push, const struct pose_state *st, float margin);
/** Free what pose__push_build made (a zeroed one is fine). */
void pose__push_release(pose__push *push);
/** Signed distance from q (the bone's rest frame) to the bone, exact within
 *  max_dist (farther: +-INFINITY by the grid's inside state is not known
 *  here: returns INFINITY); the nearest point and the outward direction. */
float pose__push_distance(const pose__push_bone *b, const float *q, float max_dist, float *closest,
                          float *outward);

/** pose_apply's last pass when the response is on: the bones' frames for
 *  the pose (serial, cheap), then the skin pushed, item by item. */
void pose__state_push(struct pose_state *st);
void pose__state_push_frames(struct pose_state *st);
void pose__state_push_item(void *ctx, size_t item);
/** pose_state_free: what pose_set_contact_response built. */
void pose__state_push_free(struct pose_state *st);

#endif /* POSE_CONTACT_PUSH_H */
