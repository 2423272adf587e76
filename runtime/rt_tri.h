/* SPDX-License-Identifier: Apache-2.0 */
/* Exact-enough triangle predicates for collision detection (rt_bvh.c and the
 * tests' brute-force counts share them, so a broad phase is checked against
 * the same narrow phase). Coordinates are floats; every predicate works in
 * double, where the differences of two floats are exact and the products
 * close to it. Degenerate contacts (a vertex exactly on a face, coplanar
 * overlap) count as no intersection: they have measure zero for posed
 * meshes and the tests count them the same way. */
#ifndef POSE_RT_TRI_H
#define POSE_RT_TRI_H

#include <stdint.h>

/* Sign of the volume of (a, b, c, d): > 0 when d lies on the side of the
 * plane abc that its normal (b - a) x (c - a) points to. */
static inline double pose__orient3(const float *a, const float *b, const float *c, const float *d)
{
    const double ux = (double)b[0] - a[0], uy = (double)b[1] - a[1], uz = (double)b[2] - a[2];
    const double vx = (double)c[0] - a[0], vy = (double)c[1] - a[1], vz = (double)c[2] - a[2];
    const double wx = (double)d[0] - a[0], wy = (double)d[1] - a[1], wz = (double)d[2] - a[2];
    return wx * (uy * vz - uz * vy) + wy * (uz * vx - ux * vz) + wz * (ux * vy - uy * vx);
}

/* Segment pq crosses the interior of triangle abc (strictly). */
static inline int pose__segment_crosses_tri(const float *p, const float *q, const float *a,
                                            const float *b, const float *c)
{
    const double sp = pose__orient3(a, b, c, p), sq = pose__orient3(a, b, c, q);
    if (!((sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0)))
        return 0;
    /* The line pq passes inside abc when it sees the three edges turning
     * the same way. */
    const double e0 = pose__orient3(p, q, a, b), e1 = pose__orient3(p, q, b, c),
                 e2 = pose__orient3(p, q, c, a);
    return (e0 > 0.0 && e1 > 0.0 && e2 > 0.0) || (e0 < 0.0 && e1 < 0.0 && e2 < 0.0);
}

/* Two triangles (vertex pointers a[3], b[3]) intersect: one's edge crosses
 * the other (for non-coplanar triangles that is every intersection). */
static inline int pose__tri_tri_intersect(const float *const a[3], const float *const b[3])
{
    /* The plane of each triangle must separate the other's vertices. */
    double s[3];
    for (int k = 0; k < 3; k++)
        s[k] = pose__orient3(a[0], a[1], a[2], b[k]);
    if ((s[0] > 0.0 && s[1] > 0.0 && s[2] > 0.0) || (s[0] < 0.0 && s[1] < 0.0 && s[2] < 0.0))
        return 0;
    for (int k = 0; k < 3; k++)
        s[k] = pose__orient3(b[0], b[1], b[2], a[k]);
    if ((s[0] > 0.0 && s[1] > 0.0 && s[2] > 0.0) || (s[0] < 0.0 && s[1] < 0.0 && s[2] < 0.0))
        return 0;
    for (int k = 0; k < 3; k++)
        if (pose__segment_crosses_tri(a[k], a[(k + 1) % 3], b[0], b[1], b[2]) ||
            pose__segment_crosses_tri(b[k], b[(k + 1) % 3], a[0], a[1], a[2]))
            return 1;
    return 0;
}

/* The ray from p along +x crosses triangle abc: +1 where the triangle faces
 * along the ray (its normal's x > 0: the ray leaves a closed outward mesh),
 * -1 where it faces against it (enters), 0 when it misses. Summed over a
 * closed, outward oriented mesh this is the winding number of p (1 inside,
 * 0 outside). Along x because a body standing in z is thinnest that way:
 * rays cross the fewest nodes of a tree. */
static inline int pose__ray_x_crossing(const float *p, const float *a, const float *b, const float *c)
{
    /* Edge functions in the yz plane ((y, z) as a right-handed pair with x). */
    const double e0 = ((double)b[1] - a[1]) * ((double)p[2] - a[2]) - ((double)b[2] - a[2]) * ((double)p[1] - a[1]);
    const double e1 = ((double)c[1] - b[1]) * ((double)p[2] - b[2]) - ((double)c[2] - b[2]) * ((double)p[1] - b[1]);
    const double e2 = ((double)a[1] - c[1]) * ((double)p[2] - c[2]) - ((double)a[2] - c[2]) * ((double)p[1] - c[1]);
    if (!((e0 > 0.0 && e1 > 0.0 && e2 > 0.0) || (e0 < 0.0 && e1 < 0.0 && e2 < 0.0)))
        return 0;
    const double area = e0 + e1 + e2; /* twice the signed yz area: the normal's x */
    const double x = (e1 * a[0] + e2 * b[0] + e0 * c[0]) / area;
    if (!(x > p[0]))
        return 0;
    return area > 0.0 ? 1 : -1;
}

/* As pose__ray_x_crossing for a ray from p along any direction d: +1 where
 * the triangle faces along the ray, -1 against it, 0 when it misses. */
static inline int pose__ray_crossing(const float *p, const float *d, const float *a, const float *b,
                                     const float *c)
{
    const double ax = (double)a[0] - p[0], ay = (double)a[1] - p[1], az = (double)a[2] - p[2];
    const double bx = (double)b[0] - p[0], by = (double)b[1] - p[1], bz = (double)b[2] - p[2];
    const double cx = (double)c[0] - p[0], cy = (double)c[1] - p[1], cz = (double)c[2] - p[2];
    /* The line p + s d passes inside abc: d sees the three edges turn one way. */
    const double e0 = d[0] * (ay * bz - az * by) + d[1] * (az * bx - ax * bz) + d[2] * (ax * by - ay * bx);
    const double e1 = d[0] * (by * cz - bz * cy) + d[1] * (bz * cx - bx * cz) + d[2] * (bx * cy - by * cx);
    const double e2 = d[0] * (cy * az - cz * ay) + d[1] * (cz * ax - cx * az) + d[2] * (cx * ay - cy * ax);
    if (!((e0 > 0.0 && e1 > 0.0 && e2 > 0.0) || (e0 < 0.0 && e1 < 0.0 && e2 < 0.0)))
        return 0;
    /* And meets the plane ahead of p (s > 0): p behind it as seen along d. */
    const double sp = pose__orient3(a, b, c, p);
    const double nd = e0 + e1 + e2; /* d . (normal), the sign that matters */
    if (!((nd > 0.0 && sp < 0.0) || (nd < 0.0 && sp > 0.0)))
        return 0;
    return nd > 0.0 ? 1 : -1;
}

/* Triangles (index triples) share a vertex. */
static inline int pose__tris_share_vertex(const uint32_t *s, const uint32_t *t)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (s[i] == t[j])
                return 1;
    return 0;
}

#endif /* POSE_RT_TRI_H */
