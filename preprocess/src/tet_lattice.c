/* SPDX-License-Identifier: Apache-2.0
 *
 * The built-in mesher over the labelled voxel image, in two variants:
 *  - uniform: a Kuhn (Freudenthal) lattice. Each body cell is cut into six
 *    tets around its (0,0,0)-(1,1,1) diagonal; every cell uses the same
 *    diagonal, so faces match between cells without any search and all tets
 *    are congruent (dihedral angles 45-90 degrees, radius-edge 0.87);
 *  - graded (opt->grading > 0): a balanced octree, fine at skin and bone
 *    boundaries and coarser inside (tet_octree.c).
 * Then the outer boundary is snapped onto the skin (tet_snap.c). Why a
 * lattice and not Delaunay refinement: it is linear-time, needs no robust
 * predicates and conforms to the labels by construction.
 */
#include "tet_cells.h"
#include "tet_snap.h"
#include "tet_build.h"
#include "tetmesh.h"
#include "voxelize.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Number the corners used by body cells into vid (UINT32_MAX when unused). */
static size_t number_corners(const pp_cells *L, uint32_t *vid, size_t *cells)
{
    size_t cx = (size_t)L->m[0] + 1, cy = (size_t)L->m[1] + 1, cz = (size_t)L->m[2] + 1;
    memset(vid, 0xff, cx * cy * cz * sizeof *vid);
    size_t n = 0, nc = 0;
    for (int z = 0; z < L->m[2]; z++)
        for (int y = 0; y < L->m[1]; y++)
            for (int x = 0; x < L->m[0]; x++) {
                if (pp_cells_at(L, x, y, z) == PP_VOXEL_OUTSIDE)
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

/* The uniform Kuhn mesh of the body cells, with the outer faces' summed
 * normals per vertex in *dir_out (3 per vertex). */
pose_status pp_tet_kuhn_build(const pp_cells *L, pp_tetmesh *out, int8_t **dir_out)
{
    memset(out, 0, sizeof *out);
    *dir_out = NULL;
    size_t corners = ((size_t)L->m[0] + 1) * ((size_t)L->m[1] + 1) * ((size_t)L->m[2] + 1);
    uint32_t *vid = malloc(corners * sizeof *vid);
    if (!vid)
        return POSE_ERR_OUT_OF_MEMORY;
    size_t ncell = 0;
    size_t nv = number_corners(L, vid, &ncell);
    if (nv > UINT32_MAX || ncell * 6 > UINT32_MAX) {
        free(vid);
        return POSE_ERR_INVALID_ARGUMENT;
    }
    out->vertex_count = nv;
    out->tet_count = 6 * ncell;
    out->positions = malloc((nv ? nv : 1) * 3 * sizeof *out->positions);
    out->tets = malloc((ncell ? ncell : 1) * 24 * sizeof *out->tets);
    out->labels = malloc((ncell ? ncell : 1) * 6 * sizeof *out->labels);
    int8_t *dir = calloc(nv ? 3 * nv : 1, 1);
    if (!out->positions || !out->tets || !out->labels || !dir) {
        free(vid);
        free(dir);
        pp_tetmesh_free(out);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    size_t cx = (size_t)L->m[0] + 1, cy = (size_t)L->m[1] + 1;
    for (size_t z = 0; z <= (size_t)L->m[2]; z++)
        for (size_t y = 0; y < cy; y++)
            for (size_t x = 0; x < cx; x++) {
                uint32_t i = vid[x + cx * (y + cy * z)];
                if (i == UINT32_MAX)
                    continue;
                out->positions[3 * (size_t)i] = (float)(L->o[0] + (double)x * L->c);
                out->positions[3 * (size_t)i + 1] = (float)(L->o[1] + (double)y * L->c);
                out->positions[3 * (size_t)i + 2] = (float)(L->o[2] + (double)z * L->c);
            }
    static const int face_dir[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0},
                                       {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};
    size_t t = 0;
    for (int z = 0; z < L->m[2]; z++)
        for (int y = 0; y < L->m[1]; y++)
            for (int x = 0; x < L->m[0]; x++) {
                uint16_t l = pp_cells_at(L, x, y, z);
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
                for (int f = 0; f < 6; f++) {
                    const int *d = face_dir[f];
                    if (pp_cells_at(L, x + d[0], y + d[1], z + d[2]) != PP_VOXEL_OUTSIDE)
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
    *dir_out = dir;
    return POSE_OK;
}

static pose_status build(const pp_cells *L, int grading, pp_tetmesh *out, int8_t **dir)
{
    return grading > 0 ? pp_tet_octree_build(L, grading, out, dir) : pp_tet_kuhn_build(L, out, dir);
}

pose_status pp_tet_lattice(const pp_voxels *vox, const pp_mesh *skin, const pp_tet_options *opt,
                           pp_tetmesh *out, char *err, size_t errlen)
{
    if (!vox || !out || !vox->labels)
        return POSE_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    pp_tet_options def = {0};
    if (!opt)
        opt = &def;
    int grading = opt->grading < 0    ? 0
                  : opt->grading == 0 ? PP_TET_DEFAULT_GRADING
                  : opt->grading > PP_TET_MAX_GRADING ? PP_TET_MAX_GRADING
                                                      : opt->grading;
    size_t body = 0, nvox = (size_t)vox->nx * vox->ny * vox->nz;
    for (size_t i = 0; i < nvox; i++)
        body += vox->labels[i] != PP_VOXEL_OUTSIDE;
    if (body == 0) {
        if (err && errlen)
            snprintf(err, errlen, "tetrahedralize: the voxel image has no body voxel");
        return POSE_ERR_INVALID_DATA;
    }

    pp_cells L = {0};
    int8_t *dir = NULL;
    double c = vox->spacing;
    if (opt->target_vertices)
        c = vox->spacing * cbrt((double)body / (double)opt->target_vertices);
    /* A few tries: each count corrects the cell size (the surface layer adds
     * vertices a volume estimate does not see; a graded mesh is mostly
     * surface, so its count goes with the square of the size). */
    pose_status s = POSE_OK;
    int grow = skin && !opt->no_snap; /* one layer more, snapped inward */
    for (int pass = 0; pass < 4; pass++) {
        pp_tetmesh_free(out);
        free(dir);
        dir = NULL;
        s = pp_cells_label(vox, c, &L);
        if (s == POSE_OK && grow)
            s = pp_cells_dilate(&L);
        if (s == POSE_OK)
            s = build(&L, grading, out, &dir);
        if (s != POSE_OK || !opt->target_vertices)
            break;
        double ratio = (double)out->vertex_count / (double)opt->target_vertices;
        if (ratio > 0.93 && ratio < 1.07)
            break;
        c *= grading > 0 ? sqrt(ratio) : cbrt(ratio);
    }
    double cell = L.c;
    pp_cells_free(&L);
    if (s != POSE_OK) {
        free(dir);
        pp_tetmesh_free(out);
        if (err && errlen)
            snprintf(err, errlen, s == POSE_ERR_OUT_OF_MEMORY
                                      ? "tetrahedralize: out of memory"
                                      : "tetrahedralize: the mesh exceeds 32-bit indices");
        return s;
    }
    /* Bone that reaches the skin keeps its voxel boundary: the skin is not its surface. */
    for (size_t t = 0; t < out->tet_count; t++)
        if (out->labels[t] != 0)
            for (int k = 0; k < 4; k++)
                memset(dir + 3 * (size_t)out->tets[4 * t + k], 0, 3);
    if (skin && !opt->no_snap) {
        size_t moved = 0;
        s = pp_tet_snap(out, skin, dir, (float)(PP_SNAP_REACH * cell),
                        (float)(PP_SNAP_MARGIN * cell), &moved);
        if (s != POSE_OK && err && errlen)
            snprintf(err, errlen, "tetrahedralize: out of memory while snapping");
    }
    free(dir);
    if (s != POSE_OK)
        pp_tetmesh_free(out);
    return s;
}
