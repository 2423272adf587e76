/* SPDX-License-Identifier: Apache-2.0 */
/* The `soft_couplings` section (soft nodes tied to points of the tet mesh
 * by zero-length springs, pose.h pose_fem_soft_coupling): what a record
 * must satisfy, for the loader and pose_set_fem_soft_couplings alike, and
 * the query. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "error.h"
#include "rig_io.h"
#include "rig_runtime.h"

#define SAME_FIELD(f) (offsetof(pose_fem_soft_coupling, f) == offsetof(pose__soft_coupling_record, f))
_Static_assert(sizeof(pose_fem_soft_coupling) == sizeof(pose__soft_coupling_record) &&
                   SAME_FIELD(other) && SAME_FIELD(weight) && SAME_FIELD(stiffness),
               "the record is pose_fem_soft_coupling of 0.2");
#undef SAME_FIELD

int pose__soft_coupling_fault(const pose__soft_coupling_record *r, size_t nv, char *why, size_t cap,
                              size_t *at)
{
    if (r->node >= nv) {
        *at = offsetof(pose__soft_coupling_record, node);
        snprintf(why, cap, "node %u is not a tet vertex (%zu)", (unsigned)r->node, nv);
        return 1;
    }
    double sum = 0.0;
    for (int c = 0; c < 4; c++) {
        *at = offsetof(pose__soft_coupling_record, weight) + (size_t)c * sizeof(float);
        if (!isfinite(r->weight[c])) {
            snprintf(why, cap, "weight %d is not finite", c);
            return 1;
        }
        sum += r->weight[c];
        if (r->weight[c] == 0.0f)
            continue;
        *at = offsetof(pose__soft_coupling_record, other) + (size_t)c * sizeof(uint32_t);
        if (r->other[c] >= nv) {
            snprintf(why, cap, "other node %d (%u) is not a tet vertex (%zu)", c,
                     (unsigned)r->other[c], nv);
            return 1;
        }
        int same = r->other[c] == r->node;
        for (int e = 0; e < c; e++)
            same |= r->weight[e] != 0.0f && r->other[e] == r->other[c];
        if (same) {
            snprintf(why, cap, "other node %d (%u) is the node or another weighted one", c,
                     (unsigned)r->other[c]);
            return 1;
        }
    }
    if (!(fabs(sum - 1.0) <= 1e-4)) {
        *at = offsetof(pose__soft_coupling_record, weight);
        snprintf(why, cap, "weights sum to %g (1: a point of the mesh)", sum);
        return 1;
    }
    *at = offsetof(pose__soft_coupling_record, stiffness);
    if (!isfinite(r->stiffness) || !(r->stiffness > 0.0f)) {
        snprintf(why, cap, "stiffness %g (finite and > 0)", (double)r->stiffness);
        return 1;
    }
    return 0;
}

pose_status pose__soft_couplings_validate(const pose_rig *rig, const pose__source *src)
{
    if (!rig->soft_couplings)
        return POSE_OK;
    if (!rig->fem)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, "soft_couplings", rig->soft_couplings,
                                 "soft couplings without a fem section (the soft tissue's material)");
    for (size_t i = 0; i < rig->soft_coupling_count; i++) {
        const pose__soft_coupling_record *r = &rig->soft_couplings[i];
        char why[128];
        size_t at = 0;
        if (pose__soft_coupling_fault(r, rig->tet_vertex_count, why, sizeof why, &at))
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, "soft_couplings",
                                     (const unsigned char *)r + at, "soft coupling %zu: %s", i, why);
    }
    return POSE_OK;
}

size_t pose_rig_fem_soft_couplings(const pose_rig *rig, pose_fem_soft_coupling *out, size_t capacity,
                                   size_t element_size)
{
    if (!rig || !rig->soft_couplings || element_size < sizeof(pose_fem_soft_coupling))
        return 0;
    for (size_t i = 0; out && i < capacity && i < rig->soft_coupling_count; i++)
        memcpy((unsigned char *)out + i * element_size, &rig->soft_couplings[i],
               sizeof(pose_fem_soft_coupling));
    return rig->soft_coupling_count;
}
