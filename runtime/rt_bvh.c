/* SPDX-License-Identifier: Apache-2.0 */
/* rt_bvh.h: refit and queries of a triangle BVH. */
#include "rt_bvh.h"

#include <math.h>

#include "rt_tri.h"

/* Plain comparisons: fminf/fmaxf are library calls where NaN rules apply. */
static float min2(float a, float b)
{
    return a < b ? a : b;
}

static float max2(float a, float b)
{
    return a > b ? a : b;
}

static const float *vertex(const float *positions, uint32_t v)
{
    return positions + 3 * (size_t)v;
}

/* Box b (lo x, y, z, hi x, y, z) grown to hold x; the axes written out:
 * loops over them were not unrolled. */
static inline void grow(float *b, const float *x)
{
    b[0] = min2(b[0], x[0]);
    b[1] = min2(b[1], x[1]);
    b[2] = min2(b[2], x[2]);
    b[3] = max2(b[3], x[0]);
    b[4] = max2(b[4], x[1]);
    b[5] = max2(b[5], x[2]);
}

void pose__bvh_refit_leaves(pose__bvh *t, const float *positions, size_t begin, size_t end)
{
    for (size_t l = begin; l < end; l++) {
        pose__bvh_node *n = &t->nodes[t->leaves[l]];
        float b[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
        if (t->corners) {
            for (uint32_t i = t->corner_begin[l]; i < t->corner_begin[l + 1]; i++)
                grow(b, vertex(positions, t->corners[i]));
        } else {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                const uint32_t *tri = t->triangles + 3 * (size_t)t->items[i];
                for (int k = 0; k < 3; k++)
                    grow(b, vertex(positions, tri[k]));
            }
        }
        for (int d = 0; d < 3; d++) {
            n->lo[d] = b[d];
            n->hi[d] = b[3 + d];
        }
    }
}

void pose__bvh_refit_inner(pose__bvh *t)
{
    /* Children follow their parents: a backward sweep sees them first. */
    for (uint32_t i = t->node_count; i-- > 0;) {
        pose__bvh_node *n = &t->nodes[i];
        if (n->count)
            continue;
        const pose__bvh_node *a = &t->nodes[n->first], *b = a + 1;
        for (int d = 0; d < 3; d++) {
            n->lo[d] = min2(a->lo[d], b->lo[d]);
            n->hi[d] = max2(a->hi[d], b->hi[d]);
        }
    }
}

static int overlap(const pose__bvh_node *a, const pose__bvh_node *b)
{
    return a->lo[0] <= b->hi[0] && b->lo[0] <= a->hi[0] && a->lo[1] <= b->hi[1] &&
           b->lo[1] <= a->hi[1] && a->lo[2] <= b->hi[2] && b->lo[2] <= a->hi[2];
}

typedef struct tri_box {
    const float *v[3];
    float lo[3], hi[3];
} tri_box;

static void leaf_boxes(const pose__bvh *t, const float *positions, const pose__bvh_node *n,
                       tri_box *out)
{
    for (uint32_t i = 0; i < n->count; i++) {
        const uint32_t *tri = t->triangles + 3 * (size_t)t->items[n->first + i];
        tri_box *b = &out[i];
        for (int k = 0; k < 3; k++)
            b->v[k] = vertex(positions, tri[k]);
        for (int d = 0; d < 3; d++) {
            b->lo[d] = min2(min2(b->v[0][d], b->v[1][d]), b->v[2][d]);
            b->hi[d] = max2(max2(b->v[0][d], b->v[1][d]), b->v[2][d]);
        }
    }
}

static int boxes_meet(const tri_box *a, const tri_box *b)
{
    for (int d = 0; d < 3; d++)
        if (a->lo[d] > b->hi[d] || b->lo[d] > a->hi[d])
            return 0;
    return 1;
}

/* Parts of the triangles and nodes (pose__bvh_self_task_parts), or none. */
typedef struct parts {
    const uint32_t *tri, *node;
} parts;

/* Intersecting pairs between leaves a and b (a == b: within the leaf); with
 * parts, only pairs of triangles of different parts. */
static size_t leaf_pairs(const pose__bvh *t, const float *positions, uint32_t a, uint32_t b,
                         const parts *pt)
{
    const pose__bvh_node *na = &t->nodes[a], *nb = &t->nodes[b];
    tri_box ba[POSE__BVH_LEAF], bb[POSE__BVH_LEAF];
    leaf_boxes(t, positions, na, ba);
    leaf_boxes(t, positions, nb, bb);
    size_t hits = 0;
    for (uint32_t i = 0; i < na->count; i++)
        for (uint32_t j = a == b ? i + 1 : 0; j < nb->count; j++) {
            if (!boxes_meet(&ba[i], &bb[j]))
                continue;
            const uint32_t ii = t->items[na->first + i], ij = t->items[nb->first + j];
            if (pt && pt->tri[ii] == pt->tri[ij])
                continue;
            const uint32_t *ti = t->triangles + 3 * (size_t)ii;
            const uint32_t *tj = t->triangles + 3 * (size_t)ij;
            if (!pose__tris_share_vertex(ti, tj) && pose__tri_tri_intersect(ba[i].v, bb[j].v))
                hits++;
        }
    return hits;
}

static float extent(const pose__bvh_node *n)
{
    return (n->hi[0] - n->lo[0]) + (n->hi[1] - n->lo[1]) + (n->hi[2] - n->lo[2]);
}

/* Depth-first over node pairs; (a, a) stands for "a against itself". Each
 * pop pushes at most three and the path is at most twice the depth long. */
#define PAIR_STACK (8 * POSE__BVH_MAX_DEPTH)

static size_t pairs_from(const pose__bvh *t, const float *positions, uint32_t a0, uint32_t b0,
                         const parts *pt)
{
    uint32_t stack[PAIR_STACK][2];
    int top = 0;
    stack[top][0] = a0;
    stack[top++][1] = b0;
    size_t hits = 0;
    while (top > 0) {
        top--;
        const uint32_t a = stack[top][0], b = stack[top][1];
        const pose__bvh_node *na = &t->nodes[a], *nb = &t->nodes[b];
        /* A node, or two nodes, all of one part hold no pair to count. */
        if (pt && pt->node[a] != POSE__BVH_MIXED && pt->node[a] == pt->node[b])
            continue;
        if (a == b) {
            if (na->count) {
                hits += leaf_pairs(t, positions, a, a, pt);
            } else {
                const uint32_t l = na->first, r = na->first + 1;
                stack[top][0] = l, stack[top++][1] = l;
                stack[top][0] = r, stack[top++][1] = r;
                stack[top][0] = l, stack[top++][1] = r;
            }
            continue;
        }
        if (!overlap(na, nb))
            continue;
        if (na->count && nb->count) {
            hits += leaf_pairs(t, positions, a, b, pt);
            continue;
        }
        /* Open the inner node, the larger one when both are. */
        const int open_a = !na->count && (nb->count || extent(na) >= extent(nb));
        const uint32_t keep = open_a ? b : a, open = open_a ? a : b;
        const uint32_t c = t->nodes[open].first;
        stack[top][0] = c, stack[top++][1] = keep;
        stack[top][0] = c + 1, stack[top++][1] = keep;
    }
    return hits;
}

static size_t self_task(const pose__bvh *t, const float *positions, uint32_t task, const parts *pt)
{
    const uint32_t n = t->split_nodes[task];
    if (task < t->split_pairs)
        return pairs_from(t, positions, t->nodes[n].first, t->nodes[n].first + 1, pt);
    return pairs_from(t, positions, n, n, pt);
}

size_t pose__bvh_self_task(const pose__bvh *t, const float *positions, uint32_t task)
{
    return self_task(t, positions, task, NULL);
}

size_t pose__bvh_self_task_parts(const pose__bvh *t, const float *positions, uint32_t task,
                                 const uint32_t *tri_part, const uint32_t *node_part)
{
    const parts pt = {tri_part, node_part};
    return self_task(t, positions, task, &pt);
}

void pose__bvh_node_parts(const pose__bvh *t, const uint32_t *tri_part, uint32_t *node_part)
{
    /* Parents come before children: children are done first from the end. */
    for (uint32_t n = t->node_count; n-- > 0;) {
        const pose__bvh_node *nd = &t->nodes[n];
        uint32_t part;
        if (nd->count) {
            part = tri_part[t->items[nd->first]];
            for (uint32_t i = 1; i < nd->count; i++)
                if (tri_part[t->items[nd->first + i]] != part)
                    part = POSE__BVH_MIXED;
        } else {
            part = node_part[nd->first] == node_part[nd->first + 1] ? node_part[nd->first] : POSE__BVH_MIXED;
        }
        node_part[n] = part;
    }
}

int pose__bvh_winding(const pose__bvh *t, const float *positions, const float *p)
{
    uint32_t stack[POSE__BVH_MAX_DEPTH + 2];
    int top = 0, w = 0;
    stack[top++] = 0;
    while (top > 0) {
        const pose__bvh_node *n = &t->nodes[stack[--top]];
        /* The ray is the half-line {p + s x, s > 0}. */
        if (p[1] < n->lo[1] || p[1] > n->hi[1] || p[2] < n->lo[2] || p[2] > n->hi[2] || p[0] > n->hi[0])
            continue;
        if (!n->count) {
            stack[top++] = n->first;
            stack[top++] = n->first + 1;
            continue;
        }
        for (uint32_t i = n->first; i < n->first + n->count; i++) {
            const uint32_t *tri = t->triangles + 3 * (size_t)t->items[i];
            w += pose__ray_x_crossing(p, vertex(positions, tri[0]), vertex(positions, tri[1]),
                                      vertex(positions, tri[2]));
        }
    }
    return w;
}

/* The ray p + s d (s >= 0) meets node n's box, grown by a little so that
 * float rounding in the slabs never drops a triangle the exact test counts
 * (inv: 1 / d per axis, 0 where d is 0: products, not a division per slab:
 * the pad holds either rounding). */
static int ray_meets(const pose__bvh_node *n, const float *p, const float *d, const float *inv)
{
    float t0 = 0.0f, t1 = INFINITY;
    for (int k = 0; k < 3; k++) {
        const float pad = 1e-5f + 1e-6f * (n->hi[k] - n->lo[k]);
        const float lo = n->lo[k] - pad - p[k], hi = n->hi[k] + pad - p[k];
        if (d[k] == 0.0f) {
            if (lo > 0.0f || hi < 0.0f)
                return 0;
            continue;
        }
        const float a = lo * inv[k], b = hi * inv[k];
        t0 = max2(t0, min2(a, b));
        t1 = min2(t1, max2(a, b));
        if (t0 > t1)
            return 0;
    }
    return 1;
}

int pose__bvh_winding_along(const pose__bvh *t, const float *positions, const float *p, const float *d)
{
    uint32_t stack[POSE__BVH_MAX_DEPTH + 2];
    int top = 0, w = 0;
    if (!t->node_count)
        return 0;
    /* a component too small for its reciprocal to be finite counts as 0 */
    const float dir[3] = {fabsf(d[0]) < 1e-30f ? 0.0f : d[0], fabsf(d[1]) < 1e-30f ? 0.0f : d[1],
                          fabsf(d[2]) < 1e-30f ? 0.0f : d[2]};
    const float inv[3] = {dir[0] != 0.0f ? 1.0f / dir[0] : 0.0f, dir[1] != 0.0f ? 1.0f / dir[1] : 0.0f,
                          dir[2] != 0.0f ? 1.0f / dir[2] : 0.0f};
    stack[top++] = 0;
    while (top > 0) {
        const pose__bvh_node *n = &t->nodes[stack[--top]];
        if (!ray_meets(n, p, dir, inv))
            continue;
        if (!n->count) {
            stack[top++] = n->first;
            stack[top++] = n->first + 1;
            continue;
        }
        for (uint32_t i = n->first; i < n->first + n->count; i++) {
            const uint32_t *tri = t->triangles + 3 * (size_t)t->items[i];
            w += pose__ray_crossing(p, d, vertex(positions, tri[0]), vertex(positions, tri[1]),
                                    vertex(positions, tri[2]));
        }
    }
    return w;
}
