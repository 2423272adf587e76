/* SPDX-License-Identifier: Apache-2.0 */
#include "pp_test_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

size_t pp_test_vertex(int nx, int ny, int i, int j, int k)
{
    return ((size_t)k * (size_t)(ny + 1) + (size_t)j) * (size_t)(nx + 1) + (size_t)i;
}

static double orient(const float *a, const float *b, const float *c, const float *d)
{
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

int pp_test_box(int nx, int ny, int nz, float h, pp_tetmesh *out)
{
    memset(out, 0, sizeof *out);
    out->vertex_count = (size_t)(nx + 1) * (ny + 1) * (nz + 1);
    out->tet_count = (size_t)6 * nx * ny * nz;
    out->positions = malloc(3 * out->vertex_count * sizeof(float));
    out->tets = malloc(4 * out->tet_count * sizeof(uint32_t));
    out->labels = calloc(out->tet_count, sizeof(uint16_t));
    if (!out->positions || !out->tets || !out->labels)
        return -1;
    for (int k = 0; k <= nz; k++)
        for (int j = 0; j <= ny; j++)
            for (int i = 0; i <= nx; i++) {
                float *p = out->positions + 3 * pp_test_vertex(nx, ny, i, j, k);
                p[0] = (float)i * h, p[1] = (float)j * h, p[2] = (float)k * h;
            }
    /* Six tets around the main diagonal 0-7, one per path 0 -> 7 along the
     * axes (Kuhn): conforming across cells because every cell uses the
     * same diagonal direction. */
    static const int paths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    size_t t = 0;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++)
                for (int p = 0; p < 6; p++) {
                    int c[3] = {i, j, k};
                    uint32_t v[4];
                    v[0] = (uint32_t)pp_test_vertex(nx, ny, c[0], c[1], c[2]);
                    for (int s = 0; s < 3; s++) {
                        c[paths[p][s]]++;
                        v[s + 1] = (uint32_t)pp_test_vertex(nx, ny, c[0], c[1], c[2]);
                    }
                    if (orient(out->positions + 3 * v[0], out->positions + 3 * v[1],
                               out->positions + 3 * v[2], out->positions + 3 * v[3]) < 0) {
                        uint32_t x = v[2];
                        v[2] = v[3];
                        v[3] = x;
                    }
                    memcpy(out->tets + 4 * t++, v, sizeof v);
                }
    return 0;
}

void pp_test_label_slab(pp_tetmesh *m, float h, int i0, int i1, uint16_t label)
{
    for (size_t t = 0; t < m->tet_count; t++) {
        double cx = 0;
        for (int c = 0; c < 4; c++)
            cx += 0.25 * m->positions[3 * (size_t)m->tets[4 * t + c]];
        int cell = (int)floor(cx / h);
        if (cell >= i0 && cell < i1)
            m->labels[t] = label;
    }
}
