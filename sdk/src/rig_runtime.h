/* SPDX-License-Identifier: Apache-2.0 */
/* Data derived from a rig at load time for the runtime kernels
 * (built by pose__rig_prepare, read by every pose_state of the rig). */
#ifndef POSE_RIG_RUNTIME_H
#define POSE_RIG_RUNTIME_H

#include <stddef.h>

#include "fem_mesh.h"
#include "rt_bind.h"
#include "rt_quat.h"
#include "rt_skin.h"
#include "rt_thread.h"
#include "rt_transfer.h"

struct pose__rig_runtime {
    /** Tet vertices in blocks of 8 lanes: rest positions and centres,
     *  compact weights (16-bit joints, 15-bit fixed-point weights, largest
     *  first, summing exactly to one). Joints stay 16-bit: 85 % of a body's
     *  blocks read a single joint row, so 8-bit indices would save under 1 %
     *  of the bytes per frame. */
    pose__skin_mesh skin;
    /** All tissues' vertices, one after another (tissue t starts at
     *  tissue_offset[t]), in the rig's order: outputs are written in the
     *  order the API returns them, and the deformed tet vertices they read
     *  (12 bytes each, 9.6 MB for 800 k) stay in the last-level cache. */
    pose__transfer_mesh transfer;
    size_t *tissue_offset;   /**< tissue_count + 1 */
    float *rest_normals;     /**< 3 * total tissue vertices, area-weighted, unit (0 if none) */
    pose__xform *rest_model; /**< joint frames at rest, as runtime transforms */
    void *block;             /**< the one allocation holding all of the above */
    /** POSE_FEM's simulation mesh (rigs with a fem section): the rig's own
     *  tets, in its own allocation (fem_block), built when a state first
     *  needs it (pose__rig_fem_mesh: 64 bytes a soft tet, about 125 MB on
     *  the default bake, which a rig that is only skinned should not carry).
     *  fem_size: its bytes, counted at load (0: no fem section). */
    pose__fem_mesh fem;
    void *fem_block;
    size_t fem_size;
    pose__mutex fem_lock; /**< guards the build (states of one rig may be on any threads) */
    int fem_lock_ready;
    /** Tissue vertices outside the tet mesh (rig_outside.c), bound to the
     *  mesh (rt_bind.h) and placed after the transfer: outside_index holds
     *  their numbers among all tissue vertices, ascending. Two allocations
     *  of their own (NULL when every vertex is inside). */
    pose__bind_mesh outside;
    uint32_t *outside_index;
    void *outside_block;
};

#endif /* POSE_RIG_RUNTIME_H */
