/* SPDX-License-Identifier: Apache-2.0 */
#include "labels_body.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

size_t pp_mask_largest_component(uint8_t *mask, int nx, int ny, int nz)
{
    size_t n = (size_t)nx * ny * nz;
    int32_t *comp = malloc(n * sizeof *comp);
    size_t *queue = malloc(n * sizeof *queue);
    if (!comp || !queue) {
        free(comp), free(queue);
        return (size_t)-1;
    }
    for (size_t v = 0; v < n; v++)
        comp[v] = -1;
    int32_t ncomp = 0, best = -1;
    size_t best_size = 0, total = 0;
    const long step[6] = {1, -1, nx, -(long)nx, (long)nx * ny, -(long)nx * ny};
    for (size_t s = 0; s < n; s++) {
        if (!mask[s] || comp[s] >= 0)
            continue;
        size_t head = 0, tail = 0;
        queue[tail++] = s;
        comp[s] = ncomp;
        while (head < tail) {
            size_t v = queue[head++];
            int i = (int)(v % (size_t)nx), j = (int)(v / (size_t)nx % (size_t)ny),
                k = (int)(v / ((size_t)nx * ny));
            const int ok[6] = {i + 1 < nx, i > 0, j + 1 < ny, j > 0, k + 1 < nz, k > 0};
            for (int d = 0; d < 6; d++) {
                if (!ok[d])
                    continue;
                size_t w = (size_t)((long)v + step[d]);
                if (mask[w] && comp[w] < 0) {
                    comp[w] = ncomp;
                    queue[tail++] = w;
                }
            }
        }
        total += tail;
        if (tail > best_size)
            best_size = tail, best = ncomp;
        ncomp++;
    }
    for (size_t v = 0; v < n; v++)
        if (mask[v] && comp[v] != best)
            mask[v] = 0;
    free(comp), free(queue);
    return total - best_size;
}

size_t pp_mask_fill_slices(uint8_t *mask, int nx, int ny, int nz)
{
    size_t plane = (size_t)nx * ny, filled = 0;
    uint8_t *outside = malloc(plane);
    size_t *queue = malloc(plane * sizeof *queue);
    if (!outside || !queue) {
        free(outside), free(queue);
        return (size_t)-1;
    }
    for (int k = 0; k < nz; k++) {
        uint8_t *m = mask + (size_t)k * plane;
        memset(outside, 0, plane);
        size_t head = 0, tail = 0;
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++)
                if ((i == 0 || j == 0 || i == nx - 1 || j == ny - 1) && !m[(size_t)j * nx + i]) {
                    outside[(size_t)j * nx + i] = 1;
                    queue[tail++] = (size_t)j * nx + i;
                }
        while (head < tail) {
            size_t v = queue[head++];
            int i = (int)(v % (size_t)nx), j = (int)(v / (size_t)nx);
            const int ni[4] = {i + 1, i - 1, i, i}, nj[4] = {j, j, j + 1, j - 1};
            for (int d = 0; d < 4; d++) {
                if (ni[d] < 0 || nj[d] < 0 || ni[d] >= nx || nj[d] >= ny)
                    continue;
                size_t w = (size_t)nj[d] * nx + ni[d];
                if (!m[w] && !outside[w]) {
                    outside[w] = 1;
                    queue[tail++] = w;
                }
            }
        }
        for (size_t v = 0; v < plane; v++)
            if (!m[v] && !outside[v]) {
                m[v] = 1;
                filled++;
            }
    }
    free(outside), free(queue);
    return filled;
}

/* Solve the 4x4 system A x = b (Gaussian elimination, partial pivoting). */
static int solve4(double A[4][4], double b[4], double x[4])
{
    for (int c = 0; c < 4; c++) {
        int p = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(A[r][c]) > fabs(A[p][c]))
                p = r;
        if (fabs(A[p][c]) < 1e-12)
            return -1;
        for (int k = 0; k < 4; k++) {
            double t = A[c][k];
            A[c][k] = A[p][k], A[p][k] = t;
        }
        double t = b[c];
        b[c] = b[p], b[p] = t;
        for (int r = c + 1; r < 4; r++) {
            double f = A[r][c] / A[c][c];
            for (int k = c; k < 4; k++)
                A[r][k] -= f * A[c][k];
            b[r] -= f * b[c];
        }
    }
    for (int r = 3; r >= 0; r--) {
        double s = b[r];
        for (int k = r + 1; k < 4; k++)
            s -= A[r][k] * x[k];
        x[r] = s / A[r][r];
    }
    return 0;
}

size_t pp_fit_contact_sphere(const uint16_t *lab, int nx, int ny, int nz,
                             const double sp[3], uint16_t a, uint16_t b, double reach_mm,
                             double centre_ijk[3], double *radius_mm)
{
    int R[3];
    for (int d = 0; d < 3; d++)
        R[d] = (int)ceil(reach_mm / sp[d]);
    double A[4][4] = {{0}}, rhs[4] = {0};
    size_t used = 0;
#define AT(i, j, k) lab[((size_t)(k) * ny + (j)) * nx + (i)]
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                if (AT(i, j, k) != a)
                    continue;
                int boundary = i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 ||
                               k == nz - 1 || AT(i + 1, j, k) != a || AT(i - 1, j, k) != a ||
                               AT(i, j + 1, k) != a || AT(i, j - 1, k) != a ||
                               AT(i, j, k + 1) != a || AT(i, j, k - 1) != a;
                if (!boundary)
                    continue;
                int near = 0;
                for (int dk = -R[2]; dk <= R[2] && !near; dk++)
                    for (int dj = -R[1]; dj <= R[1] && !near; dj++)
                        for (int di = -R[0]; di <= R[0] && !near; di++) {
                            int x = i + di, y = j + dj, z = k + dk;
                            if (x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz)
                                continue;
                            double dx = di * sp[0], dy = dj * sp[1], dz = dk * sp[2];
                            near = AT(x, y, z) == b && dx * dx + dy * dy + dz * dz <= reach_mm * reach_mm;
                        }
                if (!near)
                    continue;
                /* |p|^2 = 2 c.p + (r^2 - |c|^2): unknowns c (3) and e, in mm. */
                double p[4] = {i * sp[0], j * sp[1], k * sp[2], 1.0};
                double q = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
                double row[4] = {2 * p[0], 2 * p[1], 2 * p[2], 1.0};
                for (int r = 0; r < 4; r++) {
                    for (int c = 0; c < 4; c++)
                        A[r][c] += row[r] * row[c];
                    rhs[r] += row[r] * q;
                }
                used++;
            }
#undef AT
    if (used < 10)
        return 0;
    double x[4];
    if (solve4(A, rhs, x) != 0)
        return 0;
    double r2 = x[3] + x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
    if (!(r2 > 0))
        return 0;
    for (int d = 0; d < 3; d++)
        centre_ijk[d] = x[d] / sp[d];
    *radius_mm = sqrt(r2);
    return used;
}
