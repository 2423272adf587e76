/* SPDX-License-Identifier: Apache-2.0 */
/* Soft-soft couplings on a state (pose.h pose_fem_soft_coupling): soft
 * simulation nodes tied to points of the tet mesh by zero-length springs,
 * in POSE_FEM and pose_step (runtime/fem_links.h). A state starts with its
 * rig's; pose_set_fem_soft_couplings replaces them and joins a running
 * simulation's islands again. Everything in one block of the state's
 * allocator: the springs in effect, their per-vertex diagonal and the
 * solvers' product scratch. */
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "state_internal.h"

static size_t align64(size_t n)
{
    return (n + 63u) & ~(size_t)63u;
}

/* A spring the simulation can move at both ends: every weighted node a
 * free soft vertex (held ones are tied to their bone already). */
static int in_effect(const pose__fem_mesh *m, const pose__soft_coupling_record *r)
{
    if (!(m->inv_diag[r->node] > 0.0f))
        return 0;
    for (int c = 0; c < 4; c++)
        if (r->weight[c] != 0.0f && !(m->inv_diag[r->other[c]] > 0.0f))
            return 0;
    return 1;
}

static const pose__soft_coupling_record *entry(const void *src, size_t i, size_t stride)
{
    return (const pose__soft_coupling_record *)(const void *)((const unsigned char *)src +
                                                              i * stride);
}

/* Build the state's soft couplings from n checked entries `stride` bytes
 * apart (the previous ones freed only once the new block exists). */
static pose_status build(pose_state *st, const void *src, size_t n, size_t stride, const char *fn)
{
    pose_status built = n ? pose__rig_fem_mesh(st->rig, fn) : POSE_OK; /* which nodes it holds */
    if (built < 0)
        return built;
    const pose__fem_mesh *m = &st->rt->fem;
    const size_t nv = st->rig->tet_vertex_count;
    size_t live = 0;
    for (size_t i = 0; i < n; i++)
        live += (size_t)in_effect(m, entry(src, i, stride));
    void *block = NULL;
    size_t touched = 0;
    if (live) {
        /* touched <= 5 live: sized for the most, counted below */
        const size_t size = align64(live * sizeof(uint32_t)) + align64(4 * live * sizeof(uint32_t)) +
                            align64(4 * live * sizeof(float)) + align64(live * sizeof(float)) +
                            align64(5 * live * sizeof(uint32_t)) + align64(nv * sizeof(float)) +
                            2 * align64(3 * nv * sizeof(float));
        block = pose__alloc(&st->allocator, size, POSE__ALIGN);
        if (!block)
            return pose__fail(POSE_ERR_OUT_OF_MEMORY,
                              "%s: out of memory for %zu soft couplings (%zu bytes)", fn, live, size);
    }
    pose__state_links_free(st);
    if (!live)
        return POSE_OK;
    unsigned char *b = block;
    uint32_t *node = (uint32_t *)(void *)b, *corner, *touch;
    float *weight, *k, *diag, *out, *out2;
    b += align64(live * sizeof(uint32_t));
    corner = (uint32_t *)(void *)b;
    b += align64(4 * live * sizeof(uint32_t));
    weight = (float *)(void *)b;
    b += align64(4 * live * sizeof(float));
    k = (float *)(void *)b;
    b += align64(live * sizeof(float));
    touch = (uint32_t *)(void *)b;
    b += align64(5 * live * sizeof(uint32_t));
    diag = (float *)(void *)b;
    b += align64(nv * sizeof(float));
    out = (float *)(void *)b;
    b += align64(3 * nv * sizeof(float));
    out2 = (float *)(void *)b;
    memset(diag, 0, nv * sizeof(float));
    memset(out, 0, 3 * nv * sizeof(float));
    memset(out2, 0, 3 * nv * sizeof(float));
    size_t j = 0;
    for (size_t i = 0; i < n; i++) {
        const pose__soft_coupling_record *r = entry(src, i, stride);
        if (!in_effect(m, r))
            continue;
        node[j] = r->node;
        /* the node's own elastic stiffness at rest is the inverse of its
         * Jacobi weight, as for the bone couplings (state_coupling.c) */
        k[j] = r->stiffness / m->inv_diag[r->node];
        diag[r->node] += k[j];
        out[3 * (size_t)r->node] = 1.0f; /* reached: listed below */
        for (int c = 0; c < 4; c++) {
            const int used = r->weight[c] != 0.0f;
            corner[4 * j + (size_t)c] = used ? r->other[c] : 0u;
            weight[4 * j + (size_t)c] = used ? r->weight[c] : 0.0f;
            if (used) {
                diag[r->other[c]] += k[j] * r->weight[c] * r->weight[c];
                out[3 * (size_t)r->other[c]] = 1.0f;
            }
        }
        j++;
    }
    for (size_t v = 0; v < nv; v++)
        if (out[3 * v] != 0.0f) {
            touch[touched++] = (uint32_t)v;
            out[3 * v] = 0.0f;
        }
    st->lnk_block = block;
    st->links = (pose__fem_links){.count = live, .node = node, .corner = corner, .weight = weight,
                                  .k = k, .touched_count = touched, .touched = touch,
                                  .diag = diag, .out = out, .out2 = out2};
    return POSE_OK;
}

pose_status pose__state_links_init(pose_state *st)
{
    const pose_rig *rig = st->rig;
    if (!rig->soft_couplings || !pose_rig_has_fem(rig))
        return POSE_OK;
    return build(st, rig->soft_couplings, rig->soft_coupling_count,
                 sizeof(pose__soft_coupling_record), "pose_state_create");
}

void pose__state_links_free(pose_state *st)
{
    if (st->lnk_block)
        pose__free(&st->allocator, st->lnk_block);
    st->lnk_block = NULL;
    memset(&st->links, 0, sizeof st->links);
}

const pose__fem_links *pose__state_links(pose_state *st)
{
    return st->links.count ? &st->links : NULL;
}

void pose__state_links_islands(pose_state *st, uint32_t *scratch)
{
    pose__fem_dyn_link(&st->rt->fem, pose__state_links(st), scratch, &st->dyn);
    st->dyn_stats.islands = (int)st->dyn.island_count;
}

pose_status pose_set_fem_soft_couplings(pose_state *st, const pose_fem_soft_coupling *c,
                                        size_t count, size_t element_size)
{
    static const char fn[] = "pose_set_fem_soft_couplings";
    pose__clear_error();
    if (!st || (count && !c))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: state is NULL, or couplings with a count",
                          fn);
    if (count && element_size < sizeof(pose_fem_soft_coupling))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "%s: element_size %zu is below the 0.2 layout (%zu)", fn, element_size,
                          sizeof(pose_fem_soft_coupling));
    if (!pose_rig_has_fem(st->rig))
        return pose__fail(POSE_ERR_UNSUPPORTED, "%s: the rig has no fem section", fn);
    for (size_t i = 0; i < count; i++) {
        char why[128];
        size_t at;
        if (pose__soft_coupling_fault(entry(c, i, element_size), st->rig->tet_vertex_count, why,
                                      sizeof why, &at))
            return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: soft coupling %zu: %s", fn, i, why);
    }
    /* a running simulation's islands are joined again: scratch first, so
     * that a failure leaves everything as it was */
    uint32_t *scratch = NULL;
    if (st->dyn_block) {
        scratch = pose__alloc(&st->allocator,
                              st->rig->tet_vertex_count * sizeof(uint32_t) + 64, POSE__ALIGN);
        if (!scratch)
            return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: out of memory for the islands", fn);
    }
    pose_status s = build(st, c, count, element_size, fn);
    if (s == POSE_OK && scratch)
        pose__state_links_islands(st, scratch);
    if (scratch)
        pose__free(&st->allocator, scratch);
    return s;
}

size_t pose_fem_soft_coupling_count(const pose_state *st)
{
    return st ? st->links.count : 0;
}
