/* SPDX-License-Identifier: Apache-2.0 */
#include "embed_geom.h"

#include <math.h>
#include <string.h>

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void sub3(const double a[3], const double b[3], double r[3])
{
    r[0] = a[0] - b[0];
    r[1] = a[1] - b[1];
    r[2] = a[2] - b[2];
}

/* Closest point by Voronoi regions of the triangle (Ericson, Real-Time
 * Collision Detection, 5.1.5): no square roots, exact on vertices/edges. */
double pp_point_triangle_dist2(const double p[3], const double a[3], const double b[3],
                               const double c[3], double q[3])
{
    double ab[3], ac[3], ap[3], r[3];
    sub3(b, a, ab);
    sub3(c, a, ac);
    sub3(p, a, ap);
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    double s, t; /* r = a + s ab + t ac */
    if (d1 <= 0 && d2 <= 0) {
        s = 0, t = 0;
    } else {
        double bp[3];
        sub3(p, b, bp);
        double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
        if (d3 >= 0 && d4 <= d3) {
            s = 1, t = 0;
        } else {
            double vc = d1 * d4 - d3 * d2;
            if (vc <= 0 && d1 >= 0 && d3 <= 0) {
                s = d1 / (d1 - d3), t = 0;
            } else {
                double cp[3];
                sub3(p, c, cp);
                double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
                if (d6 >= 0 && d5 <= d6) {
                    s = 0, t = 1;
                } else {
                    double vb = d5 * d2 - d1 * d6;
                    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
                        s = 0, t = d2 / (d2 - d6);
                    } else {
                        double va = d3 * d6 - d5 * d4;
                        if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
                            double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
                            s = 1 - w, t = w; /* on edge bc */
                        } else {
                            double den = va + vb + vc;
                            if (den == 0) { /* degenerate triangle: fall back to a vertex */
                                s = 0, t = 0;
                            } else {
                                s = vb / den, t = vc / den;
                            }
                        }
                    }
                }
            }
        }
    }
    for (int k = 0; k < 3; k++)
        r[k] = a[k] + s * ab[k] + t * ac[k];
    if (q)
        memcpy(q, r, sizeof r);
    double d[3];
    sub3(p, r, d);
    return dot3(d, d);
}

static double det3(const double u[3], const double v[3], const double w[3])
{
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

int pp_tet_barycentric(const double p[3], const double a[3], const double b[3], const double c[3],
                       const double d[3], double bary[4])
{
    double ab[3], ac[3], ad[3], ap[3];
    sub3(b, a, ab);
    sub3(c, a, ac);
    sub3(d, a, ad);
    sub3(p, a, ap);
    double vol = det3(ab, ac, ad);
    if (vol == 0.0 || !isfinite(vol)) {
        bary[0] = 1, bary[1] = bary[2] = bary[3] = 0;
        return 0;
    }
    /* Cramer's rule: each coordinate is a sub-volume over the whole. */
    bary[1] = det3(ap, ac, ad) / vol;
    bary[2] = det3(ab, ap, ad) / vol;
    bary[3] = det3(ab, ac, ap) / vol;
    bary[0] = 1.0 - bary[1] - bary[2] - bary[3];
    return 1;
}

double pp_point_tet_dist2(const double p[3], const double a[3], const double b[3],
                          const double c[3], const double d[3])
{
    double bary[4];
    if (pp_tet_barycentric(p, a, b, c, d, bary) && bary[0] >= 0 && bary[1] >= 0 && bary[2] >= 0 &&
        bary[3] >= 0)
        return 0.0;
    double best = pp_point_triangle_dist2(p, b, c, d, NULL);
    double x = pp_point_triangle_dist2(p, a, c, d, NULL);
    best = x < best ? x : best;
    x = pp_point_triangle_dist2(p, a, b, d, NULL);
    best = x < best ? x : best;
    x = pp_point_triangle_dist2(p, a, b, c, NULL);
    return x < best ? x : best;
}

void pp_sym3_eigen(const double m[3][3], double w[3], double v[3][3])
{
    double a[3][3];
    memcpy(a, m, sizeof a);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            v[i][j] = i == j;
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
        double scale = fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]);
        if (off <= 1e-15 * scale || off == 0.0)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (a[p][q] == 0.0)
                    continue;
                double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; k++) { /* A <- A J */
                    double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) { /* A <- J^T A */
                    double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) {
                    double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (a[order[j]][order[j]] > a[order[i]][order[i]]) {
                int tmp = order[i];
                order[i] = order[j];
                order[j] = tmp;
            }
    double vs[3][3];
    for (int c = 0; c < 3; c++) {
        w[c] = a[order[c]][order[c]];
        for (int r = 0; r < 3; r++)
            vs[r][c] = v[r][order[c]];
    }
    memcpy(v, vs, sizeof vs);
}
