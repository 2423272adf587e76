/* SPDX-License-Identifier: Apache-2.0 */
/* pose/binding.h: a host's mesh bound to a rig by multi-anchor binding. */
#include "pose/binding.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "bind_build.h"
#include "error.h"
#include "state_internal.h"

struct pose_binding {
    const pose_rig *rig;
    pose_allocator allocator;
    pose__bind_mesh mesh;
    void *mesh_block;
    float *frames; /* POSE__BIND_FRAME per frame, posed by each apply */
};

/* The least options size accepted: the 0.2 layout (0 also means it). */
#define OPTIONS_SIZE_0_2 (offsetof(pose_binding_options, sources) + sizeof(uint32_t))

_Static_assert(POSE_BINDING_MAX_ANCHORS == POSE__BIND_MAX_ANCHORS, "one anchor limit");
_Static_assert((unsigned)POSE_BINDING_NODES == (unsigned)POSE__BIND_NODES &&
                   (unsigned)POSE_BINDING_BONES == (unsigned)POSE__BIND_JOINTS,
               "one set of anchor kinds");

pose_status pose_binding_create(const pose_rig *rig, const float *rest_xyz, size_t count,
                                const pose_binding_options *options, pose_binding **out)
{
    pose__clear_error();
    if (out)
        *out = NULL;
    if (!rig || !rest_xyz || !out || count == 0)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_binding_create: rig, rest_xyz, out and count > 0 are required");
    pose_binding_options opt = {0};
    if (options)
        opt = *options;
    if (opt.size != 0 && opt.size < OPTIONS_SIZE_0_2)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_binding_create: options.size %zu is below the 0.2 layout (%zu)",
                          opt.size, (size_t)OPTIONS_SIZE_0_2);
    if (!pose__allocator_valid(&opt.allocator))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_binding_create: allocator needs both alloc and free");
    const unsigned n = opt.anchors ? opt.anchors : 4;
    const uint32_t sources = opt.sources ? opt.sources : POSE_BINDING_NODES;
    if (n > POSE_BINDING_MAX_ANCHORS || (sources & ~(uint32_t)(POSE_BINDING_NODES | POSE_BINDING_BONES)))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_binding_create: anchors %u (1..%d) or sources 0x%x out of range", n,
                          POSE_BINDING_MAX_ANCHORS, (unsigned)sources);
    if (count > SIZE_MAX / (3 * sizeof(float) * POSE_BINDING_MAX_ANCHORS * 16))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_binding_create: %zu vertices", count);
    for (size_t i = 0; i < 3 * count; i++)
        if (!isfinite(rest_xyz[i]))
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "pose_binding_create: vertex %zu is not finite", i / 3);

    pose_allocator alloc = pose__allocator_resolve(&opt.allocator);
    pose__bind_mesh mesh;
    void *mesh_block;
    pose_status s = pose__bind_build(rig, rest_xyz, count, n, sources, &alloc, &mesh, &mesh_block);
    if (s != POSE_OK)
        return s;
    const size_t frames = mesh.node_frames + mesh.joint_frames;
    const size_t head = (sizeof(pose_binding) + 63u) & ~(size_t)63u;
    unsigned char *mem = pose__alloc(&alloc, head + frames * POSE__BIND_FRAME * sizeof(float),
                                     POSE__ALIGN);
    if (!mem) {
        pose__free(&alloc, mesh_block);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "pose_binding_create: out of memory for %zu frames",
                          frames);
    }
    pose_binding *b = (pose_binding *)mem;
    *b = (pose_binding){rig, alloc, mesh, mesh_block, (float *)(mem + head)};
    *out = b;
    return POSE_OK;
}

pose_status pose_binding_apply(pose_binding *b, const pose_state *st, float *out_xyz)
{
    pose__clear_error();
    if (!b || !st || !out_xyz)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_binding_apply: binding, state and out_xyz are required");
    if (st->rig != b->rig)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_binding_apply: the state comes from another rig than the binding");
    const pose__bind_mesh *m = &b->mesh;
    pose__bind_frames(m, st->tet_positions, st->skin, 0, m->node_frames + m->joint_frames, b->frames);
    pose__bind_blend(m, b->frames, st->tet_positions, 0, m->vertex_count, out_xyz);
    return POSE_OK;
}

void pose_binding_free(pose_binding *b)
{
    if (!b)
        return;
    pose_allocator alloc = b->allocator;
    pose__free(&alloc, b->mesh_block);
    pose__free(&alloc, b);
}

size_t pose_binding_vertex_count(const pose_binding *b)
{
    return b ? b->mesh.vertex_count : 0;
}

unsigned pose_binding_anchor_count(const pose_binding *b)
{
    return b ? b->mesh.anchors : 0;
}

pose_status pose_binding_vertex_anchors(const pose_binding *b, size_t vertex, pose_binding_anchor *out)
{
    pose__clear_error();
    if (!b || !out || vertex >= b->mesh.vertex_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_binding_vertex_anchors: vertex %zu out of range (%zu) or NULL argument",
                          vertex, b ? b->mesh.vertex_count : 0);
    const pose__bind_mesh *m = &b->mesh;
    for (unsigned k = 0; k < m->anchors; k++) {
        const pose__bind_anchor *a = &m->anchor[vertex * m->anchors + k];
        const int joint = a->frame >= m->node_frames;
        out[k] = (pose_binding_anchor){
            joint ? POSE_BINDING_BONES : POSE_BINDING_NODES,
            joint ? m->joints[a->frame - m->node_frames] : m->node[a->frame], a->weight};
    }
    return POSE_OK;
}
