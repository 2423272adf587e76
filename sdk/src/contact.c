/* SPDX-License-Identifier: Apache-2.0 */
/* pose/contact.h: collision detection between posed skin and bones. */
#include "pose/contact.h"

#include <stddef.h>
#include <string.h>

#include "alloc.h"
#include "contact_build.h"
#include "error.h"
#include "rt_bvh.h"
#include "rt_thread.h"
#include "state_internal.h"

enum { COUNT_PAIRS, COUNT_SKIN_IN_BONE, COUNT_BONE_OUT, COUNT_BONE_PAIRS, COUNT_KINDS };

/* The counts' first layout (no bone_pairs), still accepted. */
#define COUNTS_SIZE_FIRST offsetof(pose_contact_counts, bone_pairs)

struct pose_contact {
    const pose_rig *rig;
    pose_allocator allocator;
    pose__pool *pool;
    pose__bvh skin, bone;       /* trees over the skin's and the bones' triangles */
    uint32_t *skin_tris, *bone_tris; /* 3 per triangle, indices into all tissue vertices */
    uint32_t *skin_verts, *bone_verts; /* the tissue vertices of each kind */
    uint32_t *bone_tri_tissue;  /* per bone triangle: its tissue (bone pairs are between two) */
    uint32_t *bone_node_tissue; /* per node of the bone tree: its one tissue, or POSE__BVH_MIXED */
    size_t skin_vert_count, bone_vert_count;
    uint8_t *flags;             /* POSE_CONTACT_* per tissue vertex, all tissues */
    size_t (*part_counts)[COUNT_KINDS]; /* per part of the last detection */
    const float *positions;     /* the detection's posed tissue vertices */
};

/* Gather the triangles and vertices of the tissues of one kind, with
 * indices into the whole tissue vertex array (rt->tissue_offset). */
static pose_status gather(pose_contact *c, pose_tissue_kind kind, uint32_t **tris, uint32_t *tri_count,
                          uint32_t **verts, size_t *vert_count, uint32_t **tri_tissue)
{
    const pose_rig *rig = c->rig;
    size_t nt = 0, nv = 0;
    for (size_t t = 0; t < rig->tissue_count; t++)
        if (rig->tissues[t].kind == kind) {
            nt += rig->tissues[t].triangle_count;
            nv += rig->tissues[t].vertex_count;
        }
    if (nt > UINT32_MAX / 4)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_contact_create: %zu triangles", nt);
    *tris = pose__alloc(&c->allocator, (3 * nt + 1) * sizeof(uint32_t), POSE__ALIGN);
    *verts = pose__alloc(&c->allocator, (nv + 1) * sizeof(uint32_t), POSE__ALIGN);
    if (tri_tissue)
        *tri_tissue = pose__alloc(&c->allocator, (nt + 1) * sizeof(uint32_t), POSE__ALIGN);
    if (!*tris || !*verts || (tri_tissue && !*tri_tissue))
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu contact triangles", nt);
    size_t it = 0, iv = 0;
    for (size_t t = 0; t < rig->tissue_count; t++) {
        const pose__tissue *ti = &rig->tissues[t];
        if (ti->kind != kind)
            continue;
        const uint32_t base = (uint32_t)rig->rt->tissue_offset[t];
        if (tri_tissue)
            for (size_t f = 0; f < ti->triangle_count; f++)
                (*tri_tissue)[it / 3 + f] = (uint32_t)t;
        for (size_t k = 0; k < 3 * ti->triangle_count; k++)
            (*tris)[it++] = base + ti->triangles[k];
        for (size_t v = 0; v < ti->vertex_count; v++)
            (*verts)[iv++] = base + (uint32_t)v;
    }
    *tri_count = (uint32_t)nt;
    *vert_count = nv;
    return POSE_OK;
}

void pose_contact_free(pose_contact *c)
{
    if (!c)
        return;
    const pose_allocator a = c->allocator;
    if (c->pool) {
        pose__pool_destroy(c->pool);
        pose__free(&a, c->pool);
    }
    pose__bvh_release(&c->skin, &a);
    pose__bvh_release(&c->bone, &a);
    pose__free(&a, c->skin_tris);
    pose__free(&a, c->bone_tris);
    pose__free(&a, c->skin_verts);
    pose__free(&a, c->bone_verts);
    pose__free(&a, c->bone_tri_tissue);
    pose__free(&a, c->bone_node_tissue);
    pose__free(&a, c->flags);
    pose__free(&a, c->part_counts);
    pose__free(&a, c);
}

/* Rest positions of every tissue vertex, in the layout of the posed ones. */
static float *rest_positions(const pose_contact *c)
{
    const pose_rig *rig = c->rig;
    const size_t n = rig->rt->tissue_offset[rig->tissue_count];
    float *x = pose__alloc(&c->allocator, (3 * n + 1) * sizeof(float), POSE__ALIGN);
    if (x)
        for (size_t t = 0; t < rig->tissue_count; t++)
            memcpy(x + 3 * rig->rt->tissue_offset[t], rig->tissues[t].positions,
                   3 * rig->tissues[t].vertex_count * sizeof(float));
    return x;
}

static pose_status build(pose_contact *c, unsigned threads)
{
    uint32_t skin_tri_count, bone_tri_count;
    pose_status s = gather(c, POSE_TISSUE_SKIN, &c->skin_tris, &skin_tri_count, &c->skin_verts,
                           &c->skin_vert_count, NULL);
    if (s == POSE_OK)
        s = gather(c, POSE_TISSUE_BONE, &c->bone_tris, &bone_tri_count, &c->bone_verts,
                   &c->bone_vert_count, &c->bone_tri_tissue);
    if (s != POSE_OK)
        return s;
    const size_t n = c->rig->rt->tissue_offset[c->rig->tissue_count];
    c->flags = pose__calloc(&c->allocator, n + 1, POSE__ALIGN);
    c->part_counts = pose__calloc(&c->allocator, threads * sizeof *c->part_counts, POSE__ALIGN);
    float *rest = rest_positions(c);
    if (!c->flags || !c->part_counts || !rest) {
        pose__free(&c->allocator, rest);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for contact flags");
    }
    s = pose__bvh_build(&c->skin, &c->allocator, c->skin_tris, skin_tri_count, rest);
    if (s == POSE_OK)
        s = pose__bvh_build(&c->bone, &c->allocator, c->bone_tris, bone_tri_count, rest);
    if (s == POSE_OK) /* each refit reads a vertex once */
        s = pose__bvh_index_corners(&c->skin, &c->allocator);
    if (s == POSE_OK)
        s = pose__bvh_index_corners(&c->bone, &c->allocator);
    pose__free(&c->allocator, rest);
    if (s != POSE_OK)
        return s;
    c->bone_node_tissue = pose__alloc(&c->allocator, (c->bone.node_count + 1) * sizeof(uint32_t), POSE__ALIGN);
    if (!c->bone_node_tissue)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for the bone tree's parts");
    pose__bvh_node_parts(&c->bone, c->bone_tri_tissue, c->bone_node_tissue);
    c->pool = pose__alloc(&c->allocator, pose__pool_size(threads), POSE__ALIGN);
    if (!c->pool)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a pool of %u threads", threads);
    if (pose__pool_init(c->pool, threads) != 0) {
        pose__free(&c->allocator, c->pool);
        c->pool = NULL;
        return pose__fail(POSE_ERR_THREAD, "could not start %u worker threads", threads - 1);
    }
    return POSE_OK;
}

pose_status pose_contact_create(const pose_rig *rig, const pose_contact_options *options,
                                pose_contact **out)
{
    pose__clear_error();
    if (out)
        *out = NULL;
    if (!rig || !out)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_contact_create: rig and out are required");
    pose_contact_options opt = {0};
    if (options) {
        if (options->size != 0 && options->size != sizeof opt)
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "pose_contact_create: options.size %zu (expected %zu or 0)",
                              options->size, sizeof opt);
        opt = *options;
    }
    if (!pose__allocator_valid(&opt.allocator) || opt.threads < 0)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_contact_create: allocator needs both alloc and free, threads >= 0");
    unsigned threads = opt.threads > 0 ? (unsigned)opt.threads : pose__cpu_count();
    if (threads > POSE__MAX_THREADS)
        threads = POSE__MAX_THREADS;
    const pose_allocator a = pose__allocator_resolve(&opt.allocator);
    pose_contact *c = pose__calloc(&a, sizeof *c, POSE__ALIGN);
    if (!c)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a pose_contact");
    c->rig = rig;
    c->allocator = a;
    const pose_status s = build(c, threads);
    if (s != POSE_OK) {
        pose_contact_free(c);
        return s;
    }
    *out = c;
    return POSE_OK;
}

static void refit_task(void *ctx, unsigned part, unsigned parts)
{
    pose_contact *c = ctx;
    pose__bvh *trees[2] = {&c->skin, &c->bone};
    for (int k = 0; k < 2; k++)
        pose__bvh_refit_leaves(trees[k], c->positions, pose__part_begin(trees[k]->leaf_count, part, parts),
                               pose__part_begin(trees[k]->leaf_count, part + 1, parts));
}

/* Skin in bone needs the rays along +x and -x to agree: on a closed mesh
 * they always do, on an open one (a few bone meshes are) one of them can
 * count a crossing the other does not. */
static const float minus_x[3] = {-1.0f, 0.0f, 0.0f};

/* Self-intersection tasks dealt round-robin (neighbouring tasks are
 * neighbouring body parts, of similar cost); vertices in ranges. */
static void detect_task(void *ctx, unsigned part, unsigned parts)
{
    pose_contact *c = ctx;
    size_t *n = c->part_counts[part];
    n[COUNT_PAIRS] = n[COUNT_SKIN_IN_BONE] = n[COUNT_BONE_OUT] = n[COUNT_BONE_PAIRS] = 0;
    if (c->skin.node_count)
        for (uint32_t i = part; i < c->skin.split_count; i += parts)
            n[COUNT_PAIRS] += pose__bvh_self_task(&c->skin, c->positions, i);
    if (c->bone.node_count)
        for (uint32_t i = part; i < c->bone.split_count; i += parts)
            n[COUNT_BONE_PAIRS] += pose__bvh_self_task_parts(&c->bone, c->positions, i, c->bone_tri_tissue,
                                                             c->bone_node_tissue);
    const size_t sb = pose__part_begin(c->skin_vert_count, part, parts),
                 se = pose__part_begin(c->skin_vert_count, part + 1, parts);
    for (size_t i = sb; i < se; i++) {
        const uint32_t v = c->skin_verts[i];
        const float *x = c->positions + 3 * (size_t)v;
        const int in = c->bone.node_count && pose__bvh_winding(&c->bone, c->positions, x) > 0 &&
                       pose__bvh_winding_along(&c->bone, c->positions, x, minus_x) > 0;
        c->flags[v] = in ? POSE_CONTACT_SKIN_IN_BONE : 0;
        n[COUNT_SKIN_IN_BONE] += (size_t)in;
    }
    const size_t bb = pose__part_begin(c->bone_vert_count, part, parts),
                 be = pose__part_begin(c->bone_vert_count, part + 1, parts);
    for (size_t i = bb; i < be; i++) {
        const uint32_t v = c->bone_verts[i];
        const int out = c->skin.node_count && pose__bvh_winding(&c->skin, c->positions, c->positions + 3 * (size_t)v) <= 0;
        c->flags[v] = out ? POSE_CONTACT_BONE_OUT_OF_SKIN : 0;
        n[COUNT_BONE_OUT] += (size_t)out;
    }
}

pose_status pose_contact_detect(pose_contact *c, const pose_state *st, pose_contact_counts *out)
{
    pose__clear_error();
    if (!c || !st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_contact_detect: contact and state are required");
    if (st->rig != c->rig)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_contact_detect: the state is of another rig");
    if (out && out->size != sizeof *out && out->size != COUNTS_SIZE_FIRST)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_contact_detect: out->size %zu (expected %zu, or %zu for the first layout)",
                          out->size, sizeof *out, (size_t)COUNTS_SIZE_FIRST);
    const double t0 = pose__seconds();
    c->positions = st->tissue_positions;
    pose__pool_run(c->pool, refit_task, c);
    if (c->skin.node_count)
        pose__bvh_refit_inner(&c->skin);
    if (c->bone.node_count)
        pose__bvh_refit_inner(&c->bone);
    pose__pool_run(c->pool, detect_task, c);
    size_t sum[COUNT_KINDS] = {0};
    for (unsigned p = 0; p < pose__pool_threads(c->pool); p++)
        for (int k = 0; k < COUNT_KINDS; k++)
            sum[k] += c->part_counts[p][k];
    if (out) {
        out->skin_pairs = sum[COUNT_PAIRS];
        out->skin_in_bone = sum[COUNT_SKIN_IN_BONE];
        out->bone_out_of_skin = sum[COUNT_BONE_OUT];
        out->seconds = pose__seconds() - t0;
        if (out->size == sizeof *out)
            out->bone_pairs = sum[COUNT_BONE_PAIRS];
    }
    return POSE_OK;
}

const uint8_t *pose_contact_vertex_flags(const pose_contact *c, int tissue, size_t *vertex_count)
{
    if (vertex_count)
        *vertex_count = 0;
    if (!c || tissue < 0 || (size_t)tissue >= c->rig->tissue_count)
        return NULL;
    if (vertex_count)
        *vertex_count = c->rig->tissues[tissue].vertex_count;
    return c->flags + c->rig->rt->tissue_offset[tissue];
}
