/* SPDX-License-Identifier: Apache-2.0
 *
 * Resampling the labelled voxel image to the mesher's cell grid.
 */
#include "tet_cells.h"
#include "voxelize.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static uint16_t voxel_at(const pp_voxels *v, int x, int y, int z)
{
    if (x < 0 || y < 0 || z < 0 || x >= v->nx || y >= v->ny || z >= v->nz)
        return PP_VOXEL_OUTSIDE;
    return v->labels[(size_t)x + (size_t)v->nx * ((size_t)y + (size_t)v->ny * z)];
}

/* A bone smaller than a coarse cell and surrounded by other bones can lose
 * every cell to its neighbours: give it the cell of its first voxel, so that
 * each joint keeps its Dirichlet region. */
static pose_status keep_every_label(const pp_voxels *v, pp_cells *L)
{
    size_t *count = calloc(65536, sizeof *count);
    if (!count)
        return POSE_ERR_OUT_OF_MEMORY;
    size_t ncell = (size_t)L->m[0] * L->m[1] * L->m[2];
    for (size_t i = 0; i < ncell; i++)
        count[L->cell[i]]++;
    for (int z = 0; z < v->nz; z++)
        for (int y = 0; y < v->ny; y++)
            for (int x = 0; x < v->nx; x++) {
                uint16_t l = v->labels[(size_t)x + (size_t)v->nx * ((size_t)y + (size_t)v->ny * z)];
                if (l < PP_VOXEL_BONE0 || count[l])
                    continue;
                int idx[3] = {x, y, z}, c[3];
                for (int k = 0; k < 3; k++) {
                    double p = v->origin[k] + idx[k] * (double)v->spacing;
                    c[k] = (int)floor((p - L->o[k]) / L->c);
                    c[k] = c[k] < 0 ? 0 : c[k] >= L->m[k] ? L->m[k] - 1 : c[k];
                }
                uint16_t *cell = &L->cell[(size_t)c[0] +
                                          (size_t)L->m[0] * ((size_t)c[1] + (size_t)L->m[1] * c[2])];
                /* never take the last cell of another bone; a later voxel may do */
                if (*cell >= PP_VOXEL_BONE0 && count[*cell] <= 1)
                    continue;
                count[*cell]--;
                *cell = l;
                count[l]++;
            }
    free(count);
    return POSE_OK;
}

/* Label the cells of edge c. A cell takes the voxel at its centre; a coarser
 * cell whose centre is not bone takes the most frequent bone among its voxels,
 * so a thin bone is never lost to sampling. */
pose_status pp_cells_label(const pp_voxels *v, double c, pp_cells *L)
{
    double h = v->spacing;
    size_t count = 1;
    for (int k = 0; k < 3; k++) {
        int n = k == 0 ? v->nx : k == 1 ? v->ny : v->nz;
        L->o[k] = v->origin[k] - 0.5 * h;
        L->m[k] = (int)ceil(n * h / c - 1e-9);
        if (L->m[k] < 1)
            L->m[k] = 1;
        count *= (size_t)L->m[k];
    }
    L->c = c;
    free(L->cell);
    L->cell = malloc(count * sizeof *L->cell);
    if (!L->cell)
        return POSE_ERR_OUT_OF_MEMORY;
    int coarse = fabs(c - h) > 1e-6 * h; /* cells are not the voxels */
    uint16_t seen[64];
    int seen_n[64];
    for (int z = 0; z < L->m[2]; z++)
        for (int y = 0; y < L->m[1]; y++)
            for (int x = 0; x < L->m[0]; x++) {
                int idx[3] = {x, y, z}, lo[3], hi[3], ctr[3];
                for (int k = 0; k < 3; k++) {
                    double a = L->o[k] + idx[k] * c, b = a + c;
                    /* voxel i spans origin + (i -/+ 0.5) h */
                    ctr[k] = (int)floor((0.5 * (a + b) - v->origin[k]) / h + 0.5);
                    lo[k] = (int)ceil((a - v->origin[k]) / h - 0.5);
                    hi[k] = (int)floor((b - v->origin[k]) / h - 0.5);
                }
                uint16_t l = voxel_at(v, ctr[0], ctr[1], ctr[2]);
                if (coarse && l < PP_VOXEL_BONE0) {
                    int ns = 0;
                    for (int k2 = lo[2]; k2 <= hi[2]; k2++)
                        for (int j2 = lo[1]; j2 <= hi[1]; j2++)
                            for (int i2 = lo[0]; i2 <= hi[0]; i2++) {
                                uint16_t b = voxel_at(v, i2, j2, k2);
                                if (b < PP_VOXEL_BONE0)
                                    continue;
                                int s = 0;
                                while (s < ns && seen[s] != b)
                                    s++;
                                if (s == ns && ns < 64) {
                                    seen[ns] = b;
                                    seen_n[ns++] = 0;
                                }
                                if (s < ns)
                                    seen_n[s]++;
                            }
                    int best = -1;
                    for (int s = 0; s < ns; s++)
                        if (best < 0 || seen_n[s] > seen_n[best])
                            best = s;
                    if (best >= 0)
                        l = seen[best];
                }
                L->cell[(size_t)x + (size_t)L->m[0] * ((size_t)y + (size_t)L->m[1] * z)] = l;
            }
    if (coarse)
        return keep_every_label(v, L);
    return POSE_OK;
}

pose_status pp_cells_dilate(pp_cells *L)
{
    int m[3] = {L->m[0] + 2, L->m[1] + 2, L->m[2] + 2};
    uint16_t *cell = calloc((size_t)m[0] * m[1] * m[2], sizeof *cell);
    if (!cell)
        return POSE_ERR_OUT_OF_MEMORY;
    for (int z = 0; z < m[2]; z++)
        for (int y = 0; y < m[1]; y++)
            for (int x = 0; x < m[0]; x++) {
                uint16_t *c = &cell[(size_t)x + (size_t)m[0] * ((size_t)y + (size_t)m[1] * z)];
                *c = pp_cells_at(L, x - 1, y - 1, z - 1);
                for (int d = 0; d < 27 && *c == PP_VOXEL_OUTSIDE; d++)
                    if (pp_cells_at(L, x - 2 + d % 3, y - 2 + d / 3 % 3, z - 2 + d / 9) !=
                        PP_VOXEL_OUTSIDE)
                        *c = PP_VOXEL_SOFT;
            }
    free(L->cell);
    L->cell = cell;
    for (int k = 0; k < 3; k++) {
        L->m[k] = m[k];
        L->o[k] -= L->c;
    }
    return POSE_OK;
}

uint16_t pp_cells_at(const pp_cells *L, int x, int y, int z)
{
    if (x < 0 || y < 0 || z < 0 || x >= L->m[0] || y >= L->m[1] || z >= L->m[2])
        return PP_VOXEL_OUTSIDE;
    return L->cell[(size_t)x + (size_t)L->m[0] * ((size_t)y + (size_t)L->m[1] * z)];
}

void pp_cells_free(pp_cells *L)
{
    if (!L)
        return;
    free(L->cell);
    memset(L, 0, sizeof *L);
}
