/* SPDX-License-Identifier: Apache-2.0 */
/* contact_cover.h: the lifts at the start of the push's pass. */
#include "contact_cover.h"

#include <math.h>
#include <string.h>

#include "contact_push.h"
#include "state_internal.h"

/* Bone higher than this over a triangle's plane is not that triangle's to
 * cover (rig units: issue 13's poses bring bone out by up to 15.3 mm). */
#define COVER_MAX_HEIGHT 0.025f
/* A triangle's footprint grown to barycentric coordinates down to
 * -COVER_BORDER: bone over the edge between two tilted triangles lies over
 * neither's own. */
#define COVER_BORDER 0.1f
/* How much more than its lift a vertex may move so that a triangle tilted
 * from the vertex's direction still rises by its lift (rig units). */
#define COVER_TILT 0.0004f
/* How far over a triangle its centroid is tested for another layer of
 * skin (rig units). */
#define COVER_OVER 0.0001f
/* Items of the skin tree's refit. */
#define COVER_REFIT_ITEMS 16
/* Candidates kept per triangle and bone, highest first. */
#define COVER_CANDIDATES 64
/* Bone vertices deeper than this under a triangle's rest plane at rest
 * are not its candidates (rig units: a stretched knee triangle, 60-99 mm
 * long in flexion, slides over condyles that lay up to 60 mm under its
 * rest plane; 40 mm left 25 more bone vertices out at the four poses). */
#define COVER_REST_BELOW 0.08f
/* A lifted vertex that the push then moves is kept within this of the
 * longer of its lift and its push from where the method left it. */
#define COVER_BOUND_SLACK 0.00005f

typedef struct candidate {
    float h;      /* distance to the posed triangle: a bound on the protrusion */
    uint32_t v;   /* bone vertex */
    int over;     /* over the triangle: its projection inside it, on the outer side */
} candidate;

/* A skin triangle in its bones' rest frame (they share their joint's). */
typedef struct tri_query {
    float a[3], n[3];         /* posed corner 0, unit normal */
    float b[3], c2[3];        /* posed corners 1 and 2 */
    float e1[3], e2[3];       /* posed edges from corner 0 */
    float d00, d01, d11, inv; /* for barycentric coordinates */
    float ra[3], rn[3];       /* rest corner 0, unit normal */
    float lo[3], hi[3];       /* box of the posed prism up to the largest height */
    float rlo[3], rhi[3];     /* box of the rest triangle grown by how far it moved */
    float margin;
    int state;                /* 0: not set up yet; 1: set up; -1: degenerate */
} tri_query;

/* A triangle's candidates in one bone. */
typedef struct cand_list {
    int count;
    candidate c[COVER_CANDIDATES];
} cand_list;

static void to_rest(const float *f, const float *x, float *q)
{
    const float d[3] = {x[0] - f[9], x[1] - f[10], x[2] - f[11]};
    for (int c = 0; c < 3; c++)
        q[c] = f[c] * d[0] + f[3 + c] * d[1] + f[6 + c] * d[2];
}

static void to_posed(const float *f, const float *q, float *x)
{
    for (int r = 0; r < 3; r++)
        x[r] = f[3 * r] * q[0] + f[3 * r + 1] * q[1] + f[3 * r + 2] * q[2] + f[9 + r];
}

/* fminf and fmaxf are calls here (they order NaNs); positions are finite. */
static inline float min2(float a, float b)
{
    return a < b ? a : b;
}

static inline float max2(float a, float b)
{
    return a > b ? a : b;
}

static float dot3(const float *u, const float *v)
{
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
}

/* Unit normal of triangle (x0, x1, x2); 0 when degenerate. */
static int unit_normal(const float *x0, const float *x1, const float *x2, float *n)
{
    const float u[3] = {x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]},
                v[3] = {x2[0] - x0[0], x2[1] - x0[1], x2[2] - x0[2]};
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    const float l = sqrtf(dot3(n, n));
    if (!(l > 0.0f))
        return 0;
    for (int d = 0; d < 3; d++)
        n[d] /= l;
    return 1;
}

/* Set up q for posed corners x[3] and rest corners r[3] (bone frame). */
static int query_setup(tri_query *q, const float x[3][3], const float *const r[3], float margin, float moved)
{
    if (!unit_normal(x[0], x[1], x[2], q->n) || !unit_normal(r[0], r[1], r[2], q->rn))
        return 0;
    float longest = 0.0f;
    for (int d = 0; d < 3; d++) {
        q->a[d] = x[0][d];
        q->b[d] = x[1][d];
        q->c2[d] = x[2][d];
        q->ra[d] = r[0][d];
        q->e1[d] = x[1][d] - x[0][d];
        q->e2[d] = x[2][d] - x[0][d];
    }
    for (int k = 0; k < 3; k++) {
        const float *p = x[k], *s = x[(k + 1) % 3];
        longest = max2(longest, sqrtf((p[0] - s[0]) * (p[0] - s[0]) + (p[1] - s[1]) * (p[1] - s[1]) +
                                      (p[2] - s[2]) * (p[2] - s[2])));
    }
    q->d00 = dot3(q->e1, q->e1);
    q->d01 = dot3(q->e1, q->e2);
    q->d11 = dot3(q->e2, q->e2);
    const float det = q->d00 * q->d11 - q->d01 * q->d01;
    if (!(det > 0.0f))
        return 0;
    q->inv = 1.0f / det;
    const float grow = COVER_BORDER * 2.0f * longest + margin;
    for (int d = 0; d < 3; d++) {
        float lo = INFINITY, hi = -INFINITY;
        for (int k = 0; k < 3; k++) {
            lo = min2(lo, min2(x[k][d], x[k][d] + COVER_MAX_HEIGHT * q->n[d]));
            hi = max2(hi, max2(x[k][d], x[k][d] + COVER_MAX_HEIGHT * q->n[d]));
        }
        q->lo[d] = lo - grow;
        q->hi[d] = hi + grow;
        q->rlo[d] = min2(min2(r[0][d], r[1][d]), r[2][d]) - moved;
        q->rhi[d] = max2(max2(r[0][d], r[1][d]), r[2][d]) + moved;
    }
    q->margin = margin;
    return 1;
}

/* A node's box can hold a candidate: over the posed plane (less the
 * margin) below the largest height, in the prism's box, under the rest
 * plane within the counted depth, and near enough to the triangle at rest
 * for the triangle to have crossed it. */
static int node_may_hold(const tri_query *q, const pose__bvh_node *n)
{
    if (n->lo[0] > q->hi[0] || n->lo[1] > q->hi[1] || n->lo[2] > q->hi[2] || n->hi[0] < q->lo[0] ||
        n->hi[1] < q->lo[1] || n->hi[2] < q->lo[2] || n->lo[0] > q->rhi[0] || n->lo[1] > q->rhi[1] ||
        n->lo[2] > q->rhi[2] || n->hi[0] < q->rlo[0] || n->hi[1] < q->rlo[1] || n->hi[2] < q->rlo[2])
        return 0;
    float c[3], e[3], r = 0.0f, r0 = 0.0f;
    for (int d = 0; d < 3; d++) {
        c[d] = 0.5f * (n->lo[d] + n->hi[d]);
        e[d] = 0.5f * (n->hi[d] - n->lo[d]);
        r += fabsf(q->n[d]) * e[d];
        r0 += fabsf(q->rn[d]) * e[d];
    }
    const float s = (c[0] - q->a[0]) * q->n[0] + (c[1] - q->a[1]) * q->n[1] + (c[2] - q->a[2]) * q->n[2];
    const float s0 = (c[0] - q->ra[0]) * q->rn[0] + (c[1] - q->ra[1]) * q->rn[1] + (c[2] - q->ra[2]) * q->rn[2];
    return s + r > -q->margin && s - r < COVER_MAX_HEIGHT && s0 - r0 <= 0.0f && s0 + r0 >= -COVER_REST_BELOW;
}

/* Bone vertex v at x (rest frame) is a candidate of the triangle: kept
 * among the COVER_CANDIDATES highest (ties: the lower vertex number). */
static void point_test(const tri_query *q, cand_list *l, uint32_t v, const float *x)
{
    const float p[3] = {x[0] - q->a[0], x[1] - q->a[1], x[2] - q->a[2]};
    const float h = dot3(p, q->n);
    if (!(h > -q->margin && h < COVER_MAX_HEIGHT))
        return;
    const float r[3] = {x[0] - q->ra[0], x[1] - q->ra[1], x[2] - q->ra[2]};
    const float h0 = dot3(r, q->rn);
    if (h0 > 0.0f || h0 < -COVER_REST_BELOW)
        return;
    const float d20 = dot3(p, q->e1), d21 = dot3(p, q->e2);
    const float b1 = (q->d11 * d20 - q->d01 * d21) * q->inv, b2 = (q->d00 * d21 - q->d01 * d20) * q->inv;
    if (b1 <= -COVER_BORDER || b2 <= -COVER_BORDER || 1.0f - b1 - b2 <= -COVER_BORDER)
        return;
    const float dist = sqrtf(pose__point_tri_dist2(x, q->a, q->b, q->c2));
    const int over = h > 0.0f && b1 >= 0.0f && b2 >= 0.0f && 1.0f - b1 - b2 >= 0.0f;
    /* insert, farthest first */
    int k = l->count < COVER_CANDIDATES ? l->count++ : COVER_CANDIDATES;
    while (k > 0 && (l->c[k - 1].h < dist || (l->c[k - 1].h == dist && l->c[k - 1].v > v))) {
        if (k < COVER_CANDIDATES)
            l->c[k] = l->c[k - 1];
        k--;
    }
    if (k < COVER_CANDIDATES)
        l->c[k] = (candidate){dist, v, over};
}

/* The triangle's candidates in bone `tree` (its counted vertices; `rest`
 * the bone's rest positions). */
static void query_bone(const tri_query *q, cand_list *l, const pose__bvh *tree, const float *rest)
{
    uint32_t stack[2 * POSE__BVH_MAX_DEPTH + 2];
    int top = 0;
    if (tree->node_count)
        stack[top++] = 0;
    while (top > 0) {
        const pose__bvh_node *n = &tree->nodes[stack[--top]];
        if (!node_may_hold(q, n))
            continue;
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                const uint32_t v = tree->triangles[3 * (size_t)tree->items[i]];
                point_test(q, l, v, rest + 3 * (size_t)v);
            }
            continue;
        }
        stack[top++] = n->first;
        stack[top++] = n->first + 1;
    }
}

/* The triangle's lift from its candidates: tested farthest first against
 * the posed skin (out by its winding number; protruding by its distance
 * d to the skin, at most its distance to the triangle), until none left
 * can raise it. One over the triangle, or nearest to it (within 1e-6 of
 * d: a nearest edge or corner is each touching triangle's), lifts it by
 * d + margin. */
static float candidates_lift(const tri_query *q, const cand_list *cl, const pose__cover *l, const pose_state *st,
                             const float *f, const float *rest, float lift, int *covered, size_t *tested)
{
    if (!(cl->count > 0 && cl->c[0].h + q->margin > lift))
        return lift;
    float dir[3];
    for (int r = 0; r < 3; r++)
        dir[r] = f[3 * r] * q->n[0] + f[3 * r + 1] * q->n[1] + f[3 * r + 2] * q->n[2];
    if (*covered < 0) {
        /* A triangle inside the skin (another layer over its centroid: a
         * fold) covers nothing: bone over it is in that layer, or comes out
         * through that layer's own triangles. */
        float c[3], y[3];
        for (int d = 0; d < 3; d++)
            c[d] = (q->a[d] + q->b[d] + q->c2[d]) / 3.0f + COVER_OVER * q->n[d];
        to_posed(f, c, y);
        (*tested)++;
        *covered = pose__bvh_winding_along(&l->skin, st->tissue_positions, y, dir) > 0;
    }
    if (*covered)
        return lift;
    for (int k = 0; k < cl->count; k++) {
        const float dist = cl->c[k].h;
        if (!(dist + q->margin > lift))
            break;
        float b[3];
        to_posed(f, rest + 3 * (size_t)cl->c[k].v, b);
        (*tested)++;
        if (pose__bvh_winding_along(&l->skin, st->tissue_positions, b, dir) > 0)
            continue;
        pose__bvh_near near;
        const float reach = dist * 1.001f + 1e-6f;
        float d = pose__bvh_nearest(&l->skin, st->tissue_positions, b, reach, &near);
        d = d < dist ? d : dist;
        if (!cl->c[k].over && d < dist - 1e-6f)
            continue;
        lift = max2(lift, d + q->margin);
    }
    return lift;
}

/* One item: its clusters' triangles' lifts (each triangle is in one
 * cluster, each cluster in one item: no shared writes). A cluster's bones
 * come joint by joint: its vertices go into the joint's rest frame once,
 * each triangle is set up once, and queried in each of the joint's bones
 * that it may have crossed. */
static void cover_item(void *ctx, size_t item)
{
    pose_state *st = ctx;
    const pose__push *p = st->push;
    pose__cover *l = p->cover;
    size_t lifted = 0, tested = 0;
    float x[3 * POSE__COVER_CLUSTER][3], moved2[3 * POSE__COVER_CLUSTER];
    tri_query q[POSE__COVER_CLUSTER];
    int covered[POSE__COVER_CLUSTER];
    cand_list cands;
    const size_t cb = pose__part_begin(l->cluster_count, (unsigned)item, POSE__COVER_ITEMS),
                 ce = pose__part_begin(l->cluster_count, (unsigned)item + 1, POSE__COVER_ITEMS);
    for (size_t c = cb; c < ce; c++) {
        const size_t fb = c * POSE__COVER_CLUSTER,
                     fe = fb + POSE__COVER_CLUSTER < l->tri_count ? fb + POSE__COVER_CLUSTER : l->tri_count;
        const uint32_t vb = l->cluster_vert_begin[c], nv = l->cluster_vert_begin[c + 1] - vb;
        for (size_t t = fb; t < fe; t++)
            covered[t - fb] = -1;
        /* How far a vertex has moved from rest (model space): with the
         * joint's own motion over the rest sphere, a bound on its move
         * relative to the joint that spares most clusters the transforms. */
        float far2 = 0.0f;
        for (uint32_t i = 0; i < nv; i++) {
            const uint32_t v = l->cluster_verts[vb + i];
            const float *y = st->tissue_positions + 3 * (size_t)l->skin_vertex[v], *r = l->skin_rest + 3 * (size_t)v;
            const float dx = y[0] - r[0], dy = y[1] - r[1], dz = y[2] - r[2];
            far2 = max2(far2, dx * dx + dy * dy + dz * dz);
        }
        const float far = sqrtf(far2), *sphere = l->cluster_sphere + 4 * c;
        for (uint32_t k = l->pair_begin[c], run; k < l->pair_begin[c + 1]; k = run) {
            const int joint = p->bones[l->pair_bone[k]].joint;
            run = k + 1;
            while (run < l->pair_begin[c + 1] && p->bones[l->pair_bone[run]].joint == joint)
                run++;
            if (l->pair_rigid[k])
                continue;
            /* The cluster relative to the joint: skin that moved less,
             * relative to a bone, than its distance at rest to every
             * counted vertex has crossed none of them (a point of a
             * triangle moves no more than its corners). */
            const float *f = p->frames + 12 * (size_t)l->pair_bone[k];
            float most = 0.0f, clear = INFINITY;
            for (uint32_t kk = k; kk < run; kk++)
                clear = min2(clear, l->pair_clear[kk]);
            /* |R^T (r + e - t) - r| <= |R - I| |r - c| + |R^T (c - t) - c| + |e|,
             * |R - I| = sqrt(3 - tr R) (the rotation's chord) */
            float cq[3];
            to_rest(f, sphere, cq);
            const float turn = sqrtf(max2(3.0f - f[0] - f[4] - f[8], 0.0f)),
                        bound = turn * sphere[3] +
                                sqrtf((cq[0] - sphere[0]) * (cq[0] - sphere[0]) + (cq[1] - sphere[1]) * (cq[1] - sphere[1]) +
                                      (cq[2] - sphere[2]) * (cq[2] - sphere[2])) +
                                far;
            if (bound * 1.001f + 1e-6f < clear)
                continue;
            for (uint32_t i = 0; i < nv; i++) {
                const uint32_t v = l->cluster_verts[vb + i];
                to_rest(f, st->tissue_positions + 3 * (size_t)l->skin_vertex[v], x[i]);
                const float *r = l->skin_rest + 3 * (size_t)v;
                const float dx = x[i][0] - r[0], dy = x[i][1] - r[1], dz = x[i][2] - r[2];
                moved2[i] = dx * dx + dy * dy + dz * dz;
                most = max2(most, moved2[i]);
            }
            if (!(most > clear * clear))
                continue;
            for (size_t t = fb; t < fe; t++)
                q[t - fb].state = 0;
            for (uint32_t kk = k; kk < run; kk++) {
                if (!(most > l->pair_clear[kk] * l->pair_clear[kk]))
                    continue;
                const uint32_t j = l->pair_bone[kk];
                for (size_t t = fb; t < fe; t++) {
                    const uint8_t *w = l->tri_local + 3 * t;
                    const float moved = sqrtf(max2(max2(moved2[w[0]], moved2[w[1]]), moved2[w[2]]));
                    tri_query *qt = &q[t - fb];
                    if (!(moved > l->tri_clear[(size_t)kk * POSE__COVER_CLUSTER + (t - fb)]))
                        continue;
                    if (qt->state == 0) {
                        const uint32_t *v = l->tris + 3 * t;
                        float corners[3][3];
                        for (int i = 0; i < 3; i++)
                            memcpy(corners[i], x[w[i]], sizeof corners[i]);
                        const float *r[3] = {l->skin_rest + 3 * (size_t)v[0], l->skin_rest + 3 * (size_t)v[1],
                                             l->skin_rest + 3 * (size_t)v[2]};
                        qt->state = query_setup(qt, corners, r, p->margin, moved) ? 1 : -1;
                    }
                    if (qt->state < 0)
                        continue;
                    cands.count = 0;
                    query_bone(qt, &cands, &l->trees[j], p->bones[j].rest);
                    l->lift[t] = candidates_lift(qt, &cands, l, st, f, p->bones[j].rest, l->lift[t],
                                                 &covered[t - fb], &tested);
                }
            }
        }
        for (size_t t = fb; t < fe; t++)
            if (l->lift[t] > 0.0f)
                l->lifted_tris[cb * POSE__COVER_CLUSTER + lifted++] = (uint32_t)t; /* item_lifts */
    }
    l->lifted[item] = lifted;
    l->tested[item] = tested;
}

/* Item `item`'s lifted triangles (l->lifted[item] of them, ascending). */
static const uint32_t *item_lifts(const pose__cover *l, size_t item)
{
    return l->lifted_tris + pose__part_begin(l->cluster_count, (unsigned)item, POSE__COVER_ITEMS) * POSE__COVER_CLUSTER;
}

/* The lifts, serially in triangle order: each skin vertex moves along the
 * lift-weighted sum of its lifted triangles' (posed) normals by the most
 * that one of them needs along it. */
static void apply_lifts(pose_state *st, pose__cover *l)
{
    size_t touched = 0;
    for (size_t item = 0; item < POSE__COVER_ITEMS; item++) { /* item by item: triangle order */
        const uint32_t *list = item_lifts(l, item);
        for (size_t k = 0; k < l->lifted[item]; k++) {
            const size_t t = list[k];
            const uint32_t *v = l->tris + 3 * t;
            float n[3];
            if (!unit_normal(st->tissue_positions + 3 * (size_t)l->skin_vertex[v[0]],
                             st->tissue_positions + 3 * (size_t)l->skin_vertex[v[1]],
                             st->tissue_positions + 3 * (size_t)l->skin_vertex[v[2]], n))
                continue;
            for (int i = 0; i < 3; i++) {
                float *a = l->acc + 4 * (size_t)v[i];
                if (!(a[3] < 0.0f)) { /* first lift of this vertex: -1 marks it */
                    l->touched[touched++] = v[i];
                    a[0] = a[1] = a[2] = 0.0f;
                    a[3] = -1.0f;
                }
                for (int d = 0; d < 3; d++)
                    a[d] += l->lift[t] * n[d];
            }
        }
    }
    /* Per touched vertex: its direction, then the most its triangles need
     * along it (from the positions before any move). */
    for (size_t k = 0; k < touched; k++) {
        const uint32_t v = l->touched[k];
        float *a = l->acc + 4 * (size_t)v;
        const float len = sqrtf(dot3(a, a));
        float move = 0.0f;
        if (len > 0.0f) {
            for (int d = 0; d < 3; d++)
                a[d] /= len;
            for (uint32_t i = l->vert_tri_begin[v]; i < l->vert_tri_begin[v + 1]; i++) {
                const uint32_t t = l->vert_tris[i];
                const uint32_t *w = l->tris + 3 * t;
                float n[3];
                if (!(l->lift[t] > 0.0f) ||
                    !unit_normal(st->tissue_positions + 3 * (size_t)l->skin_vertex[w[0]],
                                 st->tissue_positions + 3 * (size_t)l->skin_vertex[w[1]],
                                 st->tissue_positions + 3 * (size_t)l->skin_vertex[w[2]], n))
                    continue;
                const float c = dot3(a, n), need = l->lift[t];
                move = max2(move, c * (need + COVER_TILT) > need ? need / c : need + COVER_TILT);
            }
        }
        a[3] = move;
    }
    float most = 0.0f;
    size_t moved = 0;
    for (size_t k = 0; k < touched; k++) {
        const float *a = l->acc + 4 * (size_t)l->touched[k];
        float *x = st->tissue_positions + 3 * (size_t)l->skin_vertex[l->touched[k]];
        if (a[3] > 0.0f) {
            for (int d = 0; d < 3; d++)
                x[d] += a[3] * a[d];
            most = max2(most, a[3]);
            moved++;
        }
    }
    for (size_t item = 0; item < POSE__COVER_ITEMS; item++) { /* the other lifts are 0 */
        const uint32_t *list = item_lifts(l, item);
        for (size_t k = 0; k < l->lifted[item]; k++)
            l->lift[list[k]] = 0.0f;
    }
    l->touched_count = touched;
    l->moved = moved;
    l->max_move = most;
}

float pose__cover_bound(const pose__push *p, const pose__push_bone *b, const float *f, size_t i,
                        const float *before, float *x)
{
    const pose__cover *l = p->cover;
    const uint32_t v = l->order_vertex[i];
    if (v == UINT32_MAX || !(l->acc[4 * (size_t)v + 3] > 0.0f))
        return -1.0f;
    const float *a = l->acc + 4 * (size_t)v;
    float x0[3], total[3], sd, c[3], out[3], push = 0.0f;
    for (int d = 0; d < 3; d++) {
        x0[d] = before[d] - a[3] * a[d];
        total[d] = x[d] - x0[d];
    }
    if (pose__push_query(p, b, f, x0, NULL, &sd, c, out, NULL)) {
        float q[3], z[3];
        for (int d = 0; d < 3; d++)
            q[d] = c[d] + p->margin * out[d];
        to_posed(f, q, z);
        push = sqrtf((z[0] - x0[0]) * (z[0] - x0[0]) + (z[1] - x0[1]) * (z[1] - x0[1]) +
                     (z[2] - x0[2]) * (z[2] - x0[2]));
    }
    const float cap = max2(a[3], push) + COVER_BOUND_SLACK, len = sqrtf(dot3(total, total));
    if (!(len > cap))
        return len;
    for (int d = 0; d < 3; d++)
        x[d] = x0[d] + total[d] * (cap / len);
    return cap;
}

void pose__cover_finish(pose__cover *l)
{
    for (size_t k = 0; k < l->touched_count; k++)
        memset(l->acc + 4 * (size_t)l->touched[k], 0, 4 * sizeof(float));
    l->touched_count = 0;
}

/* The skin tree's leaves, item by item. */
static void refit_item(void *ctx, size_t item)
{
    pose_state *st = ctx;
    pose__cover *l = st->push->cover;
    pose__bvh_refit_leaves(&l->skin, st->tissue_positions,
                           pose__part_begin(l->skin.leaf_count, (unsigned)item, COVER_REFIT_ITEMS),
                           pose__part_begin(l->skin.leaf_count, (unsigned)item + 1, COVER_REFIT_ITEMS));
}

void pose__state_cover(pose_state *st)
{
    pose__cover *l = st->push->cover;
    pose__pool_run_items(st->pool, refit_item, st, COVER_REFIT_ITEMS);
    pose__bvh_refit_inner(&l->skin);
    pose__pool_run_items(st->pool, cover_item, st, POSE__COVER_ITEMS);
    apply_lifts(st, l);
}
