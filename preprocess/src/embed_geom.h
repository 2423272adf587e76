/* SPDX-License-Identifier: Apache-2.0
 *
 * Small exact geometry used by rigging and mapping: closest point on a
 * triangle, barycentric coordinates in a tet, point-to-tet distance, and a
 * 3x3 symmetric eigen-solver for principal directions. Doubles throughout:
 * these run once per vertex offline and must not lose millimetres.
 */
#ifndef POSE_PP_EMBED_GEOM_H
#define POSE_PP_EMBED_GEOM_H

/** Squared distance from p to triangle (a, b, c); closest point into q (may be NULL). */
double pp_point_triangle_dist2(const double p[3], const double a[3], const double b[3],
                               const double c[3], double q[3]);

/**
 * Barycentric coordinates of p in tet (a, b, c, d), summing to 1; all in
 * [0, 1] when p is inside. Returns 0 for a degenerate (zero-volume) tet.
 */
int pp_tet_barycentric(const double p[3], const double a[3], const double b[3], const double c[3],
                       const double d[3], double bary[4]);

/** Squared distance from p to the solid tet (0 inside). */
double pp_point_tet_dist2(const double p[3], const double a[3], const double b[3],
                          const double c[3], const double d[3]);

/**
 * Eigen-decomposition of a symmetric 3x3 matrix (Jacobi rotations):
 * eigenvalues descending in w, unit eigenvectors as the columns of v
 * (v[row][col]).
 */
void pp_sym3_eigen(const double m[3][3], double w[3], double v[3][3]);

#endif /* POSE_PP_EMBED_GEOM_H */
