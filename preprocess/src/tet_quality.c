/* SPDX-License-Identifier: Apache-2.0
 *
 * Quality figures of a tet mesh: dihedral angles from the face normals,
 * radius-edge ratio from the circumcentre formula, signed volumes.
 */
#include "tetmesh.h"

#include <math.h>
#include <string.h>

static void corners(const pp_tetmesh *t, size_t i, double p[4][3])
{
    for (int c = 0; c < 4; c++)
        for (int k = 0; k < 3; k++)
            p[c][k] = t->positions[3 * (size_t)t->tets[4 * i + c] + k];
}

static void sub(const double *a, const double *b, double *r)
{
    for (int k = 0; k < 3; k++)
        r[k] = a[k] - b[k];
}
static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static void cross(const double *a, const double *b, double *r)
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}

double pp_tet_volume(const pp_tetmesh *t, size_t i)
{
    double p[4][3], a[3], b[3], c[3], x[3];
    corners(t, i, p);
    sub(p[1], p[0], a);
    sub(p[2], p[0], b);
    sub(p[3], p[0], c);
    cross(b, c, x);
    return dot(a, x) / 6.0;
}

void pp_tet_quality_measure(const pp_tetmesh *t, pp_tet_quality *q)
{
    memset(q, 0, sizeof *q);
    q->vertex_count = t->vertex_count;
    q->tet_count = t->tet_count;
    if (t->tet_count == 0)
        return;
    const double rad2deg = 180.0 / 3.14159265358979323846;
    q->min_dihedral_deg = 180.0;
    q->min_volume = INFINITY;
    /* faces opposite each vertex, listed so the normal points outwards for
     * a positive tet */
    static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    for (size_t i = 0; i < t->tet_count; i++) {
        double p[4][3];
        corners(t, i, p);
        double a[3], b[3], c[3], x[3];
        sub(p[1], p[0], a);
        sub(p[2], p[0], b);
        sub(p[3], p[0], c);
        cross(b, c, x);
        double vol = dot(a, x) / 6.0;
        q->total_volume += vol;
        if (vol < q->min_volume)
            q->min_volume = vol;
        if (vol <= 0.0) {
            q->inverted_count++;
            continue;
        }
        double n[4][3];
        for (int f = 0; f < 4; f++) {
            double u[3], w[3];
            sub(p[face[f][1]], p[face[f][0]], u);
            sub(p[face[f][2]], p[face[f][0]], w);
            cross(u, w, n[f]);
            double l = sqrt(dot(n[f], n[f]));
            for (int k = 0; k < 3; k++)
                n[f][k] /= l;
        }
        for (int f = 0; f < 4; f++)
            for (int g = f + 1; g < 4; g++) {
                double cs = -dot(n[f], n[g]);
                cs = cs > 1.0 ? 1.0 : cs < -1.0 ? -1.0 : cs;
                double ang = acos(cs) * rad2deg;
                if (ang < q->min_dihedral_deg)
                    q->min_dihedral_deg = ang;
                if (ang > q->max_dihedral_deg)
                    q->max_dihedral_deg = ang;
            }
        /* circumcentre offset: (|a|^2 b x c + |b|^2 c x a + |c|^2 a x b) / (12 V) */
        double bc[3], ca[3], ab[3], r[3];
        cross(b, c, bc);
        cross(c, a, ca);
        cross(a, b, ab);
        double la = dot(a, a), lb = dot(b, b), lc = dot(c, c);
        for (int k = 0; k < 3; k++)
            r[k] = (la * bc[k] + lb * ca[k] + lc * ab[k]) / (12.0 * vol);
        double radius = sqrt(dot(r, r));
        double shortest = fmin(la, fmin(lb, lc));
        double e[3];
        sub(p[2], p[1], e);
        shortest = fmin(shortest, dot(e, e));
        sub(p[3], p[1], e);
        shortest = fmin(shortest, dot(e, e));
        sub(p[3], p[2], e);
        shortest = fmin(shortest, dot(e, e));
        double re = radius / sqrt(shortest);
        if (re > q->max_radius_edge)
            q->max_radius_edge = re;
    }
}
