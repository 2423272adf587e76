/* SPDX-License-Identifier: Apache-2.0 */
/* contact_cover.h: the bones' counted vertices and their trees, the skin's
 * triangle clusters and the bones near each, built with the push. */
#include "contact_cover.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "contact_build.h"
#include "contact_push.h"
#include "error.h"
#include "morton.h"
#include "state_internal.h"

typedef struct cover_build {
    pose__cover *l;
    const pose_allocator *a;
    const pose_state *st;
    uint32_t *skin_tris; /* 3 per triangle, skin vertex numbers, rig order */
    size_t *tissue;      /* per bone: its tissue */
} cover_build;

static pose_status oom(const char *what)
{
    return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for the contact cover's %s", what);
}

/* The skin tissues as one surface: vertex numbers, rest positions, triangles. */
static pose_status gather_skin(cover_build *b)
{
    const pose_rig *rig = b->st->rig;
    pose__cover *l = b->l;
    size_t nv = 0, nt = 0;
    for (size_t t = 0; t < rig->tissue_count; t++)
        if (rig->tissues[t].kind == POSE_TISSUE_SKIN) {
            nv += rig->tissues[t].vertex_count;
            nt += rig->tissues[t].triangle_count;
        }
    l->vertex_count = nv;
    l->tri_count = nt;
    l->skin_rest = pose__alloc(b->a, (3 * nv + 1) * sizeof(float), POSE__ALIGN);
    b->skin_tris = pose__alloc(b->a, (3 * nt + 1) * sizeof(uint32_t), POSE__ALIGN);
    l->skin_vertex = pose__alloc(b->a, (nv + 1) * sizeof *l->skin_vertex, POSE__ALIGN);
    if (!l->skin_rest || !b->skin_tris || !l->skin_vertex)
        return oom("skin");
    size_t v0 = 0, f = 0;
    for (size_t t = 0; t < rig->tissue_count; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        if (ts->kind != POSE_TISSUE_SKIN)
            continue;
        for (size_t v = 0; v < ts->vertex_count; v++) {
            const size_t g = b->st->rt->tissue_offset[t] + v;
            l->skin_vertex[v0 + v] = (uint32_t)g;
            memcpy(l->skin_rest + 3 * (v0 + v), ts->positions + 3 * v, 3 * sizeof(float));
        }
        for (size_t k = 0; k < 3 * ts->triangle_count; k++)
            b->skin_tris[f++] = (uint32_t)v0 + ts->triangles[k];
        v0 += ts->vertex_count;
    }
    return pose__bvh_build(&l->skin, b->a, b->skin_tris, (uint32_t)nt, l->skin_rest);
}

/* The skin tree, built over skin vertex numbers at rest, from now on reads
 * the posed tissue vertices. */
static pose_status skin_tree_posed(cover_build *b)
{
    pose__cover *l = b->l;
    l->skin_tris = pose__alloc(b->a, (3 * l->tri_count + 1) * sizeof *l->skin_tris, POSE__ALIGN);
    if (!l->skin_tris)
        return oom("skin tree");
    for (size_t k = 0; k < 3 * l->tri_count; k++)
        l->skin_tris[k] = l->skin_vertex[b->skin_tris[k]];
    l->skin.triangles = l->skin_tris;
    return pose__bvh_index_corners(&l->skin, b->a); /* the refit reads each vertex once */
}

/* A bone's counted vertices: inside the rest skin (its winding number, as
 * pose_contact_detect counts) and within POSE__COVER_DEPTH of it. */
static pose_status bone_points(cover_build *b, size_t j, const pose__tissue *ts)
{
    const float depth = POSE__COVER_DEPTH;
    pose__cover *l = b->l;
    uint32_t *pts = pose__alloc(b->a, (3 * ts->vertex_count + 1) * sizeof *pts, POSE__ALIGN);
    if (!pts)
        return oom("bone vertices");
    uint32_t n = 0;
    for (size_t v = 0; v < ts->vertex_count; v++) {
        const float *x = ts->positions + 3 * v;
        if (!pose__bvh_any_within(&l->skin, l->skin_rest, x, depth) ||
            pose__bvh_winding(&l->skin, l->skin_rest, x) <= 0)
            continue;
        pts[3 * n] = pts[3 * n + 1] = pts[3 * n + 2] = (uint32_t)v;
        n++;
    }
    l->points[j] = pts;
    return pose__bvh_build(&l->trees[j], b->a, pts, n, ts->positions);
}

/* Triangles in Morton order of their rest centroids (runs of
 * POSE__COVER_CLUSTER are compact clusters). */
static pose_status order_triangles(cover_build *b)
{
    pose__cover *l = b->l;
    const size_t nt = l->tri_count;
    l->cluster_count = (nt + POSE__COVER_CLUSTER - 1) / POSE__COVER_CLUSTER;
    l->tris = pose__alloc(b->a, (3 * nt + 1) * sizeof *l->tris, POSE__ALIGN);
    pose__morton *k = pose__alloc(b->a, (nt + 1) * sizeof *k, POSE__ALIGN);
    if (!l->tris || !k) {
        pose__free(b->a, k);
        return oom("triangles");
    }
    const pose__bvh_node *root = &l->skin.nodes[0];
    for (size_t f = 0; f < nt; f++) {
        float c[3] = {0.0f, 0.0f, 0.0f};
        for (int d = 0; d < 3; d++)
            for (int i = 0; i < 3; i++)
                c[d] += l->skin_rest[3 * (size_t)b->skin_tris[3 * f + (size_t)i] + (size_t)d] / 3.0f;
        k[f] = (pose__morton){pose__morton_key(c, root->lo, root->hi), (uint32_t)f};
    }
    qsort(k, nt, sizeof *k, pose__morton_cmp);
    for (size_t f = 0; f < nt; f++)
        for (int i = 0; i < 3; i++)
            l->tris[3 * f + (size_t)i] = b->skin_tris[3 * (size_t)k[f].index + (size_t)i];
    pose__free(b->a, k);
    return POSE_OK;
}

/* Per cluster its distinct vertices, and the bones with a counted vertex
 * within POSE__COVER_DEPTH of its rest box. */
static pose_status cluster_lists(cover_build *b)
{
    const float depth = POSE__COVER_DEPTH;
    pose__cover *l = b->l;
    const size_t nc = l->cluster_count;
    l->cluster_vert_begin = pose__alloc(b->a, (nc + 1) * sizeof(uint32_t), POSE__ALIGN);
    l->cluster_verts = pose__alloc(b->a, (3 * l->tri_count + 1) * sizeof(uint32_t), POSE__ALIGN);
    l->pair_begin = pose__alloc(b->a, (nc + 1) * sizeof(uint32_t), POSE__ALIGN);
    l->pair_bone = pose__alloc(b->a, (nc * l->bone_count + 1) * sizeof(uint32_t), POSE__ALIGN);
    l->tri_local = pose__alloc(b->a, 3 * l->tri_count + 1, POSE__ALIGN);
    l->cluster_sphere = pose__alloc(b->a, (4 * nc + 1) * sizeof(float), POSE__ALIGN);
    uint32_t *seen = pose__calloc(b->a, (l->vertex_count + 1) * sizeof *seen, POSE__ALIGN);
    uint8_t *local = pose__alloc(b->a, l->vertex_count + 1, POSE__ALIGN);
    uint32_t *stack = pose__alloc(b->a, (2 * POSE__BVH_MAX_DEPTH + 2) * sizeof *stack, POSE__ALIGN);
    if (!l->cluster_vert_begin || !l->cluster_verts || !l->pair_begin || !l->pair_bone || !l->tri_local ||
        !l->cluster_sphere || !seen || !local || !stack) {
        pose__free(b->a, seen);
        pose__free(b->a, local);
        pose__free(b->a, stack);
        return oom("clusters");
    }
    uint32_t nv = 0, np = 0;
    for (size_t c = 0; c < nc; c++) {
        l->cluster_vert_begin[c] = nv;
        l->pair_begin[c] = np;
        const size_t fb = c * POSE__COVER_CLUSTER,
                     fe = fb + POSE__COVER_CLUSTER < l->tri_count ? fb + POSE__COVER_CLUSTER : l->tri_count;
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t f = fb; f < fe; f++)
            for (int i = 0; i < 3; i++) {
                const uint32_t v = l->tris[3 * f + (size_t)i];
                if (seen[v] != c + 1) {
                    seen[v] = (uint32_t)c + 1;
                    local[v] = (uint8_t)(nv - l->cluster_vert_begin[c]);
                    l->cluster_verts[nv++] = v;
                }
                l->tri_local[3 * f + (size_t)i] = local[v];
                for (int d = 0; d < 3; d++) {
                    lo[d] = fminf(lo[d], l->skin_rest[3 * (size_t)v + (size_t)d] - depth);
                    hi[d] = fmaxf(hi[d], l->skin_rest[3 * (size_t)v + (size_t)d] + depth);
                }
            }
        for (size_t j = 0; j < l->bone_count; j++) {
            const pose__bvh *t = &l->trees[j];
            int near = 0, top = 0;
            if (t->node_count)
                stack[top++] = 0;
            while (top > 0 && !near) {
                const pose__bvh_node *n = &t->nodes[stack[--top]];
                if (n->lo[0] > hi[0] || n->lo[1] > hi[1] || n->lo[2] > hi[2] || n->hi[0] < lo[0] ||
                    n->hi[1] < lo[1] || n->hi[2] < lo[2])
                    continue;
                if (n->count) {
                    near = 1;
                    continue;
                }
                stack[top++] = n->first;
                stack[top++] = n->first + 1;
            }
            if (!near)
                continue;
            /* in order of joint, then bone: a joint's bones share its frame */
            const int joint = b->st->rig->tissues[b->tissue[j]].joint;
            uint32_t k = np++;
            while (k > l->pair_begin[c] && b->st->rig->tissues[b->tissue[l->pair_bone[k - 1]]].joint > joint) {
                l->pair_bone[k] = l->pair_bone[k - 1];
                k--;
            }
            l->pair_bone[k] = (uint32_t)j;
        }
    }
    l->cluster_vert_begin[nc] = nv;
    l->pair_begin[nc] = np;
    for (size_t c = 0; c < nc; c++) { /* rest spheres: the box's centre, the farthest vertex */
        float *sp = l->cluster_sphere + 4 * c, lo[3] = {INFINITY, INFINITY, INFINITY},
              hi[3] = {-INFINITY, -INFINITY, -INFINITY}, r2 = 0.0f;
        for (uint32_t i = l->cluster_vert_begin[c]; i < l->cluster_vert_begin[c + 1]; i++)
            for (int d = 0; d < 3; d++) {
                lo[d] = fminf(lo[d], l->skin_rest[3 * (size_t)l->cluster_verts[i] + (size_t)d]);
                hi[d] = fmaxf(hi[d], l->skin_rest[3 * (size_t)l->cluster_verts[i] + (size_t)d]);
            }
        for (int d = 0; d < 3; d++)
            sp[d] = 0.5f * (lo[d] + hi[d]);
        for (uint32_t i = l->cluster_vert_begin[c]; i < l->cluster_vert_begin[c + 1]; i++) {
            const float *r = l->skin_rest + 3 * (size_t)l->cluster_verts[i];
            r2 = fmaxf(r2, (r[0] - sp[0]) * (r[0] - sp[0]) + (r[1] - sp[1]) * (r[1] - sp[1]) +
                               (r[2] - sp[2]) * (r[2] - sp[2]));
        }
        sp[3] = sqrtf(r2) * 1.0001f + 1e-6f;
    }
    pose__free(b->a, seen);
    pose__free(b->a, local);
    pose__free(b->a, stack);
    return POSE_OK;
}

/* Squared distance between a node's box and the box lo..hi. */
static float box_gap2(const pose__bvh_node *n, const float *lo, const float *hi)
{
    float gap = 0.0f;
    for (int d = 0; d < 3; d++) {
        const float e = n->lo[d] > hi[d] ? n->lo[d] - hi[d] : lo[d] > n->hi[d] ? lo[d] - n->hi[d] : 0.0f;
        gap += e * e;
    }
    return gap;
}

/* The least distance from the counted vertices of bone j (rest positions
 * `rest`) to triangle r, found up to `cap` (cap when none is nearer):
 * boxes against the triangle's box, the nearer child first (the least so
 * far then prunes more of the other), then exact distances. */
static float tri_clearance(const pose__bvh *t, const float *rest, const float *const r[3], float cap,
                           uint32_t *stack)
{
    float lo[3], hi[3], best = cap * cap;
    for (int d = 0; d < 3; d++) {
        lo[d] = fminf(fminf(r[0][d], r[1][d]), r[2][d]);
        hi[d] = fmaxf(fmaxf(r[0][d], r[1][d]), r[2][d]);
    }
    int top = 0;
    if (t->node_count && box_gap2(&t->nodes[0], lo, hi) < best)
        stack[top++] = 0;
    while (top > 0) {
        const pose__bvh_node *n = &t->nodes[stack[--top]];
        if (box_gap2(n, lo, hi) >= best) /* best may have shrunk since it was pushed */
            continue;
        if (!n->count) {
            const uint32_t a = n->first, b = n->first + 1;
            const float ga = box_gap2(&t->nodes[a], lo, hi), gb = box_gap2(&t->nodes[b], lo, hi);
            const int a_first = ga <= gb; /* pushed last, popped first */
            if ((a_first ? gb : ga) < best)
                stack[top++] = a_first ? b : a;
            if ((a_first ? ga : gb) < best)
                stack[top++] = a_first ? a : b;
            continue;
        }
        for (uint32_t i = n->first; i < n->first + n->count; i++) {
            const float d2 = pose__point_tri_dist2(rest + 3 * (size_t)t->triangles[3 * (size_t)t->items[i]], r[0],
                                                   r[1], r[2]);
            best = d2 < best ? d2 : best;
        }
    }
    return sqrtf(best);
}

/* Cluster c's pairs: per pair and per triangle of the cluster, the distance
 * at rest between the triangle and the bone's counted vertices (skin must
 * move by more, relative to the bone, to cross one of them). An item of the
 * state's pool: it writes its own pairs' entries only. */
static void clearance_item(void *ctx, size_t c)
{
    const cover_build *b = ctx;
    pose__cover *l = b->l;
    uint32_t stack[2 * POSE__BVH_MAX_DEPTH + 2];
    for (uint32_t k = l->pair_begin[c]; k < l->pair_begin[c + 1]; k++) {
        const uint32_t j = l->pair_bone[k];
        const float *rest = b->st->rig->tissues[b->tissue[j]].positions;
        float least = INFINITY;
        for (size_t i = 0; i < POSE__COVER_CLUSTER; i++) {
            const size_t f = c * POSE__COVER_CLUSTER + i;
            float clear = INFINITY;
            if (f < l->tri_count) {
                const uint32_t *v = l->tris + 3 * f;
                const float *r[3] = {l->skin_rest + 3 * (size_t)v[0], l->skin_rest + 3 * (size_t)v[1],
                                     l->skin_rest + 3 * (size_t)v[2]};
                clear = tri_clearance(&l->trees[j], rest, r, 2.0f * POSE__COVER_DEPTH, stack);
            }
            l->tri_clear[(size_t)k * POSE__COVER_CLUSTER + i] = clear;
            least = fminf(least, clear);
        }
        l->pair_clear[k] = least;
    }
}

/* Every pair's clearances, clusters shared out among the state's threads. */
static pose_status clearances(cover_build *b)
{
    pose__cover *l = b->l;
    const size_t np = l->pair_begin[l->cluster_count];
    l->pair_clear = pose__alloc(b->a, (np + 1) * sizeof(float), POSE__ALIGN);
    l->tri_clear = pose__alloc(b->a, (np * POSE__COVER_CLUSTER + 1) * sizeof(float), POSE__ALIGN);
    if (!l->pair_clear || !l->tri_clear)
        return oom("clearances");
    pose__pool_run_items(b->st->pool, clearance_item, b, l->cluster_count);
    return POSE_OK;
}

void pose__cover_release(pose__cover *l, const pose_allocator *a)
{
    for (size_t j = 0; l->trees && j < l->bone_count; j++) {
        pose__bvh_release(&l->trees[j], a);
        pose__free(a, l->points[j]);
    }
    pose__free(a, l->trees);
    pose__free(a, l->points);
    pose__free(a, l->tris);
    pose__free(a, l->skin_rest);
    pose__free(a, l->skin_vertex);
    pose__free(a, l->vert_tri_begin);
    pose__free(a, l->vert_tris);
    pose__free(a, l->cluster_vert_begin);
    pose__free(a, l->cluster_verts);
    pose__free(a, l->tri_local);
    pose__free(a, l->cluster_sphere);
    pose__free(a, l->pair_begin);
    pose__free(a, l->pair_bone);
    pose__free(a, l->pair_clear);
    pose__free(a, l->tri_clear);
    pose__free(a, l->pair_rigid);
    pose__bvh_release(&l->skin, a);
    pose__free(a, l->skin_tris);
    pose__free(a, l->lift);
    pose__free(a, l->lifted_tris);
    pose__free(a, l->acc);
    pose__free(a, l->touched);
    pose__free(a, l->order_vertex);
    memset(l, 0, sizeof *l);
}

/* Per skin vertex its triangles (indices in cluster order), in order. */
static pose_status vertex_triangles(cover_build *b)
{
    pose__cover *l = b->l;
    l->vert_tri_begin = pose__calloc(b->a, (l->vertex_count + 2) * sizeof(uint32_t), POSE__ALIGN);
    l->vert_tris = pose__alloc(b->a, (3 * l->tri_count + 1) * sizeof(uint32_t), POSE__ALIGN);
    if (!l->vert_tri_begin || !l->vert_tris)
        return oom("triangles of each vertex");
    for (size_t k = 0; k < 3 * l->tri_count; k++)
        l->vert_tri_begin[l->tris[k] + 2]++;
    for (size_t v = 0; v < l->vertex_count; v++)
        l->vert_tri_begin[v + 2] += l->vert_tri_begin[v + 1];
    /* begin[v + 1] counts up as v's triangles are placed: ends at begin[v + 2]'s old value */
    for (size_t f = 0; f < l->tri_count; f++)
        for (int i = 0; i < 3; i++)
            l->vert_tris[l->vert_tri_begin[l->tris[3 * f + (size_t)i] + 1]++] = (uint32_t)f;
    return POSE_OK;
}

/* The joint a skin vertex moves with rigidly, whatever the method (as
 * contact_push_build.c's mark_rigid finds it: embedded in a bone tet of
 * that joint whose four corners are weighted to it alone), or -1. */
static int rigid_joint(const cover_build *b, uint32_t g)
{
    const pose_rig *rig = b->st->rig;
    size_t t = 0;
    while (b->st->rt->tissue_offset[t + 1] <= g)
        t++;
    const uint32_t tet = rig->tissues[t].tet[g - b->st->rt->tissue_offset[t]];
    if (!rig->tet_labels || rig->tet_labels[tet] == 0)
        return -1;
    const int joint = rig->tet_labels[tet] - 1;
    const unsigned K = rig->influences;
    for (int c = 0; c < 4; c++) {
        const size_t tv = rig->tets[4 * (size_t)tet + (size_t)c];
        float w = 0.0f;
        for (unsigned k = 0; k < K; k++)
            if (rig->weight_joints[K * tv + k] == joint)
                w += rig->weights[K * tv + k];
        if (!(w >= 1.0f - 1e-6f))
            return -1;
    }
    return joint;
}

/* Per pair: every vertex of the cluster moves rigidly with the bone's
 * joint, so the cluster keeps its rest place relative to the bone. */
static pose_status rigid_pairs(cover_build *b)
{
    pose__cover *l = b->l;
    const size_t np = l->pair_begin[l->cluster_count];
    l->pair_rigid = pose__alloc(b->a, np + 1, POSE__ALIGN);
    int *joint = pose__alloc(b->a, (l->vertex_count + 1) * sizeof *joint, POSE__ALIGN);
    if (!l->pair_rigid || !joint) {
        pose__free(b->a, joint);
        return oom("pairs");
    }
    for (size_t v = 0; v < l->vertex_count; v++)
        joint[v] = rigid_joint(b, l->skin_vertex[v]);
    for (size_t c = 0; c < l->cluster_count; c++)
        for (uint32_t k = l->pair_begin[c]; k < l->pair_begin[c + 1]; k++) {
            const int bone_joint = b->st->rig->tissues[b->tissue[l->pair_bone[k]]].joint;
            int rigid = 1;
            for (uint32_t i = l->cluster_vert_begin[c]; i < l->cluster_vert_begin[c + 1] && rigid; i++)
                rigid = joint[l->cluster_verts[i]] == bone_joint;
            l->pair_rigid[k] = (uint8_t)rigid;
        }
    pose__free(b->a, joint);
    return POSE_OK;
}

/* Per entry of the push's order (tissue vertices), its skin vertex number. */
static pose_status order_vertices(cover_build *b, const pose__push *push)
{
    pose__cover *l = b->l;
    const size_t all = b->st->rt->tissue_offset[b->st->rig->tissue_count];
    uint32_t *number = pose__alloc(b->a, (all + 1) * sizeof *number, POSE__ALIGN);
    l->order_vertex = pose__alloc(b->a, (push->vertex_count + 1) * sizeof *l->order_vertex, POSE__ALIGN);
    if (!number || !l->order_vertex) {
        pose__free(b->a, number);
        return oom("skin vertices");
    }
    for (size_t g = 0; g < all; g++)
        number[g] = UINT32_MAX;
    for (size_t v = 0; v < l->vertex_count; v++)
        number[l->skin_vertex[v]] = (uint32_t)v;
    for (size_t i = 0; i < push->vertex_count; i++)
        l->order_vertex[i] = number[push->order[i]];
    pose__free(b->a, number);
    return POSE_OK;
}

pose_status pose__cover_build(pose__cover *l, const pose_state *st, const pose__push *push)
{
    const pose_allocator *a = &push->allocator;
    cover_build b = {.l = l, .a = a, .st = st};
    memset(l, 0, sizeof *l);
    l->bone_count = push->bone_count;
    l->trees = pose__calloc(a, (l->bone_count + 1) * sizeof *l->trees, POSE__ALIGN);
    l->points = pose__calloc(a, (l->bone_count + 1) * sizeof *l->points, POSE__ALIGN);
    b.tissue = pose__alloc(a, (l->bone_count + 1) * sizeof *b.tissue, POSE__ALIGN);
    pose_status s = l->trees && l->points && b.tissue ? gather_skin(&b) : oom("bones");
    /* The push's bones are the rig's bone tissues with a joint and
     * triangles, in order. */
    const pose_rig *rig = st->rig;
    for (size_t t = 0, j = 0; t < rig->tissue_count && s == POSE_OK; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        if (ts->kind == POSE_TISSUE_BONE && ts->joint >= 0 && ts->triangle_count > 0) {
            b.tissue[j] = t;
            s = bone_points(&b, j++, ts);
        }
    }
    if (s == POSE_OK)
        s = order_triangles(&b);
    if (s == POSE_OK)
        s = vertex_triangles(&b);
    if (s == POSE_OK)
        s = cluster_lists(&b);
    if (s == POSE_OK)
        s = clearances(&b);
    if (s == POSE_OK)
        s = rigid_pairs(&b);
    if (s == POSE_OK)
        s = skin_tree_posed(&b);
    if (s == POSE_OK) {
        l->lift = pose__calloc(a, (l->tri_count + 1) * sizeof(float), POSE__ALIGN);
        l->acc = pose__calloc(a, (4 * l->vertex_count + 1) * sizeof(float), POSE__ALIGN);
        l->touched = pose__alloc(a, (l->vertex_count + 1) * sizeof(uint32_t), POSE__ALIGN);
        l->lifted_tris = pose__alloc(a, (l->tri_count + 1) * sizeof(uint32_t), POSE__ALIGN);
        if (!l->lift || !l->acc || !l->touched || !l->lifted_tris)
            s = oom("work arrays");
    }
    if (s == POSE_OK)
        s = order_vertices(&b, push);
    pose__free(a, b.skin_tris);
    pose__free(a, b.tissue);
    return s;
}
