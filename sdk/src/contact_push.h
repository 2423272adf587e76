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

#include "contact_quiet.h"
#include "pose/contact.h"
#include "rt_bvh.h"

/** Skin vertices per cluster. */
#define POSE__PUSH_CLUSTER 32
/** Skin vertices per group (a cluster's part, tested before its vertices). */
#define POSE__PUSH_GROUP 4
/** How near a bone must lie to a cluster of skin at rest for the push to
 *  move that skin out of it (rig units: 40 mm): skin in a bone farther
 *  away is in another part of the body (a thigh's skin in the fingers of a
 *  hand posed into it), which pushing the skin cannot take out, and whose
 *  small bones, moving through the skin, would throw it from side to side
 *  from frame to frame. */
#define POSE__PUSH_REACH 0.04f
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

/** What a point's last queries against two bones proved: at q (the
 *  bone's rest frame) the point was outside it by d or more, so a later
 *  query nearer to q than d - margin needs no search (pose__push_query). */
typedef struct pose__push_cache {
    struct {
        float q[3];
        float d;
        uint32_t bone; /**< index in pose__push.bones; UINT32_MAX: none */
    } slot[2];
} pose__push_cache;

/** Where a point (skin vertex or node) lies at rest against the joint
 *  that carries most of it (its largest skinning weight): as long as the
 *  point strays from where that joint alone would carry it by less than
 *  `room`, it is farther than the margin from every bone of that joint
 *  (the distance is 1-Lipschitz), which then needs no search for it
 *  (pose__push_anchors). Skin riding with a limb's bones, a hand's among
 *  its 27, was most of what the passes searched. */
typedef struct pose__push_anchor {
    float rest[3];
    float room;    /**< its rest distance to the joint's bones (counted up to POSE__PUSH_REACH)
                        less the margin (> 0) */
    int32_t joint; /**< -1: none (no bones, within the margin of one or inside one at rest) */
} pose__push_anchor;

/** A cluster's anchors tested against the pose (pose__push_anchors): per
 *  point, the joint whose bones need no search for it, or -1, and a lower
 *  bound on its distance to them; the same per group of
 *  POSE__PUSH_GROUP, where every point of the group has that joint. */
typedef struct pose__push_anchored {
    int32_t joint[POSE__PUSH_CLUSTER];
    float clear[POSE__PUSH_CLUSTER];
    int32_t group_joint[POSE__PUSH_CLUSTER / POSE__PUSH_GROUP];
    float group_clear[POSE__PUSH_CLUSTER / POSE__PUSH_GROUP];
} pose__push_anchored;

/** Most bones one node of the dynamic response touches at once. */
#define POSE__PUSH_NODE_BONES 4

/** A node's resting contact on a bone (contact_dyn.c): a plane in the
 *  bone's rest frame, where the step puts it, and its multiplier. */
typedef struct pose__push_rest {
    float q[3], n[3]; /**< a point of the plane and its unit normal out of the bone (rest frame) */
    float a[3], m[3]; /**< the point and normal posed where the step ends */
    float force;      /**< the multiplier: force out of the plane, N */
    uint16_t bone;    /**< index in pose__push.bones */
} pose__push_rest;

typedef struct pose__push {
    pose_allocator allocator;
    float margin;
    pose__push_bone *bones;
    size_t bone_count;
    uint32_t *order;        /**< skin vertices (indices into all tissue vertices), cluster by cluster */
    uint8_t *skip;          /**< per entry of order: inside a bone at rest (anatomy: left alone) */
    pose__push_cache *cache; /**< per entry of order */
    pose__push_anchor *anchor; /**< per entry of order (pose__push_anchors) */
    size_t vertex_count, cluster_count;
    uint64_t *reach;        /**< per cluster, a bit per bone (bone_words words): the bone
                                 lies within POSE__PUSH_REACH of the cluster at rest, so the
                                 cluster's skin covers it; the others are another part's
                                 bones, not pushed out of */
    size_t bone_words;      /**< 64-bit words of a bit per bone */
    float *frames;          /**< per bone per frame: rotation (9, row-major) and translation */
    float *bone_spheres;    /**< per frame, posed: the bones' centres' x, then y, z and radii,
                                 64 bone_words each (padding: x infinite, never near) */
    uint32_t *near;         /**< per item: scratch for pose__push_near_bones, bone_count entries */
    uint8_t *hit;           /**< per item: its scratch too, bone_count bytes */
    size_t joint_count;     /**< the rig's joints */
    pose__quiet_joints quiet_joints; /**< the joints' frames and moves (contact_quiet.h) */
    float *bound;           /**< per item: scratch, a bound per joint (contact_quiet.h) */
    uint32_t *joint_start;  /**< per joint + 1: where its bones start in joint_bones */
    uint32_t *joint_bones;  /**< bones (indices in bones) joint by joint */
    float *joint_spheres;   /**< per joint: a sphere holding its bones' at rest (4), then posed (4) */
    pose__quiet skin_quiet; /**< the skin's clusters' last full passes */
    int quiet_off;          /**< tests: every cluster's pass in full */
    size_t pushed[POSE__PUSH_ITEMS]; /**< per item of the last pass */
    float max_push[POSE__PUSH_ITEMS];
    struct pose__cover *cover; /**< skin lifted over bone before the push (contact_cover.h) */
    double build_seconds;
    /* The dynamic response (contact_dyn.c): the tet mesh's soft nodes,
     * built by the first pose_step with the response on. */
    int nodes_built;
    int step_keeps_skin;    /**< tests and benches: pose_step leaves the skin where the transfer
                                 put it (0: pushed out of bone as pose_apply does) */
    uint32_t *nodes;        /**< soft nodes (tet vertices), cluster by cluster (Morton order at rest) */
    pose__push_cache *node_cache; /**< per node */
    pose__push_anchor *node_anchor; /**< per node (pose__push_anchors) */
    pose__quiet node_quiet; /**< the nodes' clusters' last full passes */
    uint16_t *node_bone;    /**< per entry: the bone (index in bones) it lies within the margin
                                 of at rest, or UINT16_MAX */
    float *node_gap;        /**< per entry: its distance to that bone at rest: the constraint's
                                 target there (the margin against the others) */
    uint8_t *rest_count;    /**< per entry: its resting contacts, */
    pose__push_rest *rests; /**< POSE__PUSH_NODE_BONES per entry */
    uint8_t *rest_on;       /**< per tet vertex: resting contacts as the solve reads them */
    float *rest_stiff, *rest_force; /**< (pose__fem_dyn_contact: 6 and 3 per tet vertex) */
    size_t node_count, node_clusters;
    float step_dt;          /**< the step's dt, for the items */
    size_t constraints[POSE__PUSH_ITEMS]; /**< per item of the last step's response */
    int sweeps[POSE__PUSH_ITEMS];         /**< most projected Gauss-Seidel sweeps of a node */
    float max_impulse[POSE__PUSH_ITEMS];  /**< largest impulse, N s */
    float max_move[POSE__PUSH_ITEMS];     /**< longest move by the response, rig units */
    float max_excess[POSE__PUSH_ITEMS];   /**< largest move beyond the node's depth in bone at
                                               its predicted position */
} pose__push;

struct pose_state;
struct pose__fem_dyn_contact;

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

/** Whether the posed point x is within the margin of bone b (frame f:
 *  rotation, row-major, and translation, as pose__state_push_frames makes
 *  them) or inside it (inside confirmed by rays along +x and -x): 1 with
 *  its signed distance, the nearest surface point and the outward
 *  direction, both in the bone's rest frame; else 0. The one query of the
 *  kinematic and the dynamic response. cache (the point's own, or NULL)
 *  skips the search where the last one proves the point outside, and is
 *  updated where this one does: the same answers, fewer searches. With
 *  bound (or NULL), a lower bound on the point's distance to the bone
 *  where it returns 0 and knows one (0 where not, and where it returns 1). */
int pose__push_query(const pose__push *p, const pose__push_bone *b, const float *f, const float *x,
                     pose__push_cache *cache, float *signed_distance, float *closest, float *outward,
                     float *bound);
/** The anchors a[i] of the points pos[3 idx[i]] (pos[3 i] when idx is
 *  NULL), i < count, against the bones' frames of the pass; points
 *  marked in skip (or NULL) need no search at all and join any group. */
void pose__push_anchors(const pose__push *p, const pose__push_anchor *a, const float *pos, const uint32_t *idx,
                        const uint8_t *skip, size_t count, pose__push_anchored *out);
/** Bounding sphere (centre, radius) of the points pos[3 idx[i]] (pos[3 i]
 *  when idx is NULL), i in [begin, end). */
void pose__push_sphere(const float *pos, const uint32_t *idx, size_t begin, size_t end, float *sphere);
/** The same for each POSE__PUSH_GROUP of those points, in order, into
 *  group, and all of them into cluster (its box from theirs: each point is
 *  read once); the groups' count. */
size_t pose__push_spheres(const float *pos, const uint32_t *idx, size_t begin, size_t end, float *cluster,
                          float (*group)[4]);
/** 1 when no point of a posed sphere needs testing against bone j (posed
 *  by its frame): the sphere is outside the grid's box, or its centre's
 *  brick's least gap proves all of it farther than the margin; then what
 *  that proves of its points' distance to the bone, into bound (per joint,
 *  or NULL). Else 0. */
int pose__push_sphere_far(const pose__push *p, size_t j, const float *sphere, float *bound);
/** Whether bone j's posed sphere comes within the margin of posed sphere
 *  c: the first test of a cluster's or a group's sphere, before the grid's. */
static inline int pose__push_spheres_near(const pose__push *p, size_t j, const float *c)
{
    const size_t stride = 64 * p->bone_words;
    const float *s = p->bone_spheres + j;
    const float dx = c[0] - s[0], dy = c[1] - s[stride], dz = c[2] - s[2 * stride];
    const float reach = c[3] + s[3 * stride] + p->margin;
    return dx * dx + dy * dy + dz * dz <= reach * reach;
}
/** What posed sphere c apart from bone j's proves of its points' distance
 *  to the bone (which lies in its sphere), into bound (per joint). */
static inline void pose__push_spheres_bound(const pose__push *p, size_t j, const float *c, float *bound)
{
    const size_t stride = 64 * p->bone_words;
    const float *s = p->bone_spheres + j;
    const float dx = c[0] - s[0], dy = c[1] - s[stride], dz = c[2] - s[2 * stride];
    pose__quiet_bound_root(bound, p->bones[j].joint, dx * dx + dy * dy + dz * dz, c[3] + s[3 * stride]);
}
/** Whether a group's posed sphere may hold a point bone j needs tested
 *  (bones' spheres, then the grid's); if not, what the test proved, into
 *  bound (per joint, or NULL). */
int pose__push_group_near(const pose__push *p, size_t j, const float *group, float *bound);
/** The bones a cluster's posed bounding sphere may need tested against,
 *  in the rig's order, into item's near; their count. With mask (a bit per
 *  bone, bone_words words), only those it marks. Each bone's posed sphere
 *  within the margin (all bones side by side), then its grid
 *  (pose__push_sphere_far, per brick). With bound (per joint, or NULL),
 *  what the tests proved of the bones left out (contact_quiet.h). */
size_t pose__push_near_bones(const pose__push *p, size_t item, const float *cluster, const uint64_t *mask,
                             float *bound);
/** The dynamic response's nodes (the state's tet mesh's soft nodes), with
 *  the state's allocator. */
pose_status pose__push_build_nodes(pose__push *push, const struct pose_state *st);
/** Forget the resting contacts (a restart, or the response turned on
 *  again): the next step starts without them. */
void pose__push_forget(pose__push *push, size_t tet_vertex_count);
/** Before pose_step's solve: the bones where the step ends and the
 *  resting contacts there (one whose plane has left its node ends), as
 *  the solve reads them, into *out. */
void pose__state_contact_rests(struct pose_state *st, float dt, struct pose__fem_dyn_contact *out);
/** pose_step's response, between the solve and x' = x + dt v' (the state's
 *  dyn.v changed where a soft node would end inside or within the margin
 *  of a bone); the counts into the push's per-item arrays. */
void pose__state_contact_step(struct pose_state *st, float dt);

/** pose_step's last pass when the response is on: the bones' frames for
 *  the pose (serial, cheap), then the skin pushed, item by item. */
void pose__state_push(struct pose_state *st);
/** pose_apply's: as pose__state_push, with the skin first lifted over bone
 *  that came out through it (contact_cover.h). */
void pose__state_push_cover(struct pose_state *st);
void pose__state_push_frames(struct pose_state *st);
void pose__state_push_item(void *ctx, size_t item);
/** pose_state_free: what pose_set_contact_response built. */
void pose__state_push_free(struct pose_state *st);

#endif /* POSE_CONTACT_PUSH_H */
