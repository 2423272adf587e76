/* SPDX-License-Identifier: Apache-2.0 */
/* Content checks every rig passes before use, whether it comes from a file,
 * a buffer or a description: names, hierarchy, indices in range, finite
 * values, weights and barycentric coordinates that sum to one. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "rig_io.h"

/** Tolerance on sums that must be 1 (weights, barycentric coordinates). */
#define SUM_TOLERANCE 1e-4f
/** Tolerance on |q| - 1 for rest rotations. */
#define UNIT_TOLERANCE 1e-4f

static bool finite3(const float *v)
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* Name in a 64-byte slot: NUL-terminated and non-empty. */
static pose_status check_slot_name(const pose__source *src, const char *section, const char *what,
                                   size_t index, const char *name)
{
    size_t n = strnlen(name, POSE__NAME_SIZE);
    if (n == POSE__NAME_SIZE)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, section, name,
                                 "%s %zu: name is not NUL-terminated within %d bytes", what, index,
                                 POSE__NAME_SIZE);
    if (n == 0)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, section, name,
                                 "%s %zu: empty name", what, index);
    return POSE_OK;
}

typedef struct name_ref {
    const char *name;
    size_t index;
} name_ref;

static int cmp_name(const void *a, const void *b)
{
    const name_ref *x = a, *y = b;
    int c = strcmp(x->name, y->name);
    return c ? c : (x->index < y->index ? -1 : x->index > y->index);
}

/* Sorting finds duplicates in O(n log n); joints may number tens of thousands. */
static pose_status check_unique(const pose__source *src, const char *section, const char *what, name_ref *refs, size_t n)
{
    qsort(refs, n, sizeof *refs, cmp_name);
    for (size_t i = 1; i < n; i++)
        if (strcmp(refs[i - 1].name, refs[i].name) == 0)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, section, refs[i].name,
                                     "%s %zu has the same name '%s' as %s %zu", what,
                                     refs[i].index, refs[i].name, what, refs[i - 1].index);
    return POSE_OK;
}

static pose_status check_skeleton(const pose_rig *rig, const pose__source *src, name_ref *refs)
{
    const char *sec = "skeleton";
    for (size_t j = 0; j < rig->joint_count; j++) {
        const char *name = pose__joint_name(rig, j);
        pose_status st = check_slot_name(src, sec, "joint", j, name);
        if (st != POSE_OK)
            return st;
        refs[j] = (name_ref){name, j};
    }
    pose_status st = check_unique(src, sec, "joint", refs, rig->joint_count);
    if (st != POSE_OK)
        return st;
    for (size_t j = 0; j < rig->joint_count; j++) {
        const char *name = pose__joint_name(rig, j);
        int32_t p = rig->joint_parents[j];
        if (p < -1 || p >= (int64_t)j)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, &rig->joint_parents[j],
                                     "joint %zu ('%s'): parent %d does not come before it "
                                     "(parents must precede children; -1 for a root)",
                                     j, name, (int)p);
        const pose_transform *m = &rig->joint_rest_model[j];
        const float *q = m->rotation;
        if (!finite3(q) || !isfinite(q[3]) || !finite3(m->translation))
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, m,
                                     "joint %zu ('%s'): rest transform is not finite", j, name);
        float len = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (fabsf(len - 1.0f) > UNIT_TOLERANCE)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, m,
                                     "joint %zu ('%s'): rest rotation has length %.6g, "
                                     "expected a unit quaternion", j, name, (double)len);
        const pose__joint_limit *l = &rig->joint_limits[j];
        if (l->flags & ~(uint32_t)(POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z) ||
            l->order > POSE_EULER_ZYX)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, l,
                                     "joint %zu ('%s'): limit flags 0x%x or Euler order %u unknown",
                                     j, name, l->flags, l->order);
        for (int a = 0; a < 3; a++)
            if ((l->flags & (1u << a)) &&
                (!isfinite(l->min_deg[a]) || !isfinite(l->max_deg[a]) ||
                 l->min_deg[a] > l->max_deg[a]))
                return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, l,
                                         "joint %zu ('%s'): limit on axis %c is [%g, %g]", j, name,
                                         "xyz"[a], (double)l->min_deg[a], (double)l->max_deg[a]);
    }
    return POSE_OK;
}

static pose_status check_tetmesh(const pose_rig *rig, const pose__source *src)
{
    const char *sec = "tetmesh";
    size_t nv = rig->tet_vertex_count;
    for (size_t v = 0; v < nv; v++)
        if (!finite3(&rig->tet_positions[3 * v]))
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, &rig->tet_positions[3 * v],
                                     "vertex %zu: position is not finite", v);
    for (size_t t = 0; t < rig->tet_count; t++) {
        const uint32_t *c = &rig->tets[4 * t];
        for (int k = 0; k < 4; k++) {
            if (c[k] >= nv)
                return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, &c[k],
                                         "tet %zu: vertex index %u out of range (%zu vertices)",
                                         t, c[k], nv);
            for (int m = 0; m < k; m++)
                if (c[m] == c[k])
                    return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, &c[k],
                                             "tet %zu: vertex %u appears twice", t, c[k]);
        }
        if (rig->tet_labels[t] > rig->joint_count)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, &rig->tet_labels[t],
                                     "tet %zu: label %u names no joint (labels are 0 or joint + 1, "
                                     "%zu joints)", t, rig->tet_labels[t], rig->joint_count);
    }
    return POSE_OK;
}

static pose_status check_weights(const pose_rig *rig, const pose__source *src)
{
    const char *sec = "weights";
    unsigned k = rig->influences;
    for (size_t v = 0; v < rig->tet_vertex_count; v++) {
        const uint16_t *j = &rig->weight_joints[v * k];
        const float *w = &rig->weights[v * k];
        float sum = 0.0f;
        for (unsigned i = 0; i < k; i++) {
            if (j[i] >= rig->joint_count)
                return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, &j[i],
                                         "vertex %zu: influence %u names joint %u, the skeleton "
                                         "has %zu", v, i, j[i], rig->joint_count);
            if (!isfinite(w[i]) || w[i] < 0.0f)
                return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, &w[i],
                                         "vertex %zu: weight %u is %g (weights are finite and "
                                         ">= 0)", v, i, (double)w[i]);
            sum += w[i];
        }
        if (fabsf(sum - 1.0f) > SUM_TOLERANCE)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, w,
                                     "vertex %zu: weights sum to %.7g, expected 1 (tolerance "
                                     "1e-4)", v, (double)sum);
    }
    if (rig->cor)
        for (size_t v = 0; v < rig->tet_vertex_count; v++)
            if (!finite3(&rig->cor[3 * v]))
                return pose__source_fail(src, POSE_ERR_INVALID_DATA, "cor", &rig->cor[3 * v],
                                         "vertex %zu: centre of rotation is not finite", v);
    return POSE_OK;
}

static pose_status check_tissue(const pose_rig *rig, const pose__source *src, size_t t)
{
    const char *sec = "tissues";
    const pose__tissue *ts = &rig->tissues[t];
    if ((uint32_t)ts->kind > POSE_TISSUE_OTHER)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, ts->name + 64,
                                 "tissue %zu ('%s'): kind %u unknown", t, ts->name,
                                 (unsigned)ts->kind);
    if (ts->joint < -1 || ts->joint >= (int64_t)rig->joint_count)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, ts->name + 68,
                                 "tissue %zu ('%s'): joint %d out of range (%zu joints)", t,
                                 ts->name, (int)ts->joint, rig->joint_count);
    for (size_t v = 0; v < ts->vertex_count; v++) {
        if (!finite3(&ts->positions[3 * v]))
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, &ts->positions[3 * v],
                                     "tissue %zu ('%s'): vertex %zu position is not finite", t,
                                     ts->name, v);
        if (ts->tet[v] >= rig->tet_count)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, &ts->tet[v],
                                     "tissue %zu ('%s'): vertex %zu embedded in tet %u, the mesh "
                                     "has %zu", t, ts->name, v, ts->tet[v], rig->tet_count);
        const float *b = &ts->bary[4 * v];
        if (!finite3(b) || !isfinite(b[3]))
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, b,
                                     "tissue %zu ('%s'): vertex %zu barycentric coordinates are "
                                     "not finite", t, ts->name, v);
        float sum = b[0] + b[1] + b[2] + b[3];
        if (fabsf(sum - 1.0f) > SUM_TOLERANCE)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, b,
                                     "tissue %zu ('%s'): vertex %zu barycentric coordinates sum "
                                     "to %.7g, expected 1 (tolerance 1e-4)", t, ts->name, v,
                                     (double)sum);
    }
    for (size_t i = 0; i < 3 * ts->triangle_count; i++)
        if (ts->triangles[i] >= ts->vertex_count)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, sec, &ts->triangles[i],
                                     "tissue %zu ('%s'): triangle %zu uses vertex %u, the tissue "
                                     "has %zu", t, ts->name, i / 3, ts->triangles[i],
                                     ts->vertex_count);
    return POSE_OK;
}

static pose_status check_tissues(const pose_rig *rig, const pose__source *src, name_ref *refs)
{
    for (size_t t = 0; t < rig->tissue_count; t++) {
        pose_status st = check_slot_name(src, "tissues", "tissue", t, rig->tissues[t].name);
        if (st != POSE_OK)
            return st;
        refs[t] = (name_ref){rig->tissues[t].name, t};
    }
    pose_status st = check_unique(src, "tissues", "tissue", refs, rig->tissue_count);
    for (size_t t = 0; st == POSE_OK && t < rig->tissue_count; t++)
        st = check_tissue(rig, src, t);
    return st;
}

pose_status pose__rig_validate(const pose_rig *rig, const pose__source *src)
{
    size_t n = rig->joint_count > rig->tissue_count ? rig->joint_count : rig->tissue_count;
    name_ref *refs = pose__alloc(&rig->allocator, (n ? n : 1) * sizeof *refs, POSE__ALIGN);
    if (!refs)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: cannot allocate the name index", src->name);
    pose_status st = check_skeleton(rig, src, refs);
    if (st == POSE_OK)
        st = check_tetmesh(rig, src);
    if (st == POSE_OK)
        st = check_weights(rig, src);
    if (st == POSE_OK)
        st = check_tissues(rig, src, refs);
    if (st == POSE_OK)
        st = pose__clinical_validate(rig, src);
    if (st == POSE_OK)
        st = pose__fem_validate(rig, src);
    if (st == POSE_OK)
        st = pose__couplings_validate(rig, src);
    if (st == POSE_OK)
        st = pose__soft_couplings_validate(rig, src);
    pose__free(&rig->allocator, refs);
    return st;
}
