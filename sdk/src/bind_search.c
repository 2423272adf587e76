/* SPDX-License-Identifier: Apache-2.0 */
/* k nearest tets by centroid distance over a uniform grid (bind_search.h). */
#include "bind_search.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "rig_internal.h"

/* Most grid cells: 64 MB of cell starts at most, whatever the mesh. */
#define MAX_CELLS (1u << 24)

typedef struct grid {
    double lo[3], cell;
    int n[3];
    uint32_t *start;  /* n0*n1*n2 + 1 */
    uint32_t *tets;   /* tets binned by centroid, cell after cell */
    float *centroid;  /* 3 per entry, beside tets: the search reads no tet vertex */
} grid;

static void tet_centroid(const pose_rig *rig, size_t t, double c[3])
{
    const uint32_t *v = rig->tets + 4 * t;
    for (int d = 0; d < 3; d++)
        c[d] = 0.25 * ((double)rig->tet_positions[3 * (size_t)v[0] + (size_t)d] +
                       rig->tet_positions[3 * (size_t)v[1] + (size_t)d] +
                       rig->tet_positions[3 * (size_t)v[2] + (size_t)d] +
                       rig->tet_positions[3 * (size_t)v[3] + (size_t)d]);
}

static int cell_of(const grid *g, double x, int d)
{
    double f = floor((x - g->lo[d]) / g->cell);
    return f < 0.0 ? 0 : f >= g->n[d] ? g->n[d] - 1 : (int)f;
}

static size_t cell_index(const grid *g, int x, int y, int z)
{
    return ((size_t)z * (size_t)g->n[1] + (size_t)y) * (size_t)g->n[0] + (size_t)x;
}

/* Bin every tet's centroid into a uniform grid (counting sort); cells hold
 * about two tets each over the mesh's bounding box. */
static pose_status grid_build(const pose_rig *rig, const pose_allocator *a, grid *g)
{
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (size_t v = 0; v < rig->tet_vertex_count; v++)
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], rig->tet_positions[3 * v + (size_t)d]);
            hi[d] = fmax(hi[d], rig->tet_positions[3 * v + (size_t)d]);
        }
    double ext[3], vol = 1.0, big = 0.0;
    for (int d = 0; d < 3; d++) {
        ext[d] = hi[d] - lo[d];
        big = fmax(big, ext[d]);
    }
    for (int d = 0; d < 3; d++)
        vol *= fmax(ext[d], 1e-3 * big);
    double cell = cbrt(2.0 * vol / (double)rig->tet_count);
    if (!(cell > 0.0))
        cell = 1.0;
    for (;;) {
        double cells = 1.0;
        for (int d = 0; d < 3; d++)
            cells *= floor(ext[d] / cell) + 1.0;
        if (cells <= MAX_CELLS)
            break;
        cell *= 1.25;
    }
    g->cell = cell;
    for (int d = 0; d < 3; d++) {
        g->lo[d] = lo[d];
        g->n[d] = (int)floor(ext[d] / cell) + 1;
    }
    const size_t ncell = (size_t)g->n[0] * (size_t)g->n[1] * (size_t)g->n[2];
    g->start = pose__calloc(a, (ncell + 1) * sizeof(uint32_t), POSE__ALIGN);
    uint32_t *cell_of_tet = pose__alloc(a, (rig->tet_count + 1) * sizeof(uint32_t), POSE__ALIGN);
    g->tets = pose__alloc(a, (rig->tet_count + 1) * sizeof(uint32_t), POSE__ALIGN);
    g->centroid = pose__alloc(a, (3 * rig->tet_count + 1) * sizeof(float), POSE__ALIGN);
    if (!g->start || !cell_of_tet || !g->tets || !g->centroid) {
        pose__free(a, cell_of_tet);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY,
                          "binding: out of memory for a grid of %zu cells and %zu tets", ncell,
                          rig->tet_count);
    }
    for (size_t t = 0; t < rig->tet_count; t++) {
        double c[3];
        tet_centroid(rig, t, c);
        size_t at = cell_index(g, cell_of(g, c[0], 0), cell_of(g, c[1], 1), cell_of(g, c[2], 2));
        cell_of_tet[t] = (uint32_t)at;
        g->start[at + 1]++;
    }
    for (size_t c = 0; c < ncell; c++)
        g->start[c + 1] += g->start[c];
    for (size_t t = 0; t < rig->tet_count; t++) {
        uint32_t at = g->start[cell_of_tet[t]]++;
        double c[3];
        tet_centroid(rig, t, c);
        g->tets[at] = (uint32_t)t;
        for (int d = 0; d < 3; d++)
            g->centroid[3 * (size_t)at + (size_t)d] = (float)c[d];
    }
    /* the fill advanced every start by its count: shift back */
    memmove(g->start + 1, g->start, ncell * sizeof(uint32_t));
    g->start[0] = 0;
    pose__free(a, cell_of_tet);
    return POSE_OK;
}

/* Closest point to p on triangle (a, b, c) (Ericson, Real-Time Collision
 * Detection, 5.1.5). */
static void closest_on_triangle(const double p[3], const double a[3], const double b[3],
                                const double c[3], double out[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int d = 0; d < 3; d++) {
        ab[d] = b[d] - a[d]; ac[d] = c[d] - a[d]; ap[d] = p[d] - a[d];
        bp[d] = p[d] - b[d]; cp[d] = p[d] - c[d];
    }
#define DOT(u, v) ((u)[0] * (v)[0] + (u)[1] * (v)[1] + (u)[2] * (v)[2])
    double d1 = DOT(ab, ap), d2 = DOT(ac, ap), d3 = DOT(ab, bp), d4 = DOT(ac, bp);
    double d5 = DOT(ab, cp), d6 = DOT(ac, cp);
#undef DOT
    double s = 0.0, t = 0.0; /* out = a + s ab + t ac */
    if (d1 <= 0.0 && d2 <= 0.0) {
    } else if (d3 >= 0.0 && d4 <= d3) {
        s = 1.0;
    } else if (d6 >= 0.0 && d5 <= d6) {
        t = 1.0;
    } else {
        double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
            s = d1 / (d1 - d3);
        } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
            t = d2 / (d2 - d6);
        } else if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
            t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            s = 1.0 - t;
        } else {
            double den = 1.0 / (va + vb + vc);
            s = vb * den;
            t = vc * den;
        }
    }
    for (int d = 0; d < 3; d++)
        out[d] = a[d] + s * ab[d] + t * ac[d];
}

/* Distance from p to tet t and the tet's point nearest to p (foot); -1 for
 * a tet of (near) zero volume. */
static double tet_distance(const pose_rig *rig, size_t t, const double p[3], double foot[3])
{
    const uint32_t *c = rig->tets + 4 * t;
    double v[4][3], e[3][3];
    for (int k = 0; k < 4; k++)
        for (int d = 0; d < 3; d++)
            v[k][d] = rig->tet_positions[3 * (size_t)c[k] + (size_t)d];
    double scale = 0.0;
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 3; d++) {
            e[k][d] = v[k + 1][d] - v[0][d];
            scale = fmax(scale, fabs(e[k][d]));
        }
    /* rows of D^-1 = cross products of edge pairs / det */
    double inv[3][3];
    for (int k = 0; k < 3; k++) {
        const double *u = e[(k + 1) % 3], *w = e[(k + 2) % 3];
        inv[k][0] = u[1] * w[2] - u[2] * w[1];
        inv[k][1] = u[2] * w[0] - u[0] * w[2];
        inv[k][2] = u[0] * w[1] - u[1] * w[0];
    }
    double det = e[0][0] * inv[0][0] + e[0][1] * inv[0][1] + e[0][2] * inv[0][2];
    if (!(fabs(det) > 1e-9 * scale * scale * scale))
        return -1.0;
    double q[3] = {p[0] - v[0][0], p[1] - v[0][1], p[2] - v[0][2]}, b[3];
    for (int k = 0; k < 3; k++)
        b[k] = (inv[k][0] * q[0] + inv[k][1] * q[1] + inv[k][2] * q[2]) / det;
    memcpy(foot, p, 3 * sizeof(double));
    if (b[0] < 0.0 || b[1] < 0.0 || b[2] < 0.0 || b[0] + b[1] + b[2] > 1.0) {
        /* outside: the nearest of the four faces */
        static const int face[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
        double best = DBL_MAX;
        for (int f = 0; f < 4; f++) {
            double x[3];
            closest_on_triangle(p, v[face[f][0]], v[face[f][1]], v[face[f][2]], x);
            double d2 = (x[0] - p[0]) * (x[0] - p[0]) + (x[1] - p[1]) * (x[1] - p[1]) +
                        (x[2] - p[2]) * (x[2] - p[2]);
            if (d2 < best) {
                best = d2;
                memcpy(foot, x, 3 * sizeof(double));
            }
        }
        return sqrt(best);
    }
    return 0.0;
}

/* Insert (t, dist) into the sorted list h[0..*n) of at most k. */
static void offer(pose__bind_hit *h, unsigned *n, unsigned k, uint32_t t, float dist)
{
    unsigned at = *n;
    while (at > 0 && (h[at - 1].distance > dist || (h[at - 1].distance == dist && h[at - 1].tet > t)))
        at--;
    if (at >= k)
        return;
    unsigned last = *n < k ? *n : k - 1;
    memmove(h + at + 1, h + at, (last - at) * sizeof *h);
    h[at] = (pose__bind_hit){.tet = t, .distance = dist};
    if (*n < k)
        (*n)++;
}

static void visit_cell(const grid *g, size_t c, const double p[3], pose__bind_hit *h, unsigned *n,
                       unsigned k)
{
    for (uint32_t i = g->start[c]; i < g->start[c + 1]; i++) {
        const float *x = g->centroid + 3 * (size_t)i;
        double dx = x[0] - p[0], dy = x[1] - p[1], dz = x[2] - p[2];
        float dist = (float)sqrt(dx * dx + dy * dy + dz * dz);
        if (*n < k || dist <= h[k - 1].distance)
            offer(h, n, k, g->tets[i], dist);
    }
}

/* Rings of cells at Chebyshev distance R around (cx, cy, cz), clipped to the
 * grid: after ring R every centroid nearer than R cells has been seen. */
static void search_point(const grid *g, const double p[3], unsigned k, pose__bind_hit *h,
                         unsigned *n)
{
    const int cx = cell_of(g, p[0], 0), cy = cell_of(g, p[1], 1), cz = cell_of(g, p[2], 2);
    const int rmax = g->n[0] + g->n[1] + g->n[2];
    *n = 0;
    for (int R = 0; R <= rmax; R++) {
        for (int z = cz - R; z <= cz + R; z++) {
            if (z < 0 || z >= g->n[2])
                continue;
            for (int y = cy - R; y <= cy + R; y++) {
                if (y < 0 || y >= g->n[1])
                    continue;
                const int shell = z == cz - R || z == cz + R || y == cy - R || y == cy + R;
                for (int x = cx - R; x <= cx + R; x += shell ? 1 : 2 * R) {
                    if (x >= 0 && x < g->n[0])
                        visit_cell(g, cell_index(g, x, y, z), p, h, n, k);
                    if (R == 0)
                        break;
                }
            }
        }
        if (*n == k && (double)h[k - 1].distance < (double)R * g->cell)
            return;
    }
}

pose_status pose__bind_nearest_tets(const pose_rig *rig, const float *xyz, size_t count,
                                    unsigned k, const pose_allocator *a, pose__bind_hit *hits,
                                    unsigned *found)
{
    grid g = {0};
    pose_status s = grid_build(rig, a, &g);
    if (s == POSE_OK)
        for (size_t i = 0; i < count; i++) {
            const double p[3] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
            pose__bind_hit *h = hits + (size_t)k * i;
            search_point(&g, p, k, h, &found[i]);
            /* the exact distance and foot of the k found only; tets of
             * (near) zero volume have no frame and drop out */
            unsigned kept = 0;
            for (unsigned j = 0; j < found[i]; j++) {
                h[kept] = h[j];
                h[kept].gap = tet_distance(rig, h[j].tet, p, h[kept].foot);
                kept += h[kept].gap >= 0.0;
            }
            found[i] = kept;
        }
    pose__free(a, g.start);
    pose__free(a, g.tets);
    pose__free(a, g.centroid);
    return s;
}
