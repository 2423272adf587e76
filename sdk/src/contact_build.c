/* SPDX-License-Identifier: Apache-2.0 */
/* contact_build.h: a median-split BVH over triangles. Splitting at the
 * median of the centroids along the longest axis keeps the tree balanced
 * (depth log2(n / leaf) + 1), which bounds the query stacks and keeps the
 * self-intersection tasks of similar size after the refit. */
#include "contact_build.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "error.h"

/* Self-intersection tasks: the subtrees at this depth against themselves,
 * and the pairs of children above it (2^(D+1) - 1 tasks), enough to
 * spread over a few threads. */
#define SPLIT_DEPTH 5

/* Reorder items[0..n) so that items[k] has the k-th smallest key and no
 * item before it a larger one (quickselect; keys indexed by item). */
static void select_kth(uint32_t *items, size_t n, size_t k, const float *key, int axis)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        const float pivot = key[3 * (size_t)items[lo + (hi - lo) / 2] + (size_t)axis];
        size_t i = lo, j = hi;
        while (i <= j) {
            while (key[3 * (size_t)items[i] + (size_t)axis] < pivot)
                i++;
            while (key[3 * (size_t)items[j] + (size_t)axis] > pivot)
                j--;
            if (i <= j) {
                uint32_t s = items[i];
                items[i] = items[j];
                items[j] = s;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return;
    }
}

typedef struct build_job {
    uint32_t node, begin, end, depth;
} build_job;

static void collect_split(pose__bvh *t, uint32_t node, int depth, uint32_t *pairs, uint32_t *selfs,
                          uint32_t *np, uint32_t *ns)
{
    const pose__bvh_node *n = &t->nodes[node];
    if (n->count || depth == SPLIT_DEPTH) {
        selfs[(*ns)++] = node;
        return;
    }
    pairs[(*np)++] = node;
    collect_split(t, n->first, depth + 1, pairs, selfs, np, ns);
    collect_split(t, n->first + 1, depth + 1, pairs, selfs, np, ns);
}

void pose__bvh_release(pose__bvh *t, const pose_allocator *a)
{
    pose__free(a, t->nodes);
    pose__free(a, t->items);
    pose__free(a, t->leaves);
    pose__free(a, t->split_nodes);
    pose__free(a, t->corner_begin);
    pose__free(a, t->corners);
    memset(t, 0, sizeof *t);
}

pose_status pose__bvh_index_corners(pose__bvh *t, const pose_allocator *a)
{
    uint32_t *begin = pose__alloc(a, ((size_t)t->leaf_count + 1) * sizeof *begin, POSE__ALIGN);
    uint32_t triangles = 0;
    for (uint32_t k = 0; k < t->leaf_count; k++)
        triangles += t->nodes[t->leaves[k]].count;
    uint32_t *corners = pose__alloc(a, (3 * (size_t)triangles + 1) * sizeof *corners, POSE__ALIGN);
    if (!begin || !corners) {
        pose__free(a, begin);
        pose__free(a, corners);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a BVH's corners (%u triangles)", triangles);
    }
    uint32_t n = 0;
    for (uint32_t k = 0; k < t->leaf_count; k++) {
        const pose__bvh_node *leaf = &t->nodes[t->leaves[k]];
        begin[k] = n;
        for (uint32_t i = leaf->first; i < leaf->first + leaf->count; i++)
            for (int c = 0; c < 3; c++) { /* a leaf holds a few triangles: a linear search */
                const uint32_t v = t->triangles[3 * (size_t)t->items[i] + (size_t)c];
                uint32_t seen = begin[k];
                while (seen < n && corners[seen] != v)
                    seen++;
                if (seen == n)
                    corners[n++] = v;
            }
    }
    begin[t->leaf_count] = n;
    pose__free(a, t->corner_begin);
    pose__free(a, t->corners);
    t->corner_begin = begin;
    t->corners = corners;
    return POSE_OK;
}

pose_status pose__bvh_build(pose__bvh *t, const pose_allocator *a, const uint32_t *triangles,
                            uint32_t count, const float *positions)
{
    memset(t, 0, sizeof *t);
    t->triangles = triangles;
    if (count == 0)
        return POSE_OK;
    const size_t max_nodes = 2 * (size_t)count - 1;
    const size_t max_split = (size_t)2 << SPLIT_DEPTH;
    t->nodes = pose__alloc(a, max_nodes * sizeof *t->nodes, POSE__ALIGN);
    t->items = pose__alloc(a, count * sizeof *t->items, POSE__ALIGN);
    t->leaves = pose__alloc(a, count * sizeof *t->leaves, POSE__ALIGN);
    t->split_nodes = pose__alloc(a, max_split * sizeof *t->split_nodes, POSE__ALIGN);
    float *centroid = pose__alloc(a, 3 * (size_t)count * sizeof(float), POSE__ALIGN);
    build_job *jobs = pose__alloc(a, (POSE__BVH_MAX_DEPTH + 2) * sizeof *jobs, POSE__ALIGN);
    if (!t->nodes || !t->items || !t->leaves || !t->split_nodes || !centroid || !jobs) {
        pose__free(a, centroid);
        pose__free(a, jobs);
        pose__bvh_release(t, a);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a BVH of %u triangles", count);
    }
    for (uint32_t i = 0; i < count; i++) {
        t->items[i] = i;
        for (int d = 0; d < 3; d++) {
            const uint32_t *v = triangles + 3 * (size_t)i;
            centroid[3 * (size_t)i + (size_t)d] =
                (positions[3 * (size_t)v[0] + (size_t)d] + positions[3 * (size_t)v[1] + (size_t)d] +
                 positions[3 * (size_t)v[2] + (size_t)d]) / 3.0f;
        }
    }
    /* Depth first, the right half waiting on the stack: a node's children
     * are allocated together, after it. */
    int top = 0;
    jobs[top++] = (build_job){0, 0, count, 0};
    t->node_count = 1;
    while (top > 0) {
        const build_job j = jobs[--top];
        pose__bvh_node *n = &t->nodes[j.node];
        const uint32_t len = j.end - j.begin;
        if (len <= POSE__BVH_LEAF) {
            n->first = j.begin;
            n->count = len;
            t->leaves[t->leaf_count++] = j.node;
            continue;
        }
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (uint32_t i = j.begin; i < j.end; i++)
            for (int d = 0; d < 3; d++) {
                const float c = centroid[3 * (size_t)t->items[i] + (size_t)d];
                lo[d] = fminf(lo[d], c);
                hi[d] = fmaxf(hi[d], c);
            }
        int axis = 0;
        for (int d = 1; d < 3; d++)
            if (hi[d] - lo[d] > hi[axis] - lo[axis])
                axis = d;
        const uint32_t mid = j.begin + len / 2;
        select_kth(t->items + j.begin, len, len / 2, centroid, axis);
        n->first = t->node_count;
        n->count = 0;
        t->node_count += 2;
        jobs[top++] = (build_job){n->first + 1, mid, j.end, j.depth + 1};
        jobs[top++] = (build_job){n->first, j.begin, mid, j.depth + 1};
    }
    pose__free(a, centroid);
    pose__free(a, jobs);

    uint32_t pairs[(size_t)1 << SPLIT_DEPTH], selfs[(size_t)2 << SPLIT_DEPTH], np = 0, ns = 0;
    collect_split(t, 0, 0, pairs, selfs, &np, &ns);
    memcpy(t->split_nodes, pairs, np * sizeof *pairs);
    memcpy(t->split_nodes + np, selfs, ns * sizeof *selfs);
    t->split_pairs = np;
    t->split_count = np + ns;
    pose__bvh_refit_leaves(t, positions, 0, t->leaf_count);
    pose__bvh_refit_inner(t);
    return POSE_OK;
}
