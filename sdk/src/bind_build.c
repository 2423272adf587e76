/* SPDX-License-Identifier: Apache-2.0 */
/* Multi-anchor binding at rest (bind_build.h).
 *
 * Blend weights. Egger weights the n predictions "by distance"; normalized
 * inverse distance over the n nearest anchors is not continuous: where the
 * n-th and the (n+1)-th nearest anchors swap, an anchor with weight 1/d_n
 * leaves the set, and the surface tears along that line (a smaller seam of
 * its own). Here w_i = (1 - d_i / d_out)^2, normalized, with d_out the
 * distance of the nearest anchor left out: an anchor's weight reaches zero,
 * with zero slope, exactly where it leaves the set, so positions are
 * continuous in the rest position for any n; the nearest anchor still
 * dominates, and d = 0 is no singularity. n = 1 degenerates to the single
 * nearest anchor (Egger's seam). */
#include "bind_build.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "bind_search.h"
#include "error.h"
#include "rig_internal.h"

typedef struct candidate {
    float distance;
    uint32_t index; /* tet vertex (node), or joint | JOINT_BIT */
} candidate;

#define JOINT_BIT 0x80000000u
/* Tets searched for the foot at least: a point near a vertex of the mesh's
 * surface is nearer to more than a dozen tet centroids than to the tet
 * holding its nearest point (measured on the Kuhn-split bar of
 * tests/binding: 4 missed it and tore the surface, 95 % stretch). */
#define FOOT_TETS 16u
#define NONE UINT32_MAX

static double segment_distance(const double p[3], const float a[3], const float b[3])
{
    double ab[3], ap[3], l2 = 0.0, t = 0.0;
    for (int d = 0; d < 3; d++) {
        ab[d] = (double)b[d] - a[d];
        ap[d] = p[d] - a[d];
        l2 += ab[d] * ab[d];
        t += ab[d] * ap[d];
    }
    t = l2 > 0.0 ? fmin(fmax(t / l2, 0.0), 1.0) : 0.0;
    double d2 = 0.0;
    for (int d = 0; d < 3; d++) {
        double x = ap[d] - t * ab[d];
        d2 += x * x;
    }
    return sqrt(d2);
}

/* Distance from p to joint j's bone: the segments to its children, or its
 * origin when it has none. */
static double bone_distance(const pose_rig *rig, size_t j, const double p[3])
{
    const float *o = rig->joint_rest_model[j].translation;
    double best = -1.0;
    for (size_t c = j + 1; c < rig->joint_count; c++)
        if (rig->joint_parents[c] == (int32_t)j) {
            double d = segment_distance(p, o, rig->joint_rest_model[c].translation);
            best = best < 0.0 ? d : fmin(best, d);
        }
    return best >= 0.0 ? best : segment_distance(p, o, o);
}

/* Insert into the sorted list c[0..*n) of at most k (ties: lower index first). */
static void insert(candidate *c, unsigned *n, unsigned k, candidate x)
{
    unsigned at = *n;
    while (at > 0 && (c[at - 1].distance > x.distance ||
                      (c[at - 1].distance == x.distance && c[at - 1].index > x.index)))
        at--;
    if (at >= k)
        return;
    unsigned last = *n < k ? *n : k - 1;
    memmove(c + at + 1, c + at, (last - at) * sizeof *c);
    c[at] = x;
    if (*n < k)
        (*n)++;
}

/* Weights of the first m of `found` candidates (see the top of the file). */
static void blend_weights(const candidate *c, unsigned found, unsigned m, float *w)
{
    double out = found > m ? c[m].distance : 2.0 * c[found - 1].distance;
    double sum = 0.0, x[POSE__BIND_MAX_ANCHORS];
    for (unsigned i = 0; i < m; i++) {
        double s = out > 0.0 ? fmax(1.0 - c[i].distance / out, 0.0) : 0.0;
        x[i] = s * s;
        sum += x[i];
    }
    for (unsigned i = 0; i < m; i++) /* all tied with the one left out: equal shares */
        w[i] = (float)(sum > 0.0 ? x[i] / sum : 1.0 / m);
}

/* Rest D^-1 of tet t (row-major; rows are cross products of edge pairs). */
static void rest_dinv(const pose_rig *rig, size_t t, double out[9])
{
    const uint32_t *c = rig->tets + 4 * t;
    double e[3][3];
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 3; d++)
            e[k][d] = (double)rig->tet_positions[3 * (size_t)c[k + 1] + (size_t)d] -
                      rig->tet_positions[3 * (size_t)c[0] + (size_t)d];
    double inv[3][3];
    for (int k = 0; k < 3; k++) {
        const double *u = e[(k + 1) % 3], *v = e[(k + 2) % 3];
        inv[k][0] = u[1] * v[2] - u[2] * v[1];
        inv[k][1] = u[2] * v[0] - u[0] * v[2];
        inv[k][2] = u[0] * v[1] - u[1] * v[0];
    }
    double det = e[0][0] * inv[0][0] + e[0][1] * inv[0][1] + e[0][2] * inv[0][2];
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 3; d++)
            out[3 * k + d] = inv[k][d] / det;
}

/* Candidates of every point: its k nearest nodes and joints, merged; and
 * its foot on the tet mesh (foot + 3 * point, in tet foot_tet[point]). The
 * FOOT_TETS (at least 2k) tets with the nearest centroids give both: the foot is the nearest
 * point among them (the nearest point of the whole mesh but where the mesh
 * folds back within a few tets), the nodes are ranked among their corners
 * (every node that near is a corner of one of them but in slivers). */
static pose_status gather(const pose_rig *rig, const float *xyz, size_t count, unsigned k,
                          unsigned sources, const pose_allocator *a, candidate *cand,
                          unsigned *found, double *foot, uint32_t *foot_tet)
{
    memset(found, 0, count * sizeof *found);
    if (sources & POSE__BIND_NODES) {
        const unsigned kk = 2 * k > FOOT_TETS ? 2 * k : FOOT_TETS;
        pose__bind_hit *hits = pose__alloc(a, count * kk * sizeof *hits, POSE__ALIGN);
        unsigned *nh = pose__alloc(a, count * sizeof *nh, POSE__ALIGN);
        pose_status s = hits && nh ? pose__bind_nearest_tets(rig, xyz, count, kk, a, hits, nh)
                                   : pose__fail(POSE_ERR_OUT_OF_MEMORY,
                                                "binding: out of memory for %zu points", count);
        for (size_t i = 0; s == POSE_OK && i < count; i++) {
            const pose__bind_hit *x = hits + (size_t)kk * i, *closest = x;
            for (unsigned h = 0; h < nh[i]; h++) {
                if (x[h].gap < closest->gap)
                    closest = &x[h];
                for (int c = 0; c < 4; c++) {
                    const uint32_t v = rig->tets[4 * (size_t)x[h].tet + (size_t)c];
                    const float *q = rig->tet_positions + 3 * (size_t)v;
                    double dx = (double)q[0] - xyz[3 * i], dy = (double)q[1] - xyz[3 * i + 1],
                           dz = (double)q[2] - xyz[3 * i + 2];
                    candidate cd = {(float)sqrt(dx * dx + dy * dy + dz * dz), v};
                    int seen = 0;
                    for (unsigned e = 0; e < found[i] && !seen; e++)
                        seen = cand[k * i + e].index == v;
                    if (!seen)
                        insert(cand + k * i, &found[i], k, cd);
                }
            }
            memcpy(foot + 3 * i, closest->foot, 3 * sizeof(double));
            foot_tet[i] = nh[i] ? closest->tet : UINT32_MAX;
        }
        pose__free(a, hits);
        pose__free(a, nh);
        if (s != POSE_OK)
            return s;
    }
    if (sources & POSE__BIND_JOINTS)
        for (size_t i = 0; i < count; i++) {
            const double p[3] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
            for (size_t j = 0; j < rig->joint_count; j++)
                insert(cand + k * i, &found[i], k,
                       (candidate){(float)bone_distance(rig, j, p), (uint32_t)j | JOINT_BIT});
        }
    for (size_t i = 0; i < count; i++)
        if (found[i] == 0 || ((sources & POSE__BIND_NODES) && foot_tet[i] == UINT32_MAX))
            return pose__fail(POSE_ERR_UNSUPPORTED,
                              "binding: the rig has no anchor for point %zu (no tet of non-zero "
                              "volume)", i);
    return POSE_OK;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Neighbours (edge-connected tet vertices) of the nf nodes numbered in
 * node_frame, sorted and unique: counts in a first pass over the tets (with
 * repeats: an edge is in several tets), then filled, sorted, compacted. */
static pose_status node_neighbours(const pose_rig *rig, const uint32_t *node_frame, size_t nf,
                                   const pose_allocator *a, uint32_t **offset_out, uint32_t **nbr_out)
{
    uint32_t *off = pose__calloc(a, (nf + 1) * sizeof(uint32_t), POSE__ALIGN);
    if (!off)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "binding: out of memory for %zu nodes", nf);
    for (size_t t = 0; t < rig->tet_count; t++)
        for (int c = 0; c < 4; c++) {
            uint32_t f = node_frame[rig->tets[4 * t + (size_t)c]];
            if (f != NONE)
                off[f + 1] += 3;
        }
    for (size_t f = 0; f < nf; f++)
        off[f + 1] += off[f];
    uint32_t *nbr = pose__alloc(a, ((size_t)off[nf] + 1) * sizeof(uint32_t), POSE__ALIGN);
    uint32_t *fill = pose__alloc(a, (nf + 1) * sizeof(uint32_t), POSE__ALIGN);
    if (!nbr || !fill) {
        pose__free(a, off);
        pose__free(a, nbr);
        pose__free(a, fill);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "binding: out of memory for %zu nodes", nf);
    }
    memcpy(fill, off, nf * sizeof(uint32_t));
    for (size_t t = 0; t < rig->tet_count; t++)
        for (int c = 0; c < 4; c++) {
            uint32_t f = node_frame[rig->tets[4 * t + (size_t)c]];
            if (f != NONE)
                for (int o = 1; o < 4; o++)
                    nbr[fill[f]++] = rig->tets[4 * t + (size_t)((c + o) % 4)];
        }
    uint32_t at = 0;
    for (size_t f = 0; f < nf; f++) {
        const uint32_t b = off[f], e = off[f + 1];
        qsort(nbr + b, e - b, sizeof(uint32_t), cmp_u32);
        off[f] = at;
        for (uint32_t i = b; i < e; i++)
            if (i == b || nbr[i] != nbr[i - 1])
                nbr[at++] = nbr[i];
    }
    off[nf] = at;
    pose__free(a, fill);
    *offset_out = off;
    *nbr_out = nbr;
    return POSE_OK;
}

/* (sum d d^T)^-1 of a node's edges d (row-major); 0 where the neighbourhood
 * is flat (a node of zero-volume tets only: its frame then stays put). */
static void aqq_inverse(const float *d, size_t count, float out[9])
{
    double A[9] = {0};
    for (size_t i = 0; i < count; i++)
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                A[3 * r + c] += (double)d[3 * i + (size_t)r] * d[3 * i + (size_t)c];
    double C[9] = {
        A[4] * A[8] - A[5] * A[7], A[2] * A[7] - A[1] * A[8], A[1] * A[5] - A[2] * A[4],
        A[5] * A[6] - A[3] * A[8], A[0] * A[8] - A[2] * A[6], A[2] * A[3] - A[0] * A[5],
        A[3] * A[7] - A[4] * A[6], A[1] * A[6] - A[0] * A[7], A[0] * A[4] - A[1] * A[3],
    };
    double det = A[0] * C[0] + A[1] * C[3] + A[2] * C[6], tr = A[0] + A[4] + A[8];
    for (int e = 0; e < 9; e++)
        out[e] = fabs(det) > 1e-12 * tr * tr * tr ? (float)(C[e] / det) : 0.0f;
}

pose_status pose__bind_build(const pose_rig *rig, const float *xyz, size_t count, unsigned n,
                             unsigned sources, const pose_allocator *a, pose__bind_mesh *mesh,
                             void **block)
{
    *block = NULL;
    memset(mesh, 0, sizeof *mesh);
    const unsigned k = n + 1;
    const size_t c1 = count ? count : 1;
    candidate *cand = pose__alloc(a, c1 * k * sizeof *cand, POSE__ALIGN);
    unsigned *found = pose__alloc(a, c1 * sizeof *found, POSE__ALIGN);
    double *foot = pose__alloc(a, c1 * 3 * sizeof *foot, POSE__ALIGN);
    uint32_t *foot_tet = pose__alloc(a, c1 * sizeof *foot_tet, POSE__ALIGN);
    /* frame of each node / joint, NONE until used: frames numbered by first use */
    uint32_t *node_frame = pose__alloc(a, (rig->tet_vertex_count + 1) * sizeof(uint32_t), POSE__ALIGN);
    uint32_t *joint_frame = pose__alloc(a, (rig->joint_count + 1) * sizeof(uint32_t), POSE__ALIGN);
    uint32_t *nbr_offset = NULL, *nbr = NULL;
    pose_status s = POSE_OK;
    if (!cand || !found || !foot || !foot_tet || !node_frame || !joint_frame)
        s = pose__fail(POSE_ERR_OUT_OF_MEMORY, "binding: out of memory for %zu points", count);
    if (s == POSE_OK)
        s = gather(rig, xyz, count, k, sources, a, cand, found, foot, foot_tet);
    if (s != POSE_OK)
        goto done;

    memset(node_frame, 0xff, rig->tet_vertex_count * sizeof(uint32_t));
    memset(joint_frame, 0xff, rig->joint_count * sizeof(uint32_t));
    size_t nf = 0, jf = 0;
    for (size_t i = 0; i < count; i++)
        for (unsigned h = 0; h < found[i] && h < n; h++) {
            uint32_t x = cand[k * i + h].index;
            uint32_t *slot = x & JOINT_BIT ? &joint_frame[x & ~JOINT_BIT] : &node_frame[x];
            if (*slot == NONE)
                *slot = (uint32_t)(x & JOINT_BIT ? jf++ : nf++);
        }
    s = node_neighbours(rig, node_frame, nf, a, &nbr_offset, &nbr);
    if (s != POSE_OK)
        goto done;
    const size_t ne = nbr_offset[nf];

    size_t off = 0;
#define CARVE(name, bytes) const size_t name = off; off += ((bytes) + 63u) & ~(size_t)63u
    CARVE(off_vertex, count * sizeof(pose__bind_vertex));
    CARVE(off_anchor, count * n * sizeof(pose__bind_anchor));
    CARVE(off_node, nf * sizeof(uint32_t));
    CARVE(off_offset, (nf + 1) * sizeof(uint32_t));
    CARVE(off_nbr, ne * sizeof(uint32_t));
    CARVE(off_rest, 3 * ne * sizeof(float));
    CARVE(off_aqq, 9 * nf * sizeof(float));
    CARVE(off_joints, jf * sizeof(uint32_t));
#undef CARVE
    unsigned char *mem = pose__calloc(a, off, POSE__ALIGN);
    if (!mem) {
        s = pose__fail(POSE_ERR_OUT_OF_MEMORY, "binding: out of memory (%zu bytes)", off);
        goto done;
    }
    pose__bind_vertex *vertex = (pose__bind_vertex *)(mem + off_vertex);
    pose__bind_anchor *anchor = (pose__bind_anchor *)(mem + off_anchor);
    uint32_t *node = (uint32_t *)(mem + off_node), *joints = (uint32_t *)(mem + off_joints);
    float *rest = (float *)(mem + off_rest), *aqq = (float *)(mem + off_aqq);
    memcpy(mem + off_offset, nbr_offset, (nf + 1) * sizeof(uint32_t));
    memcpy(mem + off_nbr, nbr, ne * sizeof(uint32_t));
    for (size_t v = 0; v < rig->tet_vertex_count; v++)
        if (node_frame[v] != NONE)
            node[node_frame[v]] = (uint32_t)v;
    for (size_t f = 0; f < nf; f++) {
        const float *c = rig->tet_positions + 3 * (size_t)node[f];
        for (uint32_t i = nbr_offset[f]; i < nbr_offset[f + 1]; i++)
            for (int d = 0; d < 3; d++)
                rest[3 * (size_t)i + (size_t)d] = rig->tet_positions[3 * (size_t)nbr[i] + (size_t)d] - c[d];
        aqq_inverse(rest + 3 * (size_t)nbr_offset[f], nbr_offset[f + 1] - nbr_offset[f], aqq + 9 * f);
    }
    for (size_t j = 0; j < rig->joint_count; j++)
        if (joint_frame[j] != NONE)
            joints[joint_frame[j]] = (uint32_t)j;

    for (size_t i = 0; i < count; i++) {
        const candidate *c = cand + k * i;
        const float *p = xyz + 3 * i;
        pose__bind_vertex *vx = &vertex[i];
        memcpy(vx->p, p, 3 * sizeof(float));
        vx->corner[0] = POSE__BIND_NO_FOOT;
        if (sources & POSE__BIND_NODES) {
            /* the foot in its tet's edge coordinates, and the offset from it */
            const uint32_t *tv = rig->tets + 4 * (size_t)foot_tet[i];
            const float *v0 = rig->tet_positions + 3 * (size_t)tv[0];
            const double *f = foot + 3 * i;
            double di[9];
            rest_dinv(rig, foot_tet[i], di);
            memcpy(vx->corner, tv, 4 * sizeof(uint32_t));
            for (int e = 0; e < 3; e++) {
                vx->b[e] = (float)(di[3 * e] * (f[0] - v0[0]) + di[3 * e + 1] * (f[1] - v0[1]) +
                                   di[3 * e + 2] * (f[2] - v0[2]));
                vx->r[e] = (float)((double)p[e] - f[e]);
            }
        }
        const unsigned m = found[i] < n ? found[i] : n;
        float w[POSE__BIND_MAX_ANCHORS];
        blend_weights(c, found[i], m, w);
        for (unsigned h = 0; h < n; h++) {
            if (h >= m) { /* fewer anchors than n in a tiny rig: weightless copies */
                anchor[i * n + h] = (pose__bind_anchor){anchor[i * n].frame, 0.0f};
                continue;
            }
            const uint32_t x = c[h].index;
            anchor[i * n + h] = (pose__bind_anchor){
                x & JOINT_BIT ? (uint32_t)nf + joint_frame[x & ~JOINT_BIT] : node_frame[x], w[h]};
        }
    }
    *mesh = (pose__bind_mesh){
        .vertex_count = count, .anchors = n, .vertex = vertex, .anchor = anchor,
        .node_frames = nf, .node = node, .nbr_offset = (const uint32_t *)(mem + off_offset),
        .nbr = (const uint32_t *)(mem + off_nbr), .nbr_rest = rest, .aqq_inv = aqq,
        .joint_frames = jf, .joints = joints,
    };
    *block = mem;
done:
    pose__free(a, cand);
    pose__free(a, found);
    pose__free(a, foot);
    pose__free(a, foot_tet);
    pose__free(a, node_frame);
    pose__free(a, joint_frame);
    pose__free(a, nbr_offset);
    pose__free(a, nbr);
    return s;
}
