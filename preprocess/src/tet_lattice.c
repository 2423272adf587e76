/* SPDX-License-Identifier: Apache-2.0
 *
 * The built-in mesher: a Kuhn (Freudenthal) lattice over the labelled voxel
 * image. Each body cell is cut into six tets around its (0,0,0)-(1,1,1)
 * diagonal; every cell uses the same diagonal, so faces match between cells
 * without any search and all tets are congruent (dihedral angles 45-90
 * degrees, radius-edge 0.87). The outer boundary is then snapped onto the
 * skin (tet_snap.c). Why a lattice and not Delaunay refinement: it is
 * linear-time, needs no robust predicates, and conforms to the labels by
 * construction; its cost is a uniform size (no grading away from
 * boundaries).
 */
#include "tet_snap.h"
#include "tetmesh.h"
#include "voxelize.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct lattice {
    int m[3];          /* cells per axis */
    double c;          /* cell edge, metres */
    double o[3];       /* corner (0,0,0) of cell (0,0,0) */
    uint16_t *cell;    /* voxel label per cell */
} lattice;

static uint16_t voxel_at(const pp_voxels *v, int x, int y, int z)
{
    if (x < 0 || y < 0 || z < 0 || x >= v->nx || y >= v->ny || z >= v->nz)
        return PP_VOXEL_OUTSIDE;
    return v->labels[(size_t)x + (size_t)v->nx * ((size_t)y + (size_t)v->ny * z)];
}

/* Label the cells of edge c. A cell takes the voxel at its centre; a coarser
 * cell whose centre is not bone takes the most frequent bone among its voxels,
 * so a thin bone is never lost to sampling. */
static pose_status label_cells(const pp_voxels *v, double c, lattice *L)
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
    int coarse = c > 1.01 * h;
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
    return POSE_OK;
}

static uint16_t cell_at(const lattice *L, int x, int y, int z)
{
    if (x < 0 || y < 0 || z < 0 || x >= L->m[0] || y >= L->m[1] || z >= L->m[2])
        return PP_VOXEL_OUTSIDE;
    return L->cell[(size_t)x + (size_t)L->m[0] * ((size_t)y + (size_t)L->m[1] * z)];
}

/* Number the corners used by body cells into vid (UINT32_MAX when unused). */
static size_t number_corners(const lattice *L, uint32_t *vid, size_t *cells)
{
    size_t cx = (size_t)L->m[0] + 1, cy = (size_t)L->m[1] + 1, cz = (size_t)L->m[2] + 1;
    memset(vid, 0xff, cx * cy * cz * sizeof *vid);
    size_t n = 0, nc = 0;
    for (int z = 0; z < L->m[2]; z++)
        for (int y = 0; y < L->m[1]; y++)
            for (int x = 0; x < L->m[0]; x++) {
                if (cell_at(L, x, y, z) == PP_VOXEL_OUTSIDE)
                    continue;
                nc++;
                for (int k = 0; k < 8; k++) {
                    size_t g = (size_t)(x + (k & 1)) + cx * ((size_t)(y + (k >> 1 & 1)) +
                                                             cy * (size_t)(z + (k >> 2)));
                    if (vid[g] == UINT32_MAX)
                        vid[g] = (uint32_t)n++;
                }
            }
    *cells = nc;
    return n;
}

/* The six Kuhn tets of the unit cube as corner indices (bit 0 = x, 1 = y,
 * 2 = z), one per axis order; odd orders are written with two vertices
 * swapped so that every tet is positively oriented. */
static const int kuhn[6][4] = {
    {0, 1, 3, 7}, /* x y z */
    {0, 4, 5, 7}, /* z x y */
    {0, 2, 6, 7}, /* y z x */
    {0, 3, 2, 7}, /* y x z (odd: path 0 2 3 7) */
    {0, 5, 1, 7}, /* x z y (odd: path 0 1 5 7) */
    {0, 6, 4, 7}, /* z y x (odd: path 0 4 6 7) */
};

pose_status pp_tet_lattice(const pp_voxels *vox, const pp_mesh *skin, const pp_tet_options *opt,
                           pp_tetmesh *out, char *err, size_t errlen)
{
    if (!vox || !out || !vox->labels)
        return POSE_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    pp_tet_options def = {0};
    if (!opt)
        opt = &def;
    size_t body = 0, nvox = (size_t)vox->nx * vox->ny * vox->nz;
    for (size_t i = 0; i < nvox; i++)
        body += vox->labels[i] != PP_VOXEL_OUTSIDE;
    if (body == 0) {
        if (err && errlen)
            snprintf(err, errlen, "tetrahedralize: the voxel image has no body voxel");
        return POSE_ERR_INVALID_DATA;
    }

    lattice L = {0};
    uint32_t *vid = NULL;
    size_t nv = 0, ncell = 0;
    double c = vox->spacing;
    if (opt->target_vertices)
        c = vox->spacing * cbrt((double)body / (double)opt->target_vertices);
    /* Two tries at most: the first count corrects the estimate (the surface
     * layer adds corners the cell count does not see). */
    for (int pass = 0; pass < 2; pass++) {
        pose_status s = label_cells(vox, c, &L);
        if (s == POSE_OK) {
            size_t corners = ((size_t)L.m[0] + 1) * ((size_t)L.m[1] + 1) * ((size_t)L.m[2] + 1);
            free(vid);
            vid = malloc(corners * sizeof *vid);
            s = vid ? POSE_OK : POSE_ERR_OUT_OF_MEMORY;
        }
        if (s != POSE_OK) {
            free(L.cell);
            free(vid);
            if (err && errlen)
                snprintf(err, errlen, "tetrahedralize: out of memory");
            return s;
        }
        nv = number_corners(&L, vid, &ncell);
        if (!opt->target_vertices || pass == 1)
            break;
        double ratio = (double)nv / (double)opt->target_vertices;
        if (ratio > 0.95 && ratio < 1.05)
            break;
        c *= cbrt(ratio);
    }
    if (nv > UINT32_MAX || ncell * 6 > UINT32_MAX) {
        free(L.cell);
        free(vid);
        if (err && errlen)
            snprintf(err, errlen, "tetrahedralize: %zu cells exceed 32-bit indices", ncell);
        return POSE_ERR_INVALID_ARGUMENT;
    }

    out->vertex_count = nv;
    out->tet_count = 6 * ncell;
    out->positions = malloc((nv ? nv : 1) * 3 * sizeof *out->positions);
    out->tets = malloc((ncell ? ncell : 1) * 24 * sizeof *out->tets);
    out->labels = malloc((ncell ? ncell : 1) * 6 * sizeof *out->labels);
    int8_t *dir = calloc(nv ? 3 * nv : 1, 1);
    uint8_t *near_bone = calloc(nv ? nv : 1, 1);
    if (!out->positions || !out->tets || !out->labels || !dir || !near_bone) {
        free(L.cell);
        free(vid);
        free(dir);
        free(near_bone);
        pp_tetmesh_free(out);
        if (err && errlen)
            snprintf(err, errlen, "tetrahedralize: out of memory");
        return POSE_ERR_OUT_OF_MEMORY;
    }
    size_t cx = (size_t)L.m[0] + 1, cy = (size_t)L.m[1] + 1;
    for (size_t z = 0; z <= (size_t)L.m[2]; z++)
        for (size_t y = 0; y < cy; y++)
            for (size_t x = 0; x < cx; x++) {
                uint32_t i = vid[x + cx * (y + cy * z)];
                if (i == UINT32_MAX)
                    continue;
                out->positions[3 * (size_t)i] = (float)(L.o[0] + (double)x * L.c);
                out->positions[3 * (size_t)i + 1] = (float)(L.o[1] + (double)y * L.c);
                out->positions[3 * (size_t)i + 2] = (float)(L.o[2] + (double)z * L.c);
            }
    static const int face_dir[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0},
                                       {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};
    size_t t = 0;
    for (int z = 0; z < L.m[2]; z++)
        for (int y = 0; y < L.m[1]; y++)
            for (int x = 0; x < L.m[0]; x++) {
                uint16_t l = cell_at(&L, x, y, z);
                if (l == PP_VOXEL_OUTSIDE)
                    continue;
                uint32_t corner[8];
                for (int k = 0; k < 8; k++)
                    corner[k] = vid[(size_t)(x + (k & 1)) +
                                    cx * ((size_t)(y + (k >> 1 & 1)) + cy * (size_t)(z + (k >> 2)))];
                uint16_t tl = (uint16_t)(l - 1); /* voxel 1 -> tet 0, 2 + j -> j + 1 */
                for (int k = 0; k < 6; k++, t++) {
                    for (int q = 0; q < 4; q++)
                        out->tets[4 * t + q] = corner[kuhn[k][q]];
                    out->labels[t] = tl;
                }
                if (l >= PP_VOXEL_BONE0)
                    for (int k = 0; k < 8; k++)
                        near_bone[corner[k]] = 1;
                /* Outer faces: their corners are snapped along the summed normals. */
                for (int f = 0; f < 6; f++) {
                    const int *d = face_dir[f];
                    if (cell_at(&L, x + d[0], y + d[1], z + d[2]) != PP_VOXEL_OUTSIDE)
                        continue;
                    int axis = f / 2, side = f & 1;
                    for (int k = 0; k < 8; k++) {
                        if (((k >> axis) & 1) != side)
                            continue;
                        int8_t *dv = dir + 3 * (size_t)corner[k];
                        dv[0] = (int8_t)(dv[0] + d[0]);
                        dv[1] = (int8_t)(dv[1] + d[1]);
                        dv[2] = (int8_t)(dv[2] + d[2]);
                    }
                }
            }
    free(vid);
    free(L.cell);
    /* Bone that reaches the skin keeps its voxel boundary: the skin is not its surface. */
    for (size_t i = 0; i < nv; i++)
        if (near_bone[i])
            dir[3 * i] = dir[3 * i + 1] = dir[3 * i + 2] = 0;
    free(near_bone);
    pose_status s = POSE_OK;
    if (skin && !opt->no_snap) {
        size_t moved = 0;
        s = pp_tet_snap(out, skin, dir, (float)(2.0 * L.c), &moved);
        if (s != POSE_OK && err && errlen)
            snprintf(err, errlen, "tetrahedralize: out of memory while snapping");
    }
    free(dir);
    if (s != POSE_OK)
        pp_tetmesh_free(out);
    return s;
}
