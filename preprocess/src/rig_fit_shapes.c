/* SPDX-License-Identifier: Apache-2.0
 *
 * Least-squares spheres and circles, and matrix -> quaternion, for rigging.
 * Algebraic fits (Kasa) give a start that is exact for exact data but biased
 * for a partial arc; a few Gauss-Newton steps on the geometric distance
 * remove that bias. Points are centred on their mean first so that metre
 * offsets do not swamp millimetre curvature.
 */
#include "rig_fit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Solve the n x n system a x = b (n <= 4) by Gaussian elimination with
 * partial pivoting; 0 if singular relative to the matrix scale. */
static int solve_small(int n, double a[4][4], double b[4], double x[4])
{
    double scale = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            scale = fmax(scale, fabs(a[i][j]));
    if (!(scale > 0))
        return 0;
    for (int c = 0; c < n; c++) {
        int piv = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c]))
                piv = r;
        if (fabs(a[piv][c]) < 1e-13 * scale)
            return 0;
        if (piv != c) {
            for (int k = 0; k < n; k++) {
                double t = a[c][k];
                a[c][k] = a[piv][k];
                a[piv][k] = t;
            }
            double t = b[c];
            b[c] = b[piv];
            b[piv] = t;
        }
        for (int r = c + 1; r < n; r++) {
            double f = a[r][c] / a[c][c];
            for (int k = c; k < n; k++)
                a[r][k] -= f * a[c][k];
            b[r] -= f * b[c];
        }
    }
    for (int r = n - 1; r >= 0; r--) {
        double s = b[r];
        for (int k = r + 1; k < n; k++)
            s -= a[r][k] * x[k];
        x[r] = s / a[r][r];
    }
    return 1;
}

/* Fit in `dim` dimensions (2 or 3) to points already centred. */
static int fit_ball(const double *pts, size_t stride, size_t n, int dim, double c[3], double *r,
                    double *rms)
{
    if (n < (size_t)dim + 1)
        return 0;
    int m = dim + 1;
    double a[4][4] = {{0}}, b[4] = {0}, x[4] = {0};
    /* |p|^2 = 2 c.p + k, unknowns (c, k). */
    for (size_t i = 0; i < n; i++) {
        const double *p = pts + i * stride;
        double row[4], rhs = 0;
        for (int d = 0; d < dim; d++) {
            row[d] = 2 * p[d];
            rhs += p[d] * p[d];
        }
        row[dim] = 1;
        for (int u = 0; u < m; u++) {
            for (int v = 0; v < m; v++)
                a[u][v] += row[u] * row[v];
            b[u] += row[u] * rhs;
        }
    }
    if (!solve_small(m, a, b, x))
        return 0;
    double cc = 0;
    for (int d = 0; d < dim; d++) {
        c[d] = x[d];
        cc += x[d] * x[d];
    }
    if (!(x[dim] + cc > 0))
        return 0;
    double rad = sqrt(x[dim] + cc);
    /* Geometric refinement: residual |p - c| - r. */
    for (int it = 0; it < 30; it++) {
        double jtj[4][4] = {{0}}, jtr[4] = {0}, step[4] = {0};
        for (size_t i = 0; i < n; i++) {
            const double *p = pts + i * stride;
            double diff[3] = {0}, len = 0;
            for (int d = 0; d < dim; d++) {
                diff[d] = p[d] - c[d];
                len += diff[d] * diff[d];
            }
            len = sqrt(len);
            if (len < 1e-12)
                continue;
            double row[4];
            for (int d = 0; d < dim; d++)
                row[d] = -diff[d] / len;
            row[dim] = -1;
            double res = len - rad;
            for (int u = 0; u < m; u++) {
                for (int v = 0; v < m; v++)
                    jtj[u][v] += row[u] * row[v];
                jtr[u] -= row[u] * res;
            }
        }
        if (!solve_small(m, jtj, jtr, step))
            break;
        double moved = 0;
        for (int d = 0; d < dim; d++) {
            c[d] += step[d];
            moved += step[d] * step[d];
        }
        rad += step[dim];
        if (moved < 1e-18)
            break;
    }
    double ss = 0;
    for (size_t i = 0; i < n; i++) {
        const double *p = pts + i * stride;
        double len = 0;
        for (int d = 0; d < dim; d++)
            len += (p[d] - c[d]) * (p[d] - c[d]);
        double res = sqrt(len) - rad;
        ss += res * res;
    }
    *r = fabs(rad);
    *rms = sqrt(ss / (double)n);
    return isfinite(*r) && isfinite(c[0]) && isfinite(c[1]) && (dim < 3 || isfinite(c[2]));
}

int pp_fit_sphere(const double *pts, size_t n, double centre[3], double *radius, double *rms)
{
    double mean[3] = {0};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            mean[k] += pts[3 * i + k] / (double)n;
    double c[3] = {0}, tmp_rms = 0, r = 0;
    double *centred = malloc(n * 3 * sizeof(double));
    if (!centred)
        return 0;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            centred[3 * i + k] = pts[3 * i + k] - mean[k];
    int ok = fit_ball(centred, 3, n, 3, c, &r, &tmp_rms);
    free(centred);
    if (!ok)
        return 0;
    for (int k = 0; k < 3; k++)
        centre[k] = c[k] + mean[k];
    *radius = r;
    *rms = tmp_rms;
    return 1;
}

int pp_fit_circle(const double *pts, size_t n, const double axis[3], double centre[3],
                  double *radius, double *rms)
{
    if (n < 3)
        return 0;
    /* Orthonormal basis (u, v) of the plane normal to the axis. */
    double a[3] = {axis[0], axis[1], axis[2]};
    double pick[3] = {1, 0, 0};
    if (fabs(a[0]) > 0.8)
        pick[0] = 0, pick[1] = 1;
    double u[3] = {a[1] * pick[2] - a[2] * pick[1], a[2] * pick[0] - a[0] * pick[2],
                   a[0] * pick[1] - a[1] * pick[0]};
    double un = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int k = 0; k < 3; k++)
        u[k] /= un;
    double v[3] = {a[1] * u[2] - a[2] * u[1], a[2] * u[0] - a[0] * u[2], a[0] * u[1] - a[1] * u[0]};
    double mean[3] = {0};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            mean[k] += pts[3 * i + k] / (double)n;
    double *uv = malloc(n * 2 * sizeof(double));
    if (!uv)
        return 0;
    for (size_t i = 0; i < n; i++) {
        double d[3] = {pts[3 * i] - mean[0], pts[3 * i + 1] - mean[1], pts[3 * i + 2] - mean[2]};
        uv[2 * i] = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
        uv[2 * i + 1] = d[0] * v[0] + d[1] * v[1] + d[2] * v[2];
    }
    double c2[3] = {0}, r = 0, e = 0;
    int ok = fit_ball(uv, 2, n, 2, c2, &r, &e);
    free(uv);
    if (!ok)
        return 0;
    for (int k = 0; k < 3; k++)
        centre[k] = mean[k] + c2[0] * u[k] + c2[1] * v[k];
    *radius = r;
    *rms = e;
    return 1;
}

void pp_quat_from_matrix(const double m[3][3], float q[4])
{
    double tr = m[0][0] + m[1][1] + m[2][2], x, y, z, w;
    if (tr > 0) {
        double s = sqrt(tr + 1.0) * 2;
        w = 0.25 * s;
        x = (m[2][1] - m[1][2]) / s;
        y = (m[0][2] - m[2][0]) / s;
        z = (m[1][0] - m[0][1]) / s;
    } else if (m[0][0] > m[1][1] && m[0][0] > m[2][2]) {
        double s = sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2;
        w = (m[2][1] - m[1][2]) / s;
        x = 0.25 * s;
        y = (m[0][1] + m[1][0]) / s;
        z = (m[0][2] + m[2][0]) / s;
    } else if (m[1][1] > m[2][2]) {
        double s = sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2;
        w = (m[0][2] - m[2][0]) / s;
        x = (m[0][1] + m[1][0]) / s;
        y = 0.25 * s;
        z = (m[1][2] + m[2][1]) / s;
    } else {
        double s = sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2;
        w = (m[1][0] - m[0][1]) / s;
        x = (m[0][2] + m[2][0]) / s;
        y = (m[1][2] + m[2][1]) / s;
        z = 0.25 * s;
    }
    double n = sqrt(x * x + y * y + z * z + w * w);
    if (w < 0)
        n = -n; /* canonical sign: w >= 0 */
    q[0] = (float)(x / n);
    q[1] = (float)(y / n);
    q[2] = (float)(z / n);
    q[3] = (float)(w / n);
}
