/* SPDX-License-Identifier: Apache-2.0 */
/* Multi-anchor binding (Egger 2004, §2.4 and §3.1-3.2): a vertex follows its
 * n nearest moving frames ("anchors") and blends their n predictions.
 *
 * Anchors are tet mesh vertices (nodes: Egger's molecules) or joints. A
 * node's frame turns as its neighbourhood does: the rotation of the
 * least-squares deformation gradient of the edges to its neighbours,
 * F = (sum d' d^T) (sum d d^T)^-1 (shape matching), polar-decomposed. Per-tet
 * rotations were the first choice and are too rough: the rotations of
 * neighbouring tets of a piecewise-linear mesh differ by up to ~15 degrees
 * where a bar bends and twists, and even blended four at a time that left
 * 15 % stretch in a surface 5 % of the bar's width off it (tests/binding).
 *
 * All node anchors of a vertex share one origin, the foot: the point of the
 * tet mesh nearest to the vertex at rest, moved exactly as the transfer
 * moves tissue vertices (barycentric in its tet). The mesh's own motion
 * carries the foot, and the anchors only turn the vertex's offset from it:
 * the offset (a few mm for skin outside the mesh) is rotated, never
 * stretched, and a vertex inside the mesh (offset 0) moves as the transfer
 * moves it. A joint's frame is its skinning transform (rest -> posed),
 * applied to the vertex's rest position.
 *
 * Prediction of a node anchor: p' = foot' + R r, r = vertex - foot at rest
 * (model axes: every frame is the identity at rest); of a joint:
 * p' = R p + t. The vertex is the weighted sum of its anchors' predictions.
 */
#ifndef POSE_RT_BIND_H
#define POSE_RT_BIND_H

#include <stddef.h>
#include <stdint.h>

#include "rt_quat.h"

/** Most anchors per vertex. */
#define POSE__BIND_MAX_ANCHORS 8
/** Floats per posed frame: R[9] (row-major), t[3]. */
#define POSE__BIND_FRAME 12
/** pose__bind_vertex.corner[0] of a vertex without a foot (joint anchors only). */
#define POSE__BIND_NO_FOOT UINT32_MAX

/** What a bound vertex keeps of its rest position (52 bytes). */
typedef struct pose__bind_vertex {
    uint32_t corner[4]; /**< the foot's tet */
    float b[3];         /**< foot = v0 + sum b[k] (v[k+1] - v0) */
    float r[3];         /**< vertex - foot at rest */
    float p[3];         /**< vertex at rest (what joint anchors move) */
} pose__bind_vertex;

/** One anchor of a bound vertex (8 bytes). */
typedef struct pose__bind_anchor {
    uint32_t frame; /**< index into the frames (nodes first, then joints) */
    float weight;   /**< the vertex's weights sum to 1 */
} pose__bind_anchor;

/** A binding in the form the kernels read. */
typedef struct pose__bind_mesh {
    size_t vertex_count;
    unsigned anchors;                /**< per vertex, 1..POSE__BIND_MAX_ANCHORS */
    const pose__bind_vertex *vertex; /**< vertex_count */
    const pose__bind_anchor *anchor; /**< vertex_count * anchors, vertex after vertex */
    size_t node_frames;              /**< frames 0 .. node_frames-1 are nodes */
    const uint32_t *node;            /**< tet vertex index per node frame */
    const uint32_t *nbr_offset;      /**< node_frames + 1: each node's neighbours */
    const uint32_t *nbr;             /**< neighbour tet vertex indices */
    const float *nbr_rest;           /**< 3 per neighbour: x_nbr - x_node at rest */
    const float *aqq_inv;            /**< 9 per node frame: (sum d d^T)^-1, row-major */
    size_t joint_frames;             /**< the frames after the nodes are joints */
    const uint32_t *joints;          /**< joint index per joint frame */
} pose__bind_mesh;

/**
 * Pose frames [begin, end) (node frames, then joint frames) from the posed
 * tet vertices and the joints' skinning transforms (rest -> posed), writing
 * POSE__BIND_FRAME floats per frame at frames + POSE__BIND_FRAME * index.
 */
void pose__bind_frames(const pose__bind_mesh *mesh, const float *tet_positions,
                       const pose__xform *skin, size_t begin, size_t end, float *frames);

/** Blend vertices [begin, end) from frames posed by pose__bind_frames and
 *  the posed tet vertices; vertex v is written at out + 3 * v. */
void pose__bind_blend(const pose__bind_mesh *mesh, const float *frames, const float *tet_positions,
                      size_t begin, size_t end, float *out);

/**
 * Vertices [begin, end), posing their anchors' frames as they go (no frame
 * array: for a few vertices spread over a mesh, such as tissue vertices
 * outside it, so a state needs no room for frames; a small cache on the
 * stack reuses the frames neighbouring vertices share); vertex v is written
 * at out + 3 * index[v].
 */
void pose__bind_place(const pose__bind_mesh *mesh, const float *tet_positions,
                      const pose__xform *skin, size_t begin, size_t end, const uint32_t *index,
                      float *out);

/**
 * Rotation of the 3x3 matrix F (row-major): the orthogonal factor of its
 * polar decomposition where det F > 0 (scaled Newton iteration), else the
 * frame of its first two columns (Gram-Schmidt), so a flattened or
 * inverted neighbourhood still gives a rotation.
 */
void pose__bind_rotation(const float F[9], float R[9]);

#endif /* POSE_RT_BIND_H */
