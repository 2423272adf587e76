/* SPDX-License-Identifier: Apache-2.0 */
/* struct pose_state: one posed instance of a rig. Every buffer is allocated
 * at creation with the state's allocator (64-byte aligned), so pose_apply
 * allocates nothing. */
#ifndef POSE_STATE_INTERNAL_H
#define POSE_STATE_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "clinical_math.h"
#include "fem_dynamics.h"
#include "fem_solve.h"
#include "pose/pose.h"
#include "rig_internal.h"
#include "rig_runtime.h"
#include "rt_pool.h"
#include "rt_quat.h"
#include "rt_skin.h"

struct pose_state {
    const pose_rig *rig;
    const struct pose__rig_runtime *rt;
    pose_allocator allocator;
    pose_method method;

    float (*local)[4];          /**< joint_count local rotations relative to rest */
    float (*clinical)[3];       /**< joint_count: last clinical angles of joints with
                                     clinical data (the triple nearest the last request) */
    pose__clinical_range *ranges; /**< joint_count: the range of motion each setter clamps
                                     to (joints with clinical data; pose_set_joint_range) */
    pose__xform root;           /**< model placement on top of the roots */
    pose__xform *skin;          /**< joint_count: rest -> posed, model space */
    pose__xform *world;         /**< joint_count: posed joint frames */
    pose__skin_joint *palette;  /**< joint_count: what the skinning kernels read */

    float *tet_positions;       /**< 3 * tet vertices */
    float *tissue_positions;    /**< 3 * all tissue vertices (rt->tissue_offset) */
    float *tissue_normals;      /**< same layout */
    uint32_t *flagged;          /**< tissue vertices whose normals come from triangles
                                     this frame; part p lists from its first vertex */
    size_t *flagged_count;      /**< per part (POSE__MAX_THREADS) */

    /* POSE_FEM and the dynamics (state_fem.c): the solver's work arrays, own
     * allocation made when first needed (60 floats a soft tet: 406 MB on the
     * default bake, which a state that only skins should not carry) */
    pose__fem_work fem_work;
    void *fem_block;            /**< NULL until POSE_FEM or the dynamics are first used */
    pose__fem_params fem_params;
    pose_fem_stats fem_stats;
    /* Dynamics (state_dynamics.c): own allocation, made when first enabled */
    pose__fem_dyn dyn;
    void *dyn_block;            /**< NULL until pose_step or pose_set_dynamics_options */
    pose_dynamics_options dyn_options;
    pose_dynamics_stats dyn_stats;

    /* Couplings (state_coupling.c): own allocation, NULL when none is in effect */
    void *cpl_block;
    size_t cpl_count;           /**< couplings in effect (on nodes the simulation moves) */
    uint32_t *cpl_node, *cpl_joint; /**< cpl_count each */
    float *cpl_anchor;          /**< 3 per coupling: rest model space */
    float *cpl_spring;          /**< per tet vertex: spring stiffness (0: not coupled) */
    float *cpl_target;          /**< 3 per tet vertex: the spring's bone end this frame */
    /* Soft-soft couplings (state_links.c): own allocation, NULL when none is in effect */
    void *lnk_block;
    pose__fem_links links;      /**< links.count: the ones in effect */
    struct pose__push *push;    /**< pose_set_contact_response (contact_push.c): own
                                     allocations, NULL until first enabled */
    int push_enabled;
    double push_seconds;        /**< the last pass's wall time */

    pose__pool *pool;           /**< own allocation: replaced by pose_set_threads */
    void *block;                /**< the allocation holding everything else */
};

/** Below this many blocks of 8 vertices (skin + transfer), pose_apply does
 *  not use the workers: ~16 k vertices take about as long as a wake-up of a
 *  sleeping worker. */
#define POSE__SERIAL_BLOCKS 2048

/** Most worker threads a state runs. */
#define POSE__MAX_THREADS 256

/** Bytes pose_apply must move per frame with the state's method: every
 *  array the kernels stream, read or written once (benchmarks). */
size_t pose__state_frame_bytes(const pose_state *st);

/** Bytes a pose_step streams with `cg_iterations` CG iterations: the
 *  skinning and transfer of a frame, the solver's passes and the copy of
 *  the positions (benchmarks). */
double pose__state_dynamics_bytes(const pose_state *st, double cg_iterations);

/** The skinning kernel a method runs (POSE_FEM skins with CoR, else DQS). */
int pose__state_skin_method(const pose_state *st);
/** pose_apply's passes (ctx: the state; part of parts). */
void pose__state_skin_task(void *ctx, unsigned part, unsigned parts);
void pose__state_transfer_task(void *ctx, unsigned part, unsigned parts);
void pose__state_fix_normals_task(void *ctx, unsigned part, unsigned parts);
/** Monotonic clock, seconds (FEM statistics). */
double pose__seconds(void);
/** Default FEM solver settings. */
void pose__state_fem_defaults(pose__fem_params *out);
/** FK, skinning palette and skinning of the tet mesh into tet_positions. */
void pose__state_skin_pass(pose_state *st);
/** The simulated tets whose centre lies outside the skin at rest turn
 *  with the skeleton in the dynamics (state_dyn_outside.c). POSE_OK or
 *  POSE_ERR_OUT_OF_MEMORY. */
pose_status pose__state_mark_outside_tets(pose_state *st);
/** Transfer of tet_positions to the tissues (positions, normals); bone
 *  tissues follow their joint instead (state_bones.c). */
void pose__state_transfer_pass(pose_state *st);
/** The transfer (pose__transfer) of the blocks among [begin, end) that
 *  hold a vertex of a tissue other than a bone; flagged vertices listed
 *  from `flagged`, their count returned (state_bones.c). */
size_t pose__state_transfer_soft(pose_state *st, size_t begin, size_t end, uint32_t *flagged);
/** Bone tissues' vertices among tissue vertices [begin, end) placed by
 *  their joint's skinning transform (positions and normals). */
void pose__state_place_bones(pose_state *st, size_t begin, size_t end);
/** A new state's couplings: the rig's (state_coupling.c). */
pose_status pose__state_couplings_init(pose_state *st);
void pose__state_couplings_free(pose_state *st);
/** Where each coupling's bone end is after the skin pass (st->skin):
 *  cpl_target at the coupled nodes; returns cpl_spring, or NULL when no
 *  coupling is in effect. */
const float *pose__state_couplings_place(pose_state *st);
/** pose__state_couplings_place, and the targets copied into
 *  st->tet_positions at the coupled nodes (the dynamics' springs pull
 *  toward `bones`). */
const float *pose__state_couplings_bones(pose_state *st);
/** A new state's soft-soft couplings: the rig's (state_links.c). */
pose_status pose__state_links_init(pose_state *st);
void pose__state_links_free(pose_state *st);
/** The soft-soft couplings for the solvers, or NULL when none is in effect. */
const pose__fem_links *pose__state_links(pose_state *st);
/** The simulation's islands joined by the soft-soft couplings (after it is
 *  laid out, and whenever they change); `scratch`: a tet vertex count of
 *  uint32_t. */
void pose__state_links_islands(pose_state *st, uint32_t *scratch);
/** pose_apply's FEM refinement of st->tet_positions (after skinning). */
void pose__state_fem_refine(pose_state *st);
/** The solver's work arrays (fem_block), allocated with the state's
 *  allocator on the first call; POSE_ERR_OUT_OF_MEMORY naming `fn`. */
pose_status pose__state_fem_work(pose_state *st, const char *fn);

/** Joint rotation setters' shared tail: clamp q to joint j's limits, store it. */
pose_status pose__state_store_joint(pose_state *st, int joint, float q[4]);
/** pose__state_store_joint for a joint with clinical data: clamp the unit
 *  quaternion q in the clinical convention, store it and its angles. */
pose_status pose__state_store_clinical(pose_state *st, int joint, const float q[4]);
/** Clinical angles of the rest pose for every joint with clinical data. */
void pose__state_rest_clinical(pose_state *st);
/** Every joint with clinical data back to the rig's range of motion. */
void pose__state_rig_ranges(pose_state *st);

#endif /* POSE_STATE_INTERNAL_H */
