/* SPDX-License-Identifier: Apache-2.0 */
/* The tests' reference distance from a point to a triangle (Ericson, Real-
 * Time Collision Detection 5.1.5), in double: written apart from the
 * library's own searches (sdk/src/bind_search.c, runtime/rt_bvh_nearest.c),
 * which the binding and contact tests check against it. */
#ifndef POSE_TEST_TRI_DISTANCE_H
#define POSE_TEST_TRI_DISTANCE_H

#include <math.h>

static inline double tri_distance(const float *p, const float *a, const float *b, const float *c)
{
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int d = 0; d < 3; d++) {
        ab[d] = (double)b[d] - a[d]; ac[d] = (double)c[d] - a[d]; ap[d] = (double)p[d] - a[d];
        bp[d] = (double)p[d] - b[d]; cp[d] = (double)p[d] - c[d];
    }
#define DOT(u, v) ((u)[0] * (v)[0] + (u)[1] * (v)[1] + (u)[2] * (v)[2])
    double d1 = DOT(ab, ap), d2 = DOT(ac, ap), d3 = DOT(ab, bp), d4 = DOT(ac, bp);
    double d5 = DOT(ab, cp), d6 = DOT(ac, cp);
#undef DOT
    double s = 0.0, t = 0.0;
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
    double e2 = 0.0;
    for (int d = 0; d < 3; d++) {
        double x = ap[d] - s * ab[d] - t * ac[d];
        e2 += x * x;
    }
    return sqrt(e2);
}

#endif /* POSE_TEST_TRI_DISTANCE_H */
