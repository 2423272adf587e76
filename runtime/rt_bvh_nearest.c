/* SPDX-License-Identifier: Apache-2.0 */
/* rt_bvh.h: the nearest point of a BVH's triangles to a point. */
#include <math.h>

#include "rt_bvh.h"

/* Closest point of triangle abc to p (Ericson, Real-Time Collision
 * Detection 5.1.5), and which feature holds it: POSE__NEAR_* codes. */
static void closest_on_tri(const float *p, const float *a, const float *b, const float *c, float *out,
                           int *feature)
{
    float ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int d = 0; d < 3; d++) {
        ab[d] = b[d] - a[d];
        ac[d] = c[d] - a[d];
        ap[d] = p[d] - a[d];
        bp[d] = p[d] - b[d];
        cp[d] = p[d] - c[d];
    }
#define DOT(u, v) ((u)[0] * (v)[0] + (u)[1] * (v)[1] + (u)[2] * (v)[2])
    const float d1 = DOT(ab, ap), d2 = DOT(ac, ap), d3 = DOT(ab, bp), d4 = DOT(ac, bp);
    const float d5 = DOT(ab, cp), d6 = DOT(ac, cp);
#undef DOT
    float s = 0.0f, t = 0.0f;
    if (d1 <= 0.0f && d2 <= 0.0f) {
        *feature = POSE__NEAR_V0;
    } else if (d3 >= 0.0f && d4 <= d3) {
        s = 1.0f;
        *feature = POSE__NEAR_V1;
    } else if (d6 >= 0.0f && d5 <= d6) {
        t = 1.0f;
        *feature = POSE__NEAR_V2;
    } else {
        const float vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) {
            s = d1 / (d1 - d3);
            *feature = POSE__NEAR_E01;
        } else if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) {
            t = d2 / (d2 - d6);
            *feature = POSE__NEAR_E20;
        } else if (va <= 0.0f && d4 - d3 >= 0.0f && d5 - d6 >= 0.0f) {
            t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            s = 1.0f - t;
            *feature = POSE__NEAR_E12;
        } else {
            const float den = 1.0f / (va + vb + vc);
            s = vb * den;
            t = vc * den;
            *feature = POSE__NEAR_FACE;
        }
    }
    for (int d = 0; d < 3; d++)
        out[d] = a[d] + s * ab[d] + t * ac[d];
}

float pose__point_tri_dist2(const float *p, const float *a, const float *b, const float *c)
{
    float q[3];
    int feature;
    closest_on_tri(p, a, b, c, q, &feature);
    return (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) + (q[2] - p[2]) * (q[2] - p[2]);
}

static float box_dist2(const pose__bvh_node *n, const float *p)
{
    float s = 0.0f;
    for (int d = 0; d < 3; d++) {
        const float e = p[d] < n->lo[d] ? n->lo[d] - p[d] : p[d] > n->hi[d] ? p[d] - n->hi[d] : 0.0f;
        s += e * e;
    }
    return s;
}

/* The nearest triangle of t to p within max_dist, or with `first`, the
 * first one found within it (nearer children first either way). */
static float search(const pose__bvh *t, const float *positions, const float *p, float max_dist, int first,
                    pose__bvh_near *out)
{
    uint32_t stack[POSE__BVH_MAX_DEPTH + 2];
    int top = 0;
    float best = max_dist * max_dist;
    out->triangle = UINT32_MAX;
    if (!t->node_count)
        return INFINITY;
    stack[top++] = 0;
    while (top > 0) {
        const pose__bvh_node *n = &t->nodes[stack[--top]];
        if (box_dist2(n, p) >= best)
            continue;
        if (!n->count) {
            /* The nearer child last, so that it is searched first. */
            const uint32_t a = n->first, b = n->first + 1;
            const int a_first = box_dist2(&t->nodes[a], p) <= box_dist2(&t->nodes[b], p);
            stack[top++] = a_first ? b : a;
            stack[top++] = a_first ? a : b;
            continue;
        }
        for (uint32_t i = n->first; i < n->first + n->count; i++) {
            const uint32_t *tri = t->triangles + 3 * (size_t)t->items[i];
            float q[3];
            int feature;
            closest_on_tri(p, positions + 3 * (size_t)tri[0], positions + 3 * (size_t)tri[1],
                           positions + 3 * (size_t)tri[2], q, &feature);
            const float e2 = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                             (q[2] - p[2]) * (q[2] - p[2]);
            if (e2 < best) {
                best = e2;
                out->triangle = t->items[i];
                out->feature = feature;
                for (int d = 0; d < 3; d++)
                    out->point[d] = q[d];
                if (first)
                    return sqrtf(best);
            }
        }
    }
    return out->triangle == UINT32_MAX ? INFINITY : sqrtf(best);
}

float pose__bvh_nearest(const pose__bvh *t, const float *positions, const float *p, float max_dist,
                        pose__bvh_near *out)
{
    return search(t, positions, p, max_dist, 0, out);
}

int pose__bvh_any_within(const pose__bvh *t, const float *positions, const float *p, float max_dist)
{
    pose__bvh_near near;
    return search(t, positions, p, max_dist, 1, &near) != INFINITY;
}
