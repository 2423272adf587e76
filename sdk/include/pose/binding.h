/* SPDX-License-Identifier: Apache-2.0
 *
 * pose/binding.h: a host's own mesh bound to a posed rig (a surgical drape,
 * an instrument's contact surface, a mesh from another tool), by
 * multi-anchor binding (Egger 2004, "Skinning a Deformation Model" §2.4,
 * §3.1-3.2; design §2).
 *
 * Every bound vertex is tied to its n nearest moving frames ("anchors"):
 * the vertices of the rig's tet mesh (nodes, default) and/or its joints.
 * At creation each vertex stores its position in every anchor's frame;
 * after pose_apply each anchor predicts where the vertex is, and the n
 * predictions are blended with weights that fall off with distance. A
 * single anchor (n = 1) shows seams where neighbouring frames turn
 * differently; n = 4 (the default, as Egger found sufficient) blends them
 * away.
 *
 * Anchors:
 *  - a node (Egger's molecule): its frame turns as its neighbourhood does,
 *    the rotation (polar decomposition) of the least-squares deformation
 *    gradient of its edges, F = (sum d' d^T)(sum d d^T)^-1. All node anchors
 *    of a vertex share one origin, its foot: the point of the tet mesh
 *    nearest to the vertex at rest, moved with its tet exactly as the
 *    rig's tissues are. The anchors turn the vertex's offset from the foot
 *    (rotated, never stretched); a vertex inside the mesh (offset 0) moves
 *    as a tissue vertex in its tet does. Node distance: to the node at rest.
 *    (Frames of single tets were tried first: the rotations of neighbouring
 *    tets of a bent, twisted bar differ by up to ~15 degrees, and blended
 *    four at a time they still stretched a surface near it by 15 %.)
 *  - a joint: its frame is the joint's skinning transform (rest -> posed),
 *    applied to the vertex's rest position; its distance is the vertex's
 *    distance to the bone (the segments from the joint to its children,
 *    the joint's origin for a leaf).
 *
 * Weights: w_i = (1 - d_i / d_out)^2, normalized over the n anchors, where
 * d_out is the distance of the nearest anchor left out. A weight reaches
 * zero exactly where its anchor leaves the n nearest, so bound positions
 * are continuous across the mesh (normalized inverse distance would tear
 * where the n-th and (n+1)-th nearest swap).
 *
 * The same binding moves the rig's own tissue vertices that lie outside its
 * tet mesh (pose_apply, with n = 4 node anchors; bones excepted, which
 * follow their own rigid tets): they keep their rest offset to the mesh
 * instead of following one tet's extrapolated deformation.
 *
 * Threads and memory: pose_binding_create allocates everything;
 * pose_binding_apply allocates nothing, runs on the calling thread, and
 * gives the same result for the same pose whatever ran before. A binding
 * holds its posed frames, so one binding is applied by one thread at a
 * time; any number of bindings of one rig may be applied at once. libc and
 * libm only, as libpose.
 */
#ifndef POSE_BINDING_H
#define POSE_BINDING_H

#include "pose.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pose_binding pose_binding; /**< a mesh bound to a rig's anchors */

/** Anchor kinds (pose_binding_options.sources, pose_binding_anchor.kind). */
enum {
    POSE_BINDING_NODES = 1u << 0, /**< the rig's tet mesh vertices (default) */
    POSE_BINDING_BONES = 1u << 1, /**< the rig's joints, by distance to their bones */
};

/** Most anchors per vertex. */
#define POSE_BINDING_MAX_ANCHORS 8

/** Options; a zeroed struct gives the defaults. size: as pose_load_options
 *  (sizeof(pose_binding_options), or 0). */
typedef struct pose_binding_options {
    size_t size;
    pose_allocator allocator; /**< zeroed = malloc/free */
    unsigned anchors;         /**< n per vertex, 1..POSE_BINDING_MAX_ANCHORS; 0 = 4 */
    uint32_t sources;         /**< POSE_BINDING_* bits; 0 = POSE_BINDING_NODES */
} pose_binding_options;

/** One anchor of a bound vertex (pose_binding_vertex_anchors). */
typedef struct pose_binding_anchor {
    uint32_t kind;   /**< POSE_BINDING_NODES or POSE_BINDING_BONES */
    uint32_t index;  /**< tet mesh vertex or joint index */
    float weight;    /**< the vertex's weights sum to 1 */
} pose_binding_anchor;

/**
 * Bind `count` vertices (rest_xyz: xyz interleaved, model space of the rig
 * at rest, rig units) to `rig` (which must outlive the binding).
 * POSE_ERR_INVALID_ARGUMENT for NULL pointers, count 0, a non-finite
 * coordinate, anchors or sources out of range or a bad options size;
 * POSE_ERR_UNSUPPORTED when the rig has no anchor of the kinds asked for
 * (no tet of non-zero volume). Cost: a grid over the tets, a pass over
 * them for the anchors' neighbours, and a search per vertex (farther from
 * the rig is slower). @since 0.2
 */
POSE_API pose_status pose_binding_create(const pose_rig *rig, const float *rest_xyz, size_t count,
                                         const pose_binding_options *options,
                                         pose_binding **out);

/**
 * Positions of the bound vertices for the pose of `state` (after
 * pose_apply; the state must come from the binding's rig) into out_xyz
 * (3 * count floats). Allocates nothing. @since 0.2
 */
POSE_API pose_status pose_binding_apply(pose_binding *binding, const pose_state *state,
                                        float *out_xyz);

/** Free a binding; NULL is a no-op. @since 0.2 */
POSE_API void pose_binding_free(pose_binding *binding);

/** Number of bound vertices (0 for NULL). @since 0.2 */
POSE_API size_t pose_binding_vertex_count(const pose_binding *binding);

/** Anchors per vertex (n; 0 for NULL). @since 0.2 */
POSE_API unsigned pose_binding_anchor_count(const pose_binding *binding);

/**
 * The n anchors of `vertex`, nearest first, into out[0..n) (n =
 * pose_binding_anchor_count). A rig with fewer than n anchors pads with
 * weight-0 copies of the nearest. POSE_ERR_INVALID_ARGUMENT for a vertex out
 * of range. @since 0.2
 */
POSE_API pose_status pose_binding_vertex_anchors(const pose_binding *binding, size_t vertex,
                                                 pose_binding_anchor *out);

#ifdef __cplusplus
}
#endif

#endif /* POSE_BINDING_H */
