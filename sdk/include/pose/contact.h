/* SPDX-License-Identifier: Apache-2.0
 *
 * pose/contact.h: collision detection between a posed rig's tissues
 * (issue 13 part 1; design §2). Skinning moves skin and bones by different
 * fields, so in deep flexion the skin folds through itself (behind the knee,
 * in the elbow, at the groin), bone comes out through the skin (shoulders,
 * elbows, knees) and skin ends up inside bone. A pose_contact finds these
 * after each pose_apply:
 *  - skin triangle pairs that intersect, pairs sharing a vertex excepted
 *    (every tissue of kind POSE_TISSUE_SKIN, as one surface);
 *  - skin vertices inside a bone (winding number of the posed bones'
 *    triangles, all tissues of kind POSE_TISSUE_BONE, by rays along +x and
 *    -x that must agree: a few bone meshes are open, and one ray through
 *    an open mesh can count a crossing without its partner);
 *  - bone vertices outside the skin (winding number of the skin);
 *  - triangle pairs of two different bones (tissues of kind
 *    POSE_TISSUE_BONE) that intersect: bone through bone, which no
 *    response to the skin can undo (the pose itself brings a joint's bones
 *    into each other, or two limbs through each other). Pairs within one
 *    bone mesh are not looked at; bones that touch or overlap at rest
 *    (the jaw and skull, vertebrae, carpals in the bundled anatomy) count
 *    at rest too.
 * Inside and outside assume closed, outward-oriented meshes (pose-bake's
 * inputs are); touching without crossing (a vertex exactly on a face)
 * counts as no contact.
 *
 * How: one bounding-volume hierarchy over the skin's triangles and one over
 * the bones', built at creation from the rest pose and refitted to the
 * posed vertices on every detection; pairs by a traversal of the skin tree
 * against itself, inside tests by a ray along +x (front to back, where the body is
 * thinnest) through the other tree.
 *
 * Threads and memory: pose_contact_create allocates everything (with the
 * options' allocator) and starts its own worker threads;
 * pose_contact_detect allocates nothing, runs on the calling thread and the
 * workers, and counts the same for any thread count. One pose_contact is
 * used by one thread at a time; the state it reads must not be posed
 * meanwhile.
 */
#ifndef POSE_CONTACT_H
#define POSE_CONTACT_H

#include "pose.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pose_contact pose_contact; /**< collision detection for one rig */

/** Options; a zeroed struct gives the defaults. */
typedef struct pose_contact_options {
    size_t size;              /**< sizeof(pose_contact_options), or 0 */
    pose_allocator allocator; /**< zeroed = malloc/free */
    int threads;              /**< threads of pose_contact_detect (caller included);
                                   0 = number of cores */
} pose_contact_options;

/** What one pose_contact_detect found. */
typedef struct pose_contact_counts {
    size_t size;             /**< sizeof(pose_contact_counts), set by the caller */
    size_t skin_pairs;       /**< skin triangle pairs that intersect, sharing no vertex */
    size_t skin_in_bone;     /**< skin vertices inside a bone */
    size_t bone_out_of_skin; /**< bone vertices outside the skin */
    double seconds;          /**< wall time of the detection */
    size_t bone_pairs;       /**< triangle pairs of two different bone tissues that intersect
                                  (added to the struct later: a caller whose size
                                  ends before it is accepted and it is not written) */
} pose_contact_counts;

/** Flags of a tissue vertex (pose_contact_vertex_flags). */
enum {
    POSE_CONTACT_SKIN_IN_BONE = 1u << 0,     /**< a skin vertex inside a bone */
    POSE_CONTACT_BONE_OUT_OF_SKIN = 1u << 1, /**< a bone vertex outside the skin */
};

/**
 * Index the tissues of `rig` (which must outlive the handle) for detection.
 * POSE_ERR_INVALID_ARGUMENT for NULL rig or out, a bad options size or
 * allocator, or negative threads; POSE_ERR_OUT_OF_MEMORY; POSE_ERR_THREAD
 * when the workers could not start. Cost: a sort of the triangles per
 * tree (~0.1 s for the bundled body's 290 k bone triangles). @since 0.2
 */
POSE_API pose_status pose_contact_create(const pose_rig *rig, const pose_contact_options *options,
                                         pose_contact **out);

/** Free a handle and stop its workers; NULL is a no-op. @since 0.2 */
POSE_API void pose_contact_free(pose_contact *contact);

/**
 * Detect contact in the tissues of `state` as its last pose_apply left
 * them (the state must come from the handle's rig) and count it into
 * *out (out->size must be set; NULL: only the flags are kept). Allocates
 * nothing. POSE_ERR_INVALID_ARGUMENT for NULL contact or state, a state of
 * another rig or a bad out->size. @since 0.2
 */
POSE_API pose_status pose_contact_detect(pose_contact *contact, const pose_state *state,
                                         pose_contact_counts *out);

/**
 * The flags (POSE_CONTACT_* bits) of the vertices of `tissue` from the last
 * pose_contact_detect (zeros before one): vertex_count bytes, owned by the
 * handle, valid until the next detection or pose_contact_free. NULL for a
 * NULL handle or a tissue out of range. @since 0.2
 */
POSE_API const uint8_t *pose_contact_vertex_flags(const pose_contact *contact, int tissue,
                                                  size_t *vertex_count);

/*
 * Response (issue 13 part 2): skin kept over and out of bone in the
 * kinematic methods. With it on, pose_apply ends with a position-level
 * projection, one move per skin vertex, in two parts:
 *  - cover: a bone vertex that posing brings out of the skin (inside the
 *    rest skin within 40 mm of it, outside the posed skin by its winding
 *    number, as pose_contact_detect counts) lifts the skin triangle it
 *    lies over (its projection inside it, on the outer side) or is nearest
 *    to: the triangle's corners move outward by the bone vertex's distance
 *    to the skin plus the margin (along the lift-weighted mean of their
 *    lifted triangles' normals, divided by the cosine to each triangle's
 *    normal, at most 0.4 mm more), so that bone coming out between skin
 *    vertices (through the middle of a triangle whose corners all lie
 *    outside every bone) is covered; a triangle inside another layer of
 *    skin (a fold) lifts nothing;
 *  - push: then every skin vertex inside a bone, or outside it by less
 *    than the margin, moves to the bone's nearest surface point plus the
 *    margin along the outward direction; only bones the skin covers count
 *    (within 40 mm of its cluster of 32 skin vertices at rest): skin in
 *    the bones of another part posed into it (a thigh's skin in the
 *    fingers of a hand, one foot's in the other's) stays, since moving
 *    skin cannot take the part out, and small bones moving through skin
 *    would throw it from side to side between frames.
 * Bones move rigidly with their joints, so each is queried in its rest
 * frame: exact nearest triangle (a BVH of the bone's mesh), sign by
 * angle-weighted pseudo-normals, a coarse grid per bone that rejects far
 * points at once, and a tree of the bone's vertices near the skin for the
 * cover; the skin's triangles are queried only where they have moved,
 * relative to a bone, farther than they lay from its vertices at rest.
 * Skin inside a bone at rest (the orbits' and the mouth's, in the skull and
 * jaw) is anatomy and is left alone.
 *
 * What it guarantees: a skin vertex moves once, by at most the larger of
 * its depth in a bone plus the margin and the protrusion of the bone that
 * comes out through one of its own triangles plus the margin and 0.4 mm (a
 * lifted vertex that the push moves on is brought back within that; pushed
 * out of the first bone in the rig's order that holds it into another, it
 * stays there), and never when neither applies; the same bits for any
 * thread count. Skin normals stay as the transfer made them. Bone vertices
 * are not moved. pose_step (below) pushes without the cover.
 *
 * Cost: the first pose_set_contact_response that enables it (or changes
 * the margin) builds the bones' structures with the state's allocator,
 * called from the calling thread only, and the state's threads (about
 * 0.85 s on 2 threads for the bundled body;
 * pose_contact_response_stats.build_seconds); pose_apply allocates
 * nothing and runs the pass on the state's threads. Each skin vertex (and
 * each node below) keeps its rest distance d to the bones of the joint that
 * carries most of it (its largest skinning weight): while it strays less
 * than d - margin from where that joint's motion alone would carry it,
 * those bones are not searched for it (they are farther than the margin);
 * a hand's skin among its 27 bones is most of what the pass would search.
 *
 * Dynamics (pose_step, pose.h): with the response on, each step also keeps
 * the tet mesh's soft nodes (vertices of soft tets only: bone nodes ride
 * their springs) out of bone, by velocity-level non-penetration
 * constraints solved after the unconstrained solve (Otaduy et al. §5.3):
 * a node whose predicted end position x + dt v lies inside a bone or
 * within the margin of it (the same query as above, on the bone where the
 * step's skeleton puts it) gets n . (v' - v) >= (margin - s) / dt for that
 * bone (s its signed distance, n the outward normal; a node nearer than
 * the margin at rest keeps its rest distance instead), at most four bones
 * per node; projected Gauss-Seidel solves each node's constraints (bones
 * are kinematic, so a contact island is one node with its constraints),
 * the impulse's effective mass from the isotropic part of the node's
 * diagonal block of the step's system matrix; x' = x + dt v' moves the
 * node. The correction is whole within the step: a node ends at the
 * margin, moved by the response by its predicted depth in bone plus the
 * margin at most, and the velocity change stays in v' (the next step
 * starts from it; a node that was not inside at the start of the step
 * leaves with its bone's normal velocity, no bounce). A node the
 * response pushed rests on that bone from the next step on, inside the
 * solve: a force out of the plane it was pushed to, a multiplier that
 * grows over the steps to the load pressing the node there and a
 * stiffness (30 times the node's own) in the step's system, so that a
 * posture held costs the solve about what it costs without contact; the
 * contact ends when the node is beyond the plane by a tenth of the
 * margin, and never pulls. pose_reset_dynamics, and turning the response
 * off and on, forget these contacts. Then, after the transfer, the skin is pushed out of bone as
 * pose_apply pushes it, without the cover (the simulation mesh is coarser than the skin:
 * bone comes through between nodes). Nodes inside a bone at rest are
 * anatomy, left alone. The first pose_step with the response on finds the
 * nodes (allocating with the state's allocator); later steps allocate
 * nothing; the same bits for any thread count. pose_dynamics_stats counts
 * the constraints, sweeps and largest impulse; the push's figures are in
 * pose_contact_response_stats.
 */

/** Response settings; a zeroed struct (size set or 0) is off. */
typedef struct pose_contact_response {
    size_t size;  /**< sizeof(pose_contact_response), or 0 */
    int enabled;  /**< nonzero: pose_apply pushes skin out of bone; pose_step keeps soft
                       nodes out of bone and pushes the skin */
    float margin; /**< distance kept from bone, rig units; 0 = 0.0005 (0.5 mm in metres) */
} pose_contact_response;

/** What the last pose_apply's (or pose_step's) push of the skin did. */
typedef struct pose_contact_response_stats {
    size_t size;          /**< sizeof(pose_contact_response_stats), set by the caller */
    size_t pushed;        /**< skin vertices moved (lifted over bone, pushed out of it, or both) */
    float max_push;       /**< longest move of one, rig units */
    float margin;         /**< the margin in effect */
    double seconds;       /**< wall time of the pass */
    double build_seconds; /**< building the bones' structures */
} pose_contact_response_stats;

/** Turn the response on or off (NULL: off), for pose_apply and pose_step.
 *  POSE_ERR_INVALID_ARGUMENT for a bad size or a negative or non-finite
 *  margin; POSE_ERR_OUT_OF_MEMORY (the response is off then). @since 0.2 */
POSE_API pose_status pose_set_contact_response(pose_state *state, const pose_contact_response *settings);

/** Statistics of the last pose_apply's or pose_step's push (zeros with it off);
 *  out->size must be set. @since 0.2 */
POSE_API pose_status pose_get_contact_response_stats(const pose_state *state,
                                                     pose_contact_response_stats *out);

#ifdef __cplusplus
}
#endif

#endif /* POSE_CONTACT_H */
