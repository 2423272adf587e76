/* SPDX-License-Identifier: Apache-2.0
 *
 * Hole-tolerant inside test of a triangle mesh on a voxel grid.
 *
 * For each axis, every triangle is rasterized onto the voxel columns along
 * that axis; a column through the projected triangle records one crossing
 * (coordinate along the axis, sign of the normal's axis component). The
 * point-in-triangle test uses edge functions evaluated in a canonical vertex
 * order plus a top-left tie rule, so a column through a shared edge or vertex
 * of a closed mesh is counted exactly once. Walking a sorted column then gives
 * two winding numbers per voxel: from the low end (ray towards -axis) and from
 * the high end (+axis). Six rays vote; 3:3 ties (a hole's shadow) fall back to
 * the exact generalized winding number, sum of triangle solid angles / 4 pi.
 * Winding numbers are compared with 0 rather than 1 so that a mesh with
 * inward normals is still filled.
 */
#include "voxelize.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct column_hits {
    size_t *start;  /* columns + 1 offsets */
    float *t;       /* crossing coordinate along the axis, grid units */
    int8_t *s;      /* sign of the normal's axis component */
} column_hits;

/* Edge function of p against edge (a, b), evaluated with the lower vertex
 * index first so that the two triangles sharing an edge get exactly opposite
 * values. */
static double edge_fn(const double *pa, const double *pb, uint32_t ia, uint32_t ib, double px,
                      double py)
{
    if (ia > ib)
        return -edge_fn(pb, pa, ib, ia, px, py);
    return (pb[0] - pa[0]) * (py - pa[1]) - (pb[1] - pa[1]) * (px - pa[0]);
}

/* Top-left rule on a counter-clockwise edge direction d: exactly one of d and
 * -d is "owned", so a column on a shared edge belongs to one triangle. */
static int owns_edge(double dx, double dy)
{
    return dy > 0.0 || (dy == 0.0 && dx < 0.0);
}

typedef struct tri2 {
    double p[3][2];  /* projected, grid units */
    double h[3];     /* coordinate along the axis, grid units */
    uint32_t idx[3];
    double area;     /* edge_fn(p0, p1, p2) */
    int lo[2], hi[2];
} tri2;

/* Project triangle t for axis a; returns 0 when it covers no column. */
static int project(const pp_mesh *m, size_t t, int a, const double o[3], double inv_h, int nu,
                   int nv, tri2 *tr)
{
    int u = (a + 1) % 3, v = (a + 2) % 3;
    double mn[2] = {INFINITY, INFINITY}, mx[2] = {-INFINITY, -INFINITY};
    for (int c = 0; c < 3; c++) {
        uint32_t vi = m->triangles[3 * t + c];
        const float *p = m->positions + 3 * (size_t)vi;
        tr->idx[c] = vi;
        tr->p[c][0] = ((double)p[u] - o[u]) * inv_h;
        tr->p[c][1] = ((double)p[v] - o[v]) * inv_h;
        tr->h[c] = ((double)p[a] - o[a]) * inv_h;
        for (int k = 0; k < 2; k++) {
            mn[k] = fmin(mn[k], tr->p[c][k]);
            mx[k] = fmax(mx[k], tr->p[c][k]);
        }
    }
    tr->area = edge_fn(tr->p[0], tr->p[1], tr->idx[0], tr->idx[1], tr->p[2][0], tr->p[2][1]);
    if (tr->area == 0.0)
        return 0; /* edge-on: the neighbours own these columns */
    int lim[2] = {nu - 1, nv - 1};
    for (int k = 0; k < 2; k++) {
        double l = ceil(mn[k]), h = floor(mx[k]);
        if (h < 0.0 || l > lim[k])
            return 0;
        tr->lo[k] = l < 0.0 ? 0 : (int)l;
        tr->hi[k] = h > lim[k] ? lim[k] : (int)h;
        if (tr->lo[k] > tr->hi[k])
            return 0;
    }
    return 1;
}

/* Does column (x, y) cross the triangle? On success fills the crossing. */
static int cross(const tri2 *tr, double x, double y, float *t)
{
    double sg = tr->area > 0.0 ? 1.0 : -1.0;
    double e[3];
    for (int k = 0; k < 3; k++) {
        int i = (k + 1) % 3, j = (k + 2) % 3; /* edge opposite vertex k */
        e[k] = sg * edge_fn(tr->p[i], tr->p[j], tr->idx[i], tr->idx[j], x, y);
        if (e[k] < 0.0)
            return 0;
        if (e[k] == 0.0) {
            double dx = sg * (tr->p[j][0] - tr->p[i][0]), dy = sg * (tr->p[j][1] - tr->p[i][1]);
            if (!owns_edge(dx, dy))
                return 0;
        }
    }
    double sum = e[0] + e[1] + e[2];
    *t = (float)((e[0] * tr->h[0] + e[1] * tr->h[1] + e[2] * tr->h[2]) / sum);
    return 1;
}

static pose_status collect_axis(const pp_mesh *m, int a, const double o[3], double h,
                                const int n[3], column_hits *ch)
{
    int u = (a + 1) % 3, v = (a + 2) % 3;
    int nu = n[u], nv = n[v];
    size_t ncol = (size_t)nu * (size_t)nv;
    double inv_h = 1.0 / h;
    ch->start = calloc(ncol + 1, sizeof *ch->start);
    if (!ch->start)
        return POSE_ERR_OUT_OF_MEMORY;
    tri2 tr;
    float t;
    for (size_t i = 0; i < m->triangle_count; i++) {
        if (!project(m, i, a, o, inv_h, nu, nv, &tr))
            continue;
        for (int y = tr.lo[1]; y <= tr.hi[1]; y++)
            for (int x = tr.lo[0]; x <= tr.hi[0]; x++)
                if (cross(&tr, x, y, &t))
                    ch->start[(size_t)y * nu + x + 1]++;
    }
    for (size_t c = 0; c < ncol; c++)
        ch->start[c + 1] += ch->start[c];
    size_t total = ch->start[ncol];
    ch->t = malloc((total ? total : 1) * sizeof *ch->t);
    ch->s = malloc((total ? total : 1) * sizeof *ch->s);
    size_t *fill = malloc((ncol ? ncol : 1) * sizeof *fill);
    if (!ch->t || !ch->s || !fill) {
        free(fill);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    memcpy(fill, ch->start, ncol * sizeof *fill);
    for (size_t i = 0; i < m->triangle_count; i++) {
        if (!project(m, i, a, o, inv_h, nu, nv, &tr))
            continue;
        int8_t s = tr.area > 0.0 ? 1 : -1;
        for (int y = tr.lo[1]; y <= tr.hi[1]; y++)
            for (int x = tr.lo[0]; x <= tr.hi[0]; x++)
                if (cross(&tr, x, y, &t)) {
                    size_t k = fill[(size_t)y * nu + x]++;
                    ch->t[k] = t;
                    ch->s[k] = s;
                }
    }
    free(fill);
    return POSE_OK;
}

static void sort_column(float *t, int8_t *s, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        float kt = t[i];
        int8_t ks = s[i];
        size_t j = i;
        while (j > 0 && t[j - 1] > kt) {
            t[j] = t[j - 1];
            s[j] = s[j - 1];
            j--;
        }
        t[j] = kt;
        s[j] = ks;
    }
}

/* Add the two ray votes of every voxel of every column along axis a. */
static void vote_axis(int a, const int n[3], column_hits *ch, uint8_t *votes)
{
    int u = (a + 1) % 3, v = (a + 2) % 3;
    size_t stride[3] = {1, (size_t)n[0], (size_t)n[0] * (size_t)n[1]};
    for (int y = 0; y < n[v]; y++) {
        for (int x = 0; x < n[u]; x++) {
            size_t c = (size_t)y * n[u] + x;
            size_t b = ch->start[c], e = ch->start[c + 1];
            if (b == e)
                continue;
            float *t = ch->t + b;
            int8_t *s = ch->s + b;
            size_t cnt = e - b;
            sort_column(t, s, cnt);
            int total = 0;
            for (size_t i = 0; i < cnt; i++)
                total += s[i];
            size_t base = (size_t)x * stride[u] + (size_t)y * stride[v];
            size_t j = 0;
            int below = 0;
            for (int k = 0; k < n[a]; k++) {
                float fk = (float)k;
                while (j < cnt && t[j] < fk)
                    below += s[j++];
                int at = 0;
                for (size_t q = j; q < cnt && t[q] == fk; q++)
                    at += s[q];
                int w_low = -below, w_high = total - below - at;
                votes[base + (size_t)k * stride[a]] += (uint8_t)((w_low != 0) + (w_high != 0));
            }
        }
    }
}

/* Generalized winding number of mesh m at point p (van Oosterom-Strackee). */
static double winding_number(const pp_mesh *m, const double p[3])
{
    double sum = 0.0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        double r[3][3], l[3];
        for (int c = 0; c < 3; c++) {
            const float *q = m->positions + 3 * (size_t)m->triangles[3 * t + c];
            for (int k = 0; k < 3; k++)
                r[c][k] = q[k] - p[k];
            l[c] = sqrt(r[c][0] * r[c][0] + r[c][1] * r[c][1] + r[c][2] * r[c][2]);
        }
        double det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) -
                     r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                     r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
        double d01 = r[0][0] * r[1][0] + r[0][1] * r[1][1] + r[0][2] * r[1][2];
        double d02 = r[0][0] * r[2][0] + r[0][1] * r[2][1] + r[0][2] * r[2][2];
        double d12 = r[1][0] * r[2][0] + r[1][1] * r[2][1] + r[1][2] * r[2][2];
        double den = l[0] * l[1] * l[2] + d01 * l[2] + d02 * l[1] + d12 * l[0];
        sum += 2.0 * atan2(det, den);
    }
    return sum / (4.0 * 3.14159265358979323846);
}

pose_status pp_voxel_inside(const pp_mesh *m, const float origin[3], float spacing, int nx,
                            int ny, int nz, uint8_t *inside, size_t *ambiguous)
{
    if (ambiguous)
        *ambiguous = 0;
    if (!m || !origin || !inside || !(spacing > 0.0f) || nx <= 0 || ny <= 0 || nz <= 0)
        return POSE_ERR_INVALID_ARGUMENT;
    int n[3] = {nx, ny, nz};
    size_t count = (size_t)nx * (size_t)ny * (size_t)nz;
    double o[3] = {origin[0], origin[1], origin[2]};
    memset(inside, 0, count);
    /* inside doubles as the vote counter (0..6) until the final pass */
    for (int a = 0; a < 3; a++) {
        column_hits ch = {0};
        pose_status s = collect_axis(m, a, o, spacing, n, &ch);
        if (s == POSE_OK)
            vote_axis(a, n, &ch, inside);
        free(ch.start);
        free(ch.t);
        free(ch.s);
        if (s != POSE_OK)
            return s;
    }
    size_t ties = 0;
    for (size_t i = 0; i < count; i++)
        ties += inside[i] == 3;
    /* The exact fallback costs one pass over the triangles per tie; a mesh
     * that is mostly holes (an open sheet) could make that minutes, so past
     * a budget ties are taken as inside, which is what a hole in a closed
     * surface usually hides. */
    int exact = (double)ties * (double)m->triangle_count <= PP_VOXEL_WINDING_BUDGET;
    if (ambiguous)
        *ambiguous = ties;
    for (size_t i = 0; i < count; i++) {
        uint8_t v = inside[i];
        if (v == 3 && !exact) {
            inside[i] = 1;
        } else if (v == 3) {
            size_t x = i % (size_t)nx, y = (i / (size_t)nx) % (size_t)ny,
                   z = i / ((size_t)nx * (size_t)ny);
            double p[3] = {o[0] + (double)x * spacing, o[1] + (double)y * spacing,
                           o[2] + (double)z * spacing};
            inside[i] = fabs(winding_number(m, p)) >= 0.5;
        } else {
            inside[i] = v >= 4;
        }
    }
    return POSE_OK;
}
