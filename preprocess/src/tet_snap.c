/* SPDX-License-Identifier: Apache-2.0
 *
 * Boundary snapping for the lattice mesher: a bucket grid of the surface
 * triangles, a ray cast along each boundary vertex's staircase normal (so
 * corners go to corners), the closest point as fallback, and a volume check
 * on the incident tets that halves or drops a move rather than invert.
 */
#include "tet_snap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A move may not push an incident tet below this shape quality (or below
 * its own, if already worse): about 0.2 keeps dihedral angles above ~10 deg. */
#ifndef PP_SNAP_MIN_SHAPE
#define PP_SNAP_MIN_SHAPE 0.2
#endif
/* Sweeps over the boundary: moves cut short go further in later ones. */
#ifndef PP_SNAP_SWEEPS
#define PP_SNAP_SWEEPS 4
#endif

typedef struct buckets {
    double o[3], b;   /* origin, bucket edge */
    int n[3];
    size_t *start;    /* n0*n1*n2 + 1 */
    uint32_t *tri;
} buckets;

static void bucket_range(const buckets *g, const double lo[3], const double hi[3], int a[3],
                         int z[3])
{
    for (int k = 0; k < 3; k++) {
        double l = floor((lo[k] - g->o[k]) / g->b), h = floor((hi[k] - g->o[k]) / g->b);
        a[k] = l < 0 ? 0 : l >= g->n[k] ? g->n[k] - 1 : (int)l;
        z[k] = h < 0 ? 0 : h >= g->n[k] ? g->n[k] - 1 : (int)h;
    }
}

static void tri_bounds(const pp_mesh *m, size_t t, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 3; k++) {
            double v = m->positions[3 * (size_t)m->triangles[3 * t + c] + k];
            lo[k] = fmin(lo[k], v);
            hi[k] = fmax(hi[k], v);
        }
}

static pose_status buckets_build(const pp_mesh *m, double b, buckets *g)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < m->vertex_count; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], m->positions[3 * i + k]);
            hi[k] = fmax(hi[k], m->positions[3 * i + k]);
        }
    /* Keep the grid to a few million buckets whatever the reach. */
    for (;;) {
        double cnt = 1;
        for (int k = 0; k < 3; k++)
            cnt *= floor((hi[k] - lo[k]) / b) + 1;
        if (cnt < 4e6)
            break;
        b *= 1.5;
    }
    g->b = b;
    size_t total = 1;
    for (int k = 0; k < 3; k++) {
        g->o[k] = lo[k];
        g->n[k] = (int)floor((hi[k] - lo[k]) / b) + 1;
        total *= (size_t)g->n[k];
    }
    g->start = calloc(total + 1, sizeof *g->start);
    if (!g->start)
        return POSE_ERR_OUT_OF_MEMORY;
    int a[3], z[3];
    double tl[3], th[3];
    for (int pass = 0; pass < 2; pass++) {
        for (size_t t = 0; t < m->triangle_count; t++) {
            tri_bounds(m, t, tl, th);
            bucket_range(g, tl, th, a, z);
            for (int k = a[2]; k <= z[2]; k++)
                for (int j = a[1]; j <= z[1]; j++)
                    for (int i = a[0]; i <= z[0]; i++) {
                        size_t c = (size_t)i + (size_t)g->n[0] * ((size_t)j + (size_t)g->n[1] * k);
                        if (pass == 0)
                            g->start[c + 1]++;
                        else
                            g->tri[g->start[c]++] = (uint32_t)t;
                    }
        }
        if (pass == 0) {
            for (size_t c = 0; c < total; c++)
                g->start[c + 1] += g->start[c];
            g->tri = malloc((g->start[total] ? g->start[total] : 1) * sizeof *g->tri);
            if (!g->tri)
                return POSE_ERR_OUT_OF_MEMORY;
        }
    }
    /* The fill pass advanced each start to the next bucket's: shift back. */
    memmove(g->start + 1, g->start, total * sizeof *g->start);
    g->start[0] = 0;
    return POSE_OK;
}

static void sub3(const double *a, const double *b, double *r)
{
    r[0] = a[0] - b[0];
    r[1] = a[1] - b[1];
    r[2] = a[2] - b[2];
}
static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static void cross3(const double *a, const double *b, double *r)
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}

static void tri_points(const pp_mesh *m, uint32_t t, double v[3][3])
{
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 3; k++)
            v[c][k] = m->positions[3 * (size_t)m->triangles[3 * (size_t)t + c] + k];
}

/* Line p + s d (d unit) against a triangle (Moller-Trumbore); s any sign. */
static int ray_tri(const double p[3], const double d[3], double v[3][3], double *s)
{
    double e1[3], e2[3], q[3], tv[3], r[3];
    sub3(v[1], v[0], e1);
    sub3(v[2], v[0], e2);
    cross3(d, e2, q);
    double det = dot3(e1, q);
    if (fabs(det) < 1e-30)
        return 0;
    double inv = 1.0 / det;
    sub3(p, v[0], tv);
    double u = dot3(tv, q) * inv;
    if (u < -1e-9 || u > 1.0 + 1e-9)
        return 0;
    cross3(tv, e1, r);
    double w = dot3(d, r) * inv;
    if (w < -1e-9 || u + w > 1.0 + 1e-9)
        return 0;
    *s = dot3(e2, r) * inv;
    return 1;
}

/* Closest point on triangle v to p (Ericson, Real-Time Collision Detection 5.1.5). */
static void closest_on_tri(const double p[3], double v[3][3], double out[3])
{
    double ab[3], ac[3], ap[3];
    sub3(v[1], v[0], ab);
    sub3(v[2], v[0], ac);
    sub3(p, v[0], ap);
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        memcpy(out, v[0], sizeof(double) * 3);
        return;
    }
    double bp[3];
    sub3(p, v[1], bp);
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        memcpy(out, v[1], sizeof(double) * 3);
        return;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double t = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++)
            out[k] = v[0][k] + t * ab[k];
        return;
    }
    double cp[3];
    sub3(p, v[2], cp);
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        memcpy(out, v[2], sizeof(double) * 3);
        return;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double t = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++)
            out[k] = v[0][k] + t * ac[k];
        return;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++)
            out[k] = v[1][k] + t * (v[2][k] - v[1][k]);
        return;
    }
    double den = 1.0 / (va + vb + vc), sv = vb * den, tw = vc * den;
    for (int k = 0; k < 3; k++)
        out[k] = v[0][k] + ab[k] * sv + ac[k] * tw;
}

/* Visit the triangles of the buckets overlapping the box [lo, hi]. */
#define FOR_TRIANGLES_IN(g, lo, hi, tvar)                                                     \
    int a_[3], z_[3];                                                                         \
    bucket_range((g), (lo), (hi), a_, z_);                                                    \
    for (int bk_ = a_[2]; bk_ <= z_[2]; bk_++)                                                \
        for (int bj_ = a_[1]; bj_ <= z_[1]; bj_++)                                            \
            for (int bi_ = a_[0]; bi_ <= z_[0]; bi_++)                                        \
                for (size_t q_ = (g)->start[(size_t)bi_ + (size_t)(g)->n[0] *                 \
                                                ((size_t)bj_ + (size_t)(g)->n[1] * bk_)],      \
                            e_ = (g)->start[(size_t)bi_ + (size_t)(g)->n[0] *                 \
                                                ((size_t)bj_ + (size_t)(g)->n[1] * bk_) + 1];  \
                     q_ < e_ && ((tvar) = (g)->tri[q_], 1); q_++)

/* Signed distance along axis `axis` from p to the nearest surface hit within
 * reach; 0 when the line misses. */
static int axis_hit(const pp_mesh *m, const buckets *g, const double p[3], int axis, double reach,
                    double *best)
{
    double d[3] = {0, 0, 0};
    d[axis] = 1.0;
    int have = 0;
    uint32_t t;
    *best = INFINITY;
    /* only the buckets along the segment */
    double lo[3] = {p[0], p[1], p[2]}, hi[3] = {p[0], p[1], p[2]};
    lo[axis] -= reach;
    hi[axis] += reach;
    FOR_TRIANGLES_IN(g, lo, hi, t)
    {
        double v[3][3], s;
        tri_points(m, t, v);
        if (ray_tri(p, d, v, &s) && fabs(s) <= reach && fabs(s) < fabs(*best)) {
            *best = s;
            have = 1;
        }
    }
    return have;
}

static int closest_within(const pp_mesh *m, const buckets *g, const double p[3], double reach,
                          double out[3])
{
    double best = reach * reach;
    int have = 0;
    uint32_t t;
    double lo[3] = {p[0] - reach, p[1] - reach, p[2] - reach},
           hi[3] = {p[0] + reach, p[1] + reach, p[2] + reach};
    FOR_TRIANGLES_IN(g, lo, hi, t)
    {
        double v[3][3], cp[3], r[3];
        tri_points(m, t, v);
        closest_on_tri(p, v, cp);
        sub3(cp, p, r);
        double d2 = dot3(r, r);
        if (d2 < best) {
            best = d2;
            memcpy(out, cp, sizeof cp);
            have = 1;
        }
    }
    return have;
}

/* Closest surface point within reach, looking near first (after the axis
 * moves the point is usually on or next to the surface). */
static int closest_point(const pp_mesh *m, const buckets *g, const double p[3], double reach,
                         double out[3])
{
    if (closest_within(m, g, p, 0.25 * reach, out))
        return 1;
    return closest_within(m, g, p, reach, out);
}

/* Target of a boundary vertex p whose staircase faces point along the axes
 * set in dir: first each of those coordinates moves to the surface along its
 * own axis (so a staircase corner offset by different amounts per axis lands
 * on the surface's corner, and a box is recovered exactly), then the result
 * goes to its closest surface point q, and the target is q moved back
 * towards p by `margin`. Only inward moves are made (p on the outer side of
 * q along dir): the staircase starts outside the skin (tet_cells.h) and a
 * vertex the skin has grown past stays where it is rather than pull the
 * boundary into the body. Returns 0 when there is nothing to do. */
static int snap_target(const pp_mesh *m, const buckets *g, const double p[3], const int8_t dir[3],
                       double reach, double margin, double out[3])
{
    double c[3] = {p[0], p[1], p[2]};
    for (int k = 0; k < 3; k++) {
        double s;
        if (dir[k] && axis_hit(m, g, p, k, reach, &s))
            c[k] = p[k] + s;
    }
    double q[3], u[3];
    if (!closest_point(m, g, c, reach, q))
        return 0;
    sub3(p, q, u);
    double len = sqrt(dot3(u, u));
    double along = u[0] * dir[0] + u[1] * dir[1] + u[2] * dir[2];
    if (!(len > margin))
        return 0; /* already within the margin */
    if (!(along > 0.0))
        return 0;
    double f = margin / len;
    for (int k = 0; k < 3; k++)
        out[k] = q[k] + f * u[k];
    return 1;
}

/* Shape quality of a tet with vertex `moved` at np: 6 sqrt(2) V / l_rms^3,
 * 1 for the regular tet, 0.66 for a Kuhn tet, <= 0 when flat or inverted. */
static double tet_shape(const float *P, const uint32_t *t, uint32_t moved, const double *np)
{
    double q[4][3];
    for (int c = 0; c < 4; c++)
        for (int k = 0; k < 3; k++)
            q[c][k] = t[c] == moved ? np[k] : (double)P[3 * (size_t)t[c] + k];
    double a[3], b[3], e[3], x[3];
    sub3(q[1], q[0], a);
    sub3(q[2], q[0], b);
    sub3(q[3], q[0], e);
    cross3(b, e, x);
    double vol = dot3(a, x) / 6.0;
    double l2 = 0.0;
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++) {
            double d[3];
            sub3(q[j], q[i], d);
            l2 += dot3(d, d);
        }
    double rms = sqrt(l2 / 6.0);
    return 6.0 * sqrt(2.0) * vol / (rms * rms * rms);
}

/* Try to move vertex v from its position towards np by f = 1, 1/2, 1/4;
 * a step is taken only when no incident tet falls below the shape bound.
 * Returns the fraction taken (0 when refused). */
static double try_move(pp_tetmesh *t, uint32_t v, const double np[3], const size_t *start,
                       const uint32_t *inc, const double *q0)
{
    double p[3] = {t->positions[3 * (size_t)v], t->positions[3 * (size_t)v + 1],
                   t->positions[3 * (size_t)v + 2]};
    for (double f = 1.0; f >= 0.25; f *= 0.5) {
        double x[3];
        for (int k = 0; k < 3; k++)
            x[k] = p[k] + f * (np[k] - p[k]);
        int ok = 1;
        for (size_t q = start[v]; q < start[v + 1] && ok; q++)
            ok = tet_shape(t->positions, t->tets + 4 * (size_t)inc[q], v, x) >=
                 fmin(PP_SNAP_MIN_SHAPE, q0[q]);
        if (!ok)
            continue;
        for (int k = 0; k < 3; k++)
            t->positions[3 * (size_t)v + k] = (float)x[k];
        return f;
    }
    return 0.0;
}

pose_status pp_tet_snap(pp_tetmesh *t, const pp_mesh *surface, const int8_t *dir, float reach,
                        float margin, size_t *moved)
{
    *moved = 0;
    if (!surface || surface->triangle_count == 0)
        return POSE_OK;
    size_t nv = t->vertex_count;
    size_t *start = calloc(nv + 1, sizeof *start);
    float *target = malloc((nv ? nv : 1) * 3 * sizeof *target);
    uint32_t *inc = NULL;
    double *q0 = NULL;
    buckets g = {0};
    pose_status s = POSE_ERR_OUT_OF_MEMORY;
    if (!start || !target)
        goto done;
    /* vertex -> incident tets, for the boundary vertices */
#define ON_BOUNDARY(v) (dir[3 * (size_t)(v)] | dir[3 * (size_t)(v) + 1] | dir[3 * (size_t)(v) + 2])
    for (size_t i = 0; i < 4 * t->tet_count; i++)
        if (ON_BOUNDARY(t->tets[i]))
            start[t->tets[i] + 1]++;
    for (size_t v = 0; v < nv; v++)
        start[v + 1] += start[v];
    inc = malloc((start[nv] ? start[nv] : 1) * sizeof *inc);
    q0 = malloc((start[nv] ? start[nv] : 1) * sizeof *q0);
    if (!inc || !q0)
        goto done;
    s = buckets_build(surface, 0.5 * reach, &g);
    if (s != POSE_OK)
        goto done;
    size_t *fill = start; /* advanced while filling, shifted back below */
    for (size_t i = 0; i < 4 * t->tet_count; i++)
        if (ON_BOUNDARY(t->tets[i]))
            inc[fill[t->tets[i]]++] = (uint32_t)(i / 4);
#undef ON_BOUNDARY
    memmove(start + 1, start, nv * sizeof *start);
    start[0] = 0;
    for (size_t v = 0; v < nv; v++)
        for (size_t q = start[v]; q < start[v + 1]; q++)
            q0[q] = tet_shape(t->positions, t->tets + 4 * (size_t)inc[q], UINT32_MAX, NULL);

    /* Targets from the staircase positions (NaN: done or none), then sweeps:
     * a move refused or cut short in one sweep often goes further in the
     * next, once its neighbours have moved. */
    size_t pending = 0;
    for (size_t v = 0; v < nv; v++) {
        double p[3] = {t->positions[3 * v], t->positions[3 * v + 1], t->positions[3 * v + 2]};
        double tg[3];
        target[3 * v] = NAN;
        if (start[v + 1] > start[v] && snap_target(surface, &g, p, dir + 3 * v, reach, margin, tg)) {
            for (int k = 0; k < 3; k++)
                target[3 * v + k] = (float)tg[k];
            pending++;
        }
    }
    for (int sweep = 0; sweep < PP_SNAP_SWEEPS && pending; sweep++)
        for (size_t v = 0; v < nv; v++) {
            if (isnan(target[3 * v]))
                continue;
            double np[3] = {target[3 * v], target[3 * v + 1], target[3 * v + 2]};
            if (try_move(t, (uint32_t)v, np, start, inc, q0) == 1.0) {
                target[3 * v] = NAN;
                pending--;
                (*moved)++;
            }
        }
done:
    free(g.start);
    free(g.tri);
    free(inc);
    free(q0);
    free(target);
    free(start);
    return s;
}
