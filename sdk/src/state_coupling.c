/* SPDX-License-Identifier: Apache-2.0 */
/* Couplings on a state (pose.h pose_fem_coupling): soft simulation nodes
 * tied to a bone's rigid motion by zero-length springs, in POSE_FEM and
 * pose_step. A state starts with its rig's; pose_set_fem_couplings
 * replaces them. The solvers read a per-vertex spring stiffness (0 where
 * nothing is coupled) and target, in the state's own allocation. */
#include <math.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "state_internal.h"

/* One coupling as the builder reads it, from the rig or the caller. */
typedef struct cpl_in {
    uint32_t node, joint;
    float stiffness, anchor[3];
} cpl_in;

typedef const cpl_in *(*cpl_get)(const void *src, size_t i, size_t stride, cpl_in *tmp);

static const cpl_in *from_rig(const void *src, size_t i, size_t stride, cpl_in *tmp)
{
    (void)stride;
    const pose__coupling_record *r = (const pose__coupling_record *)src + i;
    *tmp = (cpl_in){.node = r->node, .joint = r->joint, .stiffness = r->stiffness};
    memcpy(tmp->anchor, r->anchor, sizeof tmp->anchor);
    return tmp;
}

static const cpl_in *from_api(const void *src, size_t i, size_t stride, cpl_in *tmp)
{
    const pose_fem_coupling *c =
        (const pose_fem_coupling *)(const void *)((const unsigned char *)src + i * stride);
    *tmp = (cpl_in){.node = c->node, .joint = (uint32_t)c->joint, .stiffness = c->stiffness};
    memcpy(tmp->anchor, c->anchor, sizeof tmp->anchor);
    return tmp;
}

static size_t align64(size_t n)
{
    return (n + 63u) & ~(size_t)63u;
}

/* Build the state's couplings from n checked entries (the previous ones
 * are freed only once the new block exists). */
static pose_status build(pose_state *st, const void *src, size_t n, size_t stride, cpl_get get,
                         const char *fn)
{
    pose_status built = n ? pose__rig_fem_mesh(st->rig, fn) : POSE_OK; /* which nodes it holds */
    if (built < 0)
        return built;
    const pose__fem_mesh *m = &st->rt->fem;
    const size_t nv = st->rig->tet_vertex_count;
    size_t live = 0;
    cpl_in tmp;
    for (size_t i = 0; i < n; i++)
        live += m->inv_diag[get(src, i, stride, &tmp)->node] > 0.0f;
    void *block = NULL;
    if (live) {
        const size_t size = 2 * align64(live * sizeof(uint32_t)) + align64(3 * live * sizeof(float)) +
                            align64(nv * sizeof(float)) + align64(3 * nv * sizeof(float));
        block = pose__alloc(&st->allocator, size, POSE__ALIGN);
        if (!block)
            return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu couplings (%zu bytes)",
                              fn, live, size);
    }
    pose__state_couplings_free(st);
    if (!live)
        return POSE_OK;
    unsigned char *b = block;
    st->cpl_block = block;
    st->cpl_node = (uint32_t *)(void *)b;
    b += align64(live * sizeof(uint32_t));
    st->cpl_joint = (uint32_t *)(void *)b;
    b += align64(live * sizeof(uint32_t));
    st->cpl_anchor = (float *)(void *)b;
    b += align64(3 * live * sizeof(float));
    st->cpl_spring = (float *)(void *)b;
    b += align64(nv * sizeof(float));
    st->cpl_target = (float *)(void *)b;
    memset(st->cpl_spring, 0, nv * sizeof(float));
    memcpy(st->cpl_target, st->rig->tet_positions, 3 * nv * sizeof(float));
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        const cpl_in *c = get(src, i, stride, &tmp);
        const float id = m->inv_diag[c->node];
        if (!(id > 0.0f)) /* held by a bone tet, or not simulated */
            continue;
        st->cpl_node[k] = c->node;
        st->cpl_joint[k] = c->joint;
        memcpy(st->cpl_anchor + 3 * k, c->anchor, sizeof c->anchor);
        /* the Jacobi weight is the inverse of the node's own elastic
         * stiffness at rest (trace / 3 of its block), as the dynamics' */
        st->cpl_spring[c->node] = c->stiffness / id;
        k++;
    }
    st->cpl_count = k;
    return POSE_OK;
}

pose_status pose__state_couplings_init(pose_state *st)
{
    const pose_rig *rig = st->rig;
    if (!rig->couplings || !pose_rig_has_fem(rig))
        return POSE_OK;
    return build(st, rig->couplings, rig->coupling_count, 0, from_rig, "pose_state_create");
}

void pose__state_couplings_free(pose_state *st)
{
    if (st->cpl_block)
        pose__free(&st->allocator, st->cpl_block);
    st->cpl_block = NULL;
    st->cpl_count = 0;
    st->cpl_node = st->cpl_joint = NULL;
    st->cpl_anchor = st->cpl_spring = st->cpl_target = NULL;
}

const float *pose__state_couplings_place(pose_state *st)
{
    if (!st->cpl_count)
        return NULL;
    for (size_t i = 0; i < st->cpl_count; i++) {
        const pose__xform *x = &st->skin[st->cpl_joint[i]];
        float R[9];
        pose__quat_to_matrix(x->q, R); /* a few joints: cheaper than caching per joint */
        const float *a = st->cpl_anchor + 3 * i;
        float *t = st->cpl_target + 3 * (size_t)st->cpl_node[i];
        for (int k = 0; k < 3; k++)
            t[k] = R[3 * k] * a[0] + R[3 * k + 1] * a[1] + R[3 * k + 2] * a[2] + x->t[k];
    }
    return st->cpl_spring;
}

const float *pose__state_couplings_bones(pose_state *st)
{
    const float *spring = pose__state_couplings_place(st);
    for (size_t i = 0; i < st->cpl_count; i++)
        memcpy(st->tet_positions + 3 * (size_t)st->cpl_node[i],
               st->cpl_target + 3 * (size_t)st->cpl_node[i], 3 * sizeof(float));
    return spring;
}

pose_status pose_set_fem_couplings(pose_state *st, const pose_fem_coupling *c, size_t count,
                                   size_t element_size)
{
    static const char fn[] = "pose_set_fem_couplings";
    pose__clear_error();
    if (!st || (count && !c))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: state is NULL, or couplings with a count",
                          fn);
    if (count && element_size < sizeof(pose_fem_coupling))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "%s: element_size %zu is below the 0.2 layout (%zu)", fn, element_size,
                          sizeof(pose_fem_coupling));
    if (!pose_rig_has_fem(st->rig))
        return pose__fail(POSE_ERR_UNSUPPORTED, "%s: the rig has no fem section", fn);
    const pose_rig *rig = st->rig;
    const size_t nv = rig->tet_vertex_count;
    /* Every node once: a bit per tet vertex. */
    uint32_t *seen = NULL;
    if (count) {
        seen = pose__alloc(&st->allocator, (nv + 31) / 32 * sizeof(uint32_t) + 64, POSE__ALIGN);
        if (!seen)
            return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
        memset(seen, 0, (nv + 31) / 32 * sizeof(uint32_t));
    }
    pose_status s = POSE_OK;
    for (size_t i = 0; i < count && s == POSE_OK; i++) {
        const pose_fem_coupling *e =
            (const pose_fem_coupling *)(const void *)((const unsigned char *)c + i * element_size);
        int finite = isfinite(e->stiffness);
        for (int a = 0; a < 3; a++)
            finite = finite && isfinite(e->anchor[a]);
        if (e->node >= nv)
            s = pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: coupling %zu: node %u is not a tet vertex "
                           "(%zu)", fn, i, (unsigned)e->node, nv);
        else if (e->joint < 0 || (size_t)e->joint >= rig->joint_count)
            s = pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: coupling %zu: joint %d (the rig has %zu)",
                           fn, i, e->joint, rig->joint_count);
        else if (!finite || !(e->stiffness > 0.0f))
            s = pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: coupling %zu: stiffness %g (finite, > 0) "
                           "or anchor not finite", fn, i, (double)e->stiffness);
        else if (seen[e->node / 32] & (1u << (e->node % 32)))
            s = pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: coupling %zu: node %u listed twice", fn,
                           i, (unsigned)e->node);
        else
            seen[e->node / 32] |= 1u << (e->node % 32);
    }
    if (seen)
        pose__free(&st->allocator, seen);
    if (s < 0)
        return s;
    return build(st, c, count, element_size, from_api, fn);
}

size_t pose_fem_coupling_count(const pose_state *st)
{
    return st ? st->cpl_count : 0;
}
