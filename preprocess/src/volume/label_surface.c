/* SPDX-License-Identifier: Apache-2.0 */
#include "label_surface.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <pose/pose.h>

/* The 6 faces of a voxel: neighbour offset and the 4 corners (offsets in
 * {0,1}^3 from the voxel's lower corner), counter-clockwise seen from
 * outside (normal = the offset). */
static const int k_face[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
static const int k_corner[6][4][3] = {
    {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}, {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}},
    {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}}, {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}},
    {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}};

static void taubin(float *pos, size_t nv, const uint32_t *tri, size_t nt, int iters)
{
    float *acc = malloc(4 * nv * sizeof *acc);
    if (!acc)
        return;
    for (int it = 0; it < 2 * iters; it++) {
        const float f = (it & 1) ? -0.53f : 0.5f;
        memset(acc, 0, 4 * nv * sizeof *acc);
        for (size_t t = 0; t < nt; t++)
            for (int e = 0; e < 3; e++) {
                uint32_t a = tri[3 * t + e], b = tri[3 * t + (e + 1) % 3];
                for (int c = 0; c < 3; c++) {
                    acc[4 * a + c] += pos[3 * b + c];
                    acc[4 * b + c] += pos[3 * a + c];
                }
                acc[4 * a + 3] += 1.0f;
                acc[4 * b + 3] += 1.0f;
            }
        for (size_t v = 0; v < nv; v++)
            if (acc[4 * v + 3] > 0)
                for (int c = 0; c < 3; c++)
                    pos[3 * v + c] += f * (acc[4 * v + c] / acc[4 * v + 3] - pos[3 * v + c]);
    }
    free(acc);
}

int pp_label_surface(const uint8_t *mask, int nx, int ny, int nz, const double affine[3][4],
                     int smooth, const char *name, pp_mesh *out)
{
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "%s", name);
    /* Bounding box of the region. */
    int lo[3] = {nx, ny, nz}, hi[3] = {-1, -1, -1};
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++)
                if (mask[((size_t)k * ny + j) * nx + i]) {
                    int c[3] = {i, j, k};
                    for (int a = 0; a < 3; a++) {
                        lo[a] = c[a] < lo[a] ? c[a] : lo[a];
                        hi[a] = c[a] > hi[a] ? c[a] : hi[a];
                    }
                }
    if (hi[0] < 0)
        return 1;
    /* Corner lattice over the box: corner (i, j, k) is the lower corner of voxel (i, j, k). */
    const int cx = hi[0] - lo[0] + 2, cy = hi[1] - lo[1] + 2, cz = hi[2] - lo[2] + 2;
    size_t ncorner = (size_t)cx * cy * cz;
    int32_t *vid = malloc(ncorner * sizeof *vid);
    if (!vid)
        return POSE_ERR_OUT_OF_MEMORY;
    for (size_t c = 0; c < ncorner; c++)
        vid[c] = -1;
    size_t nq = 0;
#define IN(i, j, k)                                                                                \
    ((i) >= 0 && (j) >= 0 && (k) >= 0 && (i) < nx && (j) < ny && (k) < nz &&                     \
     mask[((size_t)(k) * ny + (j)) * nx + (i)])
    for (int pass = 0; pass < 2; pass++) {
        size_t q = 0, nv = 0;
        for (int k = lo[2]; k <= hi[2]; k++)
            for (int j = lo[1]; j <= hi[1]; j++)
                for (int i = lo[0]; i <= hi[0]; i++) {
                    if (!IN(i, j, k))
                        continue;
                    for (int f = 0; f < 6; f++) {
                        if (IN(i + k_face[f][0], j + k_face[f][1], k + k_face[f][2]))
                            continue;
                        if (pass == 0) {
                            q++;
                            continue;
                        }
                        uint32_t v[4];
                        for (int c = 0; c < 4; c++) {
                            int a = i - lo[0] + k_corner[f][c][0], b = j - lo[1] + k_corner[f][c][1],
                                d = k - lo[2] + k_corner[f][c][2];
                            size_t ci = ((size_t)d * cy + b) * cx + a;
                            if (vid[ci] < 0) {
                                vid[ci] = (int32_t)nv;
                                double p[3] = {lo[0] + a - 0.5, lo[1] + b - 0.5, lo[2] + d - 0.5};
                                for (int r = 0; r < 3; r++)
                                    out->positions[3 * nv + r] =
                                        (float)(affine[r][0] * p[0] + affine[r][1] * p[1] +
                                                affine[r][2] * p[2] + affine[r][3]);
                                nv++;
                            }
                            v[c] = (uint32_t)vid[ci];
                        }
                        uint32_t *t = out->triangles + 6 * q;
                        t[0] = v[0], t[1] = v[1], t[2] = v[2];
                        t[3] = v[0], t[4] = v[2], t[5] = v[3];
                        q++;
                    }
                }
        if (pass == 0) {
            nq = q;
            /* at most 4 new corners per face */
            out->positions = malloc(3 * 4 * nq * sizeof *out->positions);
            out->triangles = malloc(6 * nq * sizeof *out->triangles);
            if (!out->positions || !out->triangles) {
                free(vid);
                pp_mesh_free(out);
                return POSE_ERR_OUT_OF_MEMORY;
            }
        } else {
            out->vertex_count = nv;
            out->triangle_count = 2 * nq;
        }
    }
#undef IN
    free(vid);
    /* A mirroring affine turns the faces inward: flip them. */
    double det = affine[0][0] * (affine[1][1] * affine[2][2] - affine[1][2] * affine[2][1]) -
                 affine[0][1] * (affine[1][0] * affine[2][2] - affine[1][2] * affine[2][0]) +
                 affine[0][2] * (affine[1][0] * affine[2][1] - affine[1][1] * affine[2][0]);
    if (det < 0)
        for (size_t t = 0; t < out->triangle_count; t++) {
            uint32_t s = out->triangles[3 * t + 1];
            out->triangles[3 * t + 1] = out->triangles[3 * t + 2];
            out->triangles[3 * t + 2] = s;
        }
    if (smooth > 0)
        taubin(out->positions, out->vertex_count, out->triangles, out->triangle_count, smooth);
    return 0;
}

int pp_mesh_write_obj(const pp_mesh *m, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    int bad = fprintf(f, "# %s: label surface (pose-bake --labels)\no %s\n", m->name, m->name) < 0;
    for (size_t v = 0; v < m->vertex_count && !bad; v++)
        bad = fprintf(f, "v %.7g %.7g %.7g\n", m->positions[3 * v], m->positions[3 * v + 1],
                      m->positions[3 * v + 2]) < 0;
    for (size_t t = 0; t < m->triangle_count && !bad; t++)
        bad = fprintf(f, "f %u %u %u\n", m->triangles[3 * t] + 1, m->triangles[3 * t + 1] + 1,
                      m->triangles[3 * t + 2] + 1) < 0;
    bad |= fclose(f) != 0;
    return bad ? -1 : 0;
}
