/* SPDX-License-Identifier: Apache-2.0 */
/* The response's cover (pose/contact.h): skin lifted over bone that posing
 * brings out through it, as part of the push's one projection. Built with
 * the push (contact_cover_build.c), run at the start of its pass
 * (contact_cover.c), on the skin as the method left it.
 *
 * Skinning moves the skin by blended transforms while a bone follows its
 * joint rigidly, so in deep flexion, and at the shoulders in the neutral
 * posture, skin over a joint sinks below bone it covered at rest: a condyle,
 * an olecranon or a humeral head comes out through the middle of skin
 * triangles whose corners all stay outside the bone (the coarse body's
 * skin triangles are 11 mm on average and stretch to 99 mm at the knee),
 * which no test of the skin's vertices against the bone sees. So:
 *  - the bone vertices that count are those inside the rest skin and
 *    within POSE__COVER_DEPTH of it (bones are rigid: a tree of them per
 *    bone, in its rest frame, built once);
 *  - a skin triangle is queried against a bone only when, relative to the
 *    bone, one of its corners has moved farther than the triangle lay from
 *    the bone's counted vertices at rest (nothing nearer can have been
 *    crossed): per cluster of 32 triangles and joint (a joint's bones share
 *    its frame), first by a bound (the cluster's farthest move from rest
 *    plus the joint's own motion over the cluster's rest sphere), then by
 *    the vertices' moves, then per triangle; a cluster whose vertices all
 *    move rigidly with the joint (embedded in its bone tets) is skipped;
 *  - the counted vertices above the posed triangle's plane (up to
 *    COVER_MAX_HEIGHT), over its footprint (grown by COVER_BORDER in
 *    barycentric terms: bone over the edge between two tilted triangles
 *    lies over neither) and below its rest plane at rest (by up to
 *    COVER_REST_BELOW) are candidates, tested farthest first; a triangle
 *    whose centroid has another layer of skin over it (a fold) has none;
 *    a candidate is out of the skin when the skin's winding number says so
 *    (a ray along the triangle's normal through a tree of the posed skin,
 *    refitted each frame: the same number as pose_contact_detect's ray
 *    along +x on a closed skin), and it protrudes by its distance to the
 *    skin d (found within its distance to the triangle);
 *  - one over the triangle (its projection inside it, on the outer side)
 *    or nearest to it lifts it: its corners must rise by d + margin for
 *    the largest such d: each skin vertex moves along the mean of its
 *    lifted triangles' normals (weighted by their lifts) by the most one
 *    of them needs along it (its lift over the cosine between that
 *    direction and its normal, so that its plane rises by the lift), at
 *    most COVER_TILT more than that lift.
 * One vertex's lift is thus at most the protrusion, beyond the skin, of
 * bone that comes out through one of its own triangles, plus the margin
 * and COVER_TILT. The push then starts from the lifted position, and a
 * lifted vertex it moves on is brought back within the longer of its lift
 * and its push from where the method left it (pose__cover_bound): one
 * projection per vertex. Candidates are found in parallel over clusters
 * (each writes its own triangles' lifts); the moves are applied serially in
 * triangle order: the same bits for any thread count. */
#ifndef POSE_CONTACT_COVER_H
#define POSE_CONTACT_COVER_H

#include <stddef.h>
#include <stdint.h>

#include "pose/pose.h"
#include "rt_bvh.h"

/** Skin triangles per cluster (Morton order of their rest centroids). */
#define POSE__COVER_CLUSTER 32
/** Items of the candidates' pass (runs of clusters, pose__pool_run_items). */
#define POSE__COVER_ITEMS 64
/** Bone vertices deeper under the rest skin than this are not counted (rig
 *  units; 40 mm: the femur, humerus and ulna vertices that come out at
 *  issue 13's poses lie up to 37 mm deep at rest). */
#define POSE__COVER_DEPTH 0.04f

typedef struct pose__cover {
    pose__bvh *trees;        /**< per bone of the push (same order): over the bone's
                                  counted vertices, as degenerate triangles (v, v, v) */
    uint32_t **points;       /**< per bone: 3 per counted vertex (the tree's triangles) */
    size_t bone_count;
    size_t tri_count, cluster_count, vertex_count;
    uint32_t *tris;          /**< 3 per skin triangle, skin vertex numbers, cluster by cluster */
    float *skin_rest;        /**< 3 per skin vertex: rest position */
    uint32_t *skin_vertex;   /**< per skin vertex number: index into all tissue vertices */
    uint32_t *vert_tri_begin; /**< vertex_count + 1, into vert_tris */
    uint32_t *vert_tris;     /**< per skin vertex its triangles (cluster order) */
    uint32_t *cluster_vert_begin; /**< cluster_count + 1, into cluster_verts */
    uint32_t *cluster_verts; /**< the clusters' skin vertices (the motion check; at most
                                  3 POSE__COVER_CLUSTER each) */
    uint8_t *tri_local;      /**< 3 per triangle: its corners' places in its cluster's list */
    float *cluster_sphere;   /**< 4 per cluster: its vertices' sphere at rest (centre, radius) */
    uint32_t *pair_begin;    /**< cluster_count + 1, into pair_bone */
    uint32_t *pair_bone;     /**< bones near each cluster at rest, by joint, then bone */
    float *pair_clear;       /**< per pair: the least distance at rest between the
                                  bone's counted vertices and the cluster's triangles */
    float *tri_clear;        /**< per pair, POSE__COVER_CLUSTER: that distance per triangle */
    uint8_t *pair_rigid;     /**< per pair: the cluster moves rigidly with the bone's joint
                                  (every vertex embedded in a bone tet of it whose corners
                                  are weighted to it alone), so it keeps its rest place */
    pose__bvh skin;          /**< over the skin's triangles, refitted each frame */
    uint32_t *skin_tris;     /**< the skin tree's triangles (indices into all tissue vertices) */
    float *lift;             /**< per triangle: this frame's lift (0: none) */
    uint32_t *lifted_tris;   /**< this frame's lifted triangles, ascending, item by item: an
                                  item's from the first triangle of its first cluster on
                                  (lifted[item] of them) */
    float *acc;              /**< 4 per skin vertex: lift-weighted normal sum, its move */
    uint32_t *touched;       /**< skin vertices with a lift this frame */
    size_t touched_count;
    uint32_t *order_vertex;  /**< per entry of the push's order: its skin vertex number */
    size_t lifted[POSE__COVER_ITEMS]; /**< per item: triangles lifted */
    size_t tested[POSE__COVER_ITEMS]; /**< per item: candidates tested against the skin */
    size_t moved;            /**< the last pass: skin vertices lifted */
    float max_move;          /**< the last pass: longest lift */
} pose__cover;

struct pose_state;
struct pose__push;
struct pose__push_bone;

/** Build the cover for the state's rig over the push's bones (already
 *  built), with the push's allocator. */
pose_status pose__cover_build(pose__cover *cover, const struct pose_state *st, const struct pose__push *push);
/** Free what pose__cover_build made (a zeroed one is fine). */
void pose__cover_release(pose__cover *cover, const pose_allocator *a);
/** The lifts on the state's skin, before the push moves any of it (the
 *  push's frames must be this frame's). */
void pose__state_cover(struct pose_state *st);
/** The push moved entry i of its order from `before` to x (bone b, frame
 *  f): a vertex the cover lifted is brought back within the longer of its
 *  lift and its push from where the method left it (and COVER_BOUND_SLACK);
 *  its whole move, or -1 when the cover did not lift it. */
float pose__cover_bound(const struct pose__push *push, const struct pose__push_bone *b, const float *f, size_t i,
                        const float *before, float *x);
/** After the push: the lifts' per-vertex data cleared for the next frame. */
void pose__cover_finish(pose__cover *cover);

#endif /* POSE_CONTACT_COVER_H */
