/* SPDX-License-Identifier: Apache-2.0 */
/* The `couplings` section (soft simulation nodes tied to bones by
 * zero-length springs, pose.h pose_fem_coupling): what a record must
 * satisfy, the queries, and the nodes near a bone a host may couple. */
#include <math.h>
#include <string.h>

#include "error.h"
#include "rig_io.h"
#include "rig_runtime.h"

pose_status pose__couplings_validate(const pose_rig *rig, const pose__source *src)
{
    if (!rig->couplings)
        return POSE_OK;
    if (!rig->fem)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, "couplings", rig->couplings,
                                 "couplings without a fem section (the soft tissue's material)");
    for (size_t i = 0; i < rig->coupling_count; i++) {
        const pose__coupling_record *r = &rig->couplings[i];
        if (r->node >= rig->tet_vertex_count)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, "couplings", &r->node,
                                     "coupling %zu: node %u is not a tet vertex (%zu)", i,
                                     (unsigned)r->node, rig->tet_vertex_count);
        if (i > 0 && r->node <= r[-1].node)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, "couplings", &r->node,
                                     "coupling %zu: node %u after node %u (nodes strictly "
                                     "increasing)", i, (unsigned)r->node, (unsigned)r[-1].node);
        if (r->joint >= rig->joint_count)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, "couplings", &r->joint,
                                     "coupling %zu: joint %u (the skeleton has %zu)", i,
                                     (unsigned)r->joint, rig->joint_count);
        if (!isfinite(r->stiffness) || !(r->stiffness > 0.0f))
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, "couplings", &r->stiffness,
                                     "coupling %zu: stiffness %g (finite and > 0)", i,
                                     (double)r->stiffness);
        for (int a = 0; a < 3; a++)
            if (!isfinite(r->anchor[a]))
                return pose__source_fail(src, POSE_ERR_INVALID_DATA, "couplings", &r->anchor[a],
                                         "coupling %zu: anchor is not finite", i);
        if (r->flags != 0 || r->reserved != 0)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, "couplings",
                                     r->flags ? (const void *)&r->flags : (const void *)&r->reserved,
                                     "coupling %zu: flags and reserved bytes must be zero", i);
    }
    return POSE_OK;
}

size_t pose_rig_fem_couplings(const pose_rig *rig, pose_fem_coupling *out, size_t capacity)
{
    if (!rig || !rig->couplings)
        return 0;
    for (size_t i = 0; out && i < capacity && i < rig->coupling_count; i++) {
        const pose__coupling_record *r = &rig->couplings[i];
        out[i] = (pose_fem_coupling){.node = r->node, .joint = (int)r->joint,
                                     .stiffness = r->stiffness};
        memcpy(out[i].anchor, r->anchor, sizeof out[i].anchor);
    }
    return rig->coupling_count;
}

/* Squared distance from p to triangle (a, b, c) (Ericson, Real-Time
 * Collision Detection §5.1.5, by Voronoi regions). */
static double tri_dist2(const double p[3], const double a[3], const double b[3], const double c[3])
{
    double ab[3], ac[3], ap[3], q[3];
    for (int k = 0; k < 3; k++) {
        ab[k] = b[k] - a[k];
        ac[k] = c[k] - a[k];
        ap[k] = p[k] - a[k];
    }
#define DOT(u, v) ((u)[0] * (v)[0] + (u)[1] * (v)[1] + (u)[2] * (v)[2])
    const double d1 = DOT(ab, ap), d2 = DOT(ac, ap);
    double bp[3], cp[3];
    for (int k = 0; k < 3; k++) {
        bp[k] = p[k] - b[k];
        cp[k] = p[k] - c[k];
    }
    const double d3 = DOT(ab, bp), d4 = DOT(ac, bp), d5 = DOT(ab, cp), d6 = DOT(ac, cp);
#undef DOT
    const double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
    double s = 0.0, t = 0.0;
    if (d1 <= 0.0 && d2 <= 0.0) {
        s = t = 0.0;
    } else if (d3 >= 0.0 && d4 <= d3) {
        s = 1.0, t = 0.0;
    } else if (d6 >= 0.0 && d5 <= d6) {
        s = 0.0, t = 1.0;
    } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        s = d1 / (d1 - d3), t = 0.0;
    } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        s = 0.0, t = d2 / (d2 - d6);
    } else if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        s = 1.0 - t;
    } else {
        const double den = 1.0 / (va + vb + vc);
        s = vb * den;
        t = vc * den;
    }
    double d2s = 0.0;
    for (int k = 0; k < 3; k++) {
        q[k] = a[k] + s * ab[k] + t * ac[k] - p[k];
        d2s += q[k] * q[k];
    }
    return d2s;
}

pose_status pose_rig_fem_nodes_near_joint(const pose_rig *rig, int joint, float reach,
                                          uint32_t *nodes, size_t capacity, size_t *count)
{
    pose__clear_error();
    if (!rig || !count || (capacity && !nodes))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_rig_fem_nodes_near_joint: rig and count are required (nodes with "
                          "a capacity)");
    *count = 0;
    if (joint < 0 || (size_t)joint >= rig->joint_count || !isfinite(reach) || !(reach >= 0.0f))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_rig_fem_nodes_near_joint: joint %d (of %zu) or reach %g (finite, "
                          ">= 0) out of range", joint, rig->joint_count, (double)reach);
    if (!pose_rig_has_fem(rig))
        return pose__fail(POSE_ERR_UNSUPPORTED,
                          "pose_rig_fem_nodes_near_joint: the rig has no fem section");
    pose_status s = pose__rig_fem_mesh(rig, "pose_rig_fem_nodes_near_joint");
    if (s < 0)
        return s;
    const pose__fem_mesh *m = &rig->rt->fem;
    const double r2 = (double)reach * reach;
    int bones = 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t t = 0; t < rig->tissue_count; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        if (ts->kind != POSE_TISSUE_BONE || ts->joint != joint)
            continue;
        bones++;
        for (size_t v = 0; v < ts->vertex_count; v++)
            for (int a = 0; a < 3; a++) {
                lo[a] = fmin(lo[a], ts->positions[3 * v + a] - (double)reach);
                hi[a] = fmax(hi[a], ts->positions[3 * v + a] + (double)reach);
            }
    }
    if (!bones)
        return pose__fail(POSE_ERR_UNSUPPORTED,
                          "pose_rig_fem_nodes_near_joint: joint %d ('%s') has no bone tissue",
                          joint, rig->joint_names + (size_t)joint * POSE__NAME_SIZE);
    size_t n = 0;
    for (size_t v = 0; v < m->vertex_count; v++) {
        if (!(m->inv_diag[v] > 0.0f)) /* held by a bone tet, or in no soft tet */
            continue;
        const double p[3] = {rig->tet_positions[3 * v], rig->tet_positions[3 * v + 1],
                             rig->tet_positions[3 * v + 2]};
        if (p[0] < lo[0] || p[1] < lo[1] || p[2] < lo[2] || p[0] > hi[0] || p[1] > hi[1] ||
            p[2] > hi[2])
            continue;
        int near = 0;
        for (size_t t = 0; t < rig->tissue_count && !near; t++) {
            const pose__tissue *ts = &rig->tissues[t];
            if (ts->kind != POSE_TISSUE_BONE || ts->joint != joint)
                continue;
            for (size_t f = 0; f < ts->triangle_count && !near; f++) {
                double c[3][3];
                int out = 0;
                for (int k = 0; k < 3; k++)
                    for (int a = 0; a < 3; a++)
                        c[k][a] = ts->positions[3 * (size_t)ts->triangles[3 * f + (size_t)k] + a];
                for (int a = 0; a < 3 && !out; a++) /* the triangle's box beyond reach */
                    out = p[a] + reach < fmin(c[0][a], fmin(c[1][a], c[2][a])) ||
                          p[a] - reach > fmax(c[0][a], fmax(c[1][a], c[2][a]));
                near = !out && tri_dist2(p, c[0], c[1], c[2]) <= r2;
            }
        }
        if (!near)
            continue;
        if (n < capacity)
            nodes[n] = (uint32_t)v;
        n++;
    }
    *count = n;
    return POSE_OK;
}
