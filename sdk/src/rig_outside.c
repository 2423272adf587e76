/* SPDX-License-Identifier: Apache-2.0 */
/* Tissue vertices outside the tet mesh (rig_outside.h).
 *
 * The bake embeds a vertex outside the mesh (0.03-0.4 % of a body's skin,
 * under 2 mm out) in its nearest tet with extrapolated barycentric
 * coordinates, so the transfer moves it with that one tet's affine map:
 * where the tet stretches or shears, so does the vertex's offset from the
 * mesh, and neighbouring outside vertices in different tets part. Here
 * they are bound to the mesh instead (multi-anchor binding, rt_bind.h, n =
 * 4 nodes): the foot on the mesh moves with the mesh, the offset turns
 * with the blended frames of the nodes around it and keeps its length.
 *
 * Bone tissues keep the transfer: their nearest tets are their own bone's,
 * which move rigidly, so extrapolating them is the bone's rigid motion
 * exactly, and anchors reaching across a joint would bend the bone (the
 * tibia by up to 13 mm at a 90 degree knee, tests/preprocess's bake test).
 *
 * Found and bound at load, from what every rig already holds: no format
 * change, nothing for old rigs to lack. Normals stay the transfer's (the
 * tet's F^-T n, or the triangles' where the tet flips). */
#include "rig_outside.h"

#include <string.h>

#include "alloc.h"
#include "bind_build.h"
#include "error.h"
#include "rig_internal.h"
#include "rig_runtime.h"
#include "state_internal.h"

/* A vertex is outside when a barycentric coordinate is below this: the bake
 * extrapolates beyond 1 micrometre out, -1e-4 of a tet's size; rounding
 * leaves vertices on a face near -1e-7. */
#define OUTSIDE_BARY -1e-4f

/* Anchors per outside vertex (Egger's n). */
#define OUTSIDE_ANCHORS 4

/* Vertex v of tissue ts is one to bind. */
static int outside(const pose__tissue *ts, size_t v)
{
    const float *b = ts->bary + 4 * v;
    return ts->kind != POSE_TISSUE_BONE && (b[0] < OUTSIDE_BARY || b[1] < OUTSIDE_BARY ||
                                            b[2] < OUTSIDE_BARY || b[3] < OUTSIDE_BARY);
}

pose_status pose__rig_prepare_outside(pose_rig *rig)
{
    struct pose__rig_runtime *rt = rig->rt;
    size_t count = 0;
    for (size_t t = 0; t < rig->tissue_count; t++)
        for (size_t v = 0; v < rig->tissues[t].vertex_count; v++)
            count += (size_t)outside(&rig->tissues[t], v);
    if (count == 0)
        return POSE_OK;
    float *xyz = pose__alloc(&rig->allocator, 3 * count * sizeof(float), POSE__ALIGN);
    rt->outside_index = pose__alloc(&rig->allocator, count * sizeof(uint32_t), POSE__ALIGN);
    if (!xyz || !rt->outside_index) {
        pose__free(&rig->allocator, xyz);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY,
                          "out of memory for %zu tissue vertices outside the tet mesh", count);
    }
    size_t at = 0;
    for (size_t t = 0; t < rig->tissue_count; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        for (size_t v = 0; v < ts->vertex_count; v++)
            if (outside(ts, v)) {
                memcpy(xyz + 3 * at, ts->positions + 3 * v, 3 * sizeof(float));
                rt->outside_index[at++] = (uint32_t)(rt->tissue_offset[t] + v);
            }
    }
    pose_status s = pose__bind_build(rig, xyz, count, OUTSIDE_ANCHORS, POSE__BIND_NODES,
                                     &rig->allocator, &rt->outside, &rt->outside_block);
    pose__free(&rig->allocator, xyz);
    if (s == POSE_ERR_UNSUPPORTED) { /* only flat tets near them: the transfer keeps them */
        pose__clear_error();
        pose__free(&rig->allocator, rt->outside_index);
        rt->outside_index = NULL;
        return POSE_OK;
    }
    return s;
}

void pose__rig_release_outside(pose_rig *rig)
{
    pose__free(&rig->allocator, rig->rt->outside_index);
    pose__free(&rig->allocator, rig->rt->outside_block);
    rig->rt->outside_index = NULL;
    rig->rt->outside_block = NULL;
}

/* First outside vertex whose number is >= v. */
static size_t lower_bound(const uint32_t *index, size_t count, size_t v)
{
    size_t lo = 0, hi = count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (index[mid] < v)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

void pose__state_place_outside(struct pose_state *st, size_t begin, size_t end)
{
    const struct pose__rig_runtime *rt = st->rt;
    const size_t n = rt->outside.vertex_count;
    if (n == 0)
        return;
    pose__bind_place(&rt->outside, st->tet_positions, st->skin, lower_bound(rt->outside_index, n, begin),
                     lower_bound(rt->outside_index, n, end), rt->outside_index, st->tissue_positions);
}
