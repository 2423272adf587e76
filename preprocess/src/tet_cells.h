/* SPDX-License-Identifier: Apache-2.0
 *
 * The cell grid under the built-in meshers (internal): the voxel image
 * resampled to cells of edge c, one label per cell.
 */
#ifndef POSE_PP_TET_CELLS_H
#define POSE_PP_TET_CELLS_H

#include "pp_types.h"

#include <pose/pose.h>

typedef struct pp_cells {
    int m[3];          /**< cells per axis */
    double c;          /**< cell edge, metres */
    double o[3];       /**< corner (0,0,0) of cell (0,0,0) */
    uint16_t *cell;    /**< voxel label per cell, x fastest */
} pp_cells;

/** Label cells of edge c covering the voxel grid. With c equal to the voxel
 * spacing, cell i is voxel i. Otherwise a cell takes the voxel at its centre,
 * or the most frequent bone among its voxels when the centre is not bone, and
 * a bone that would vanish takes the cell of one of its voxels (unless that
 * is another bone's last cell). Replaces L->cell. */
pose_status pp_cells_label(const pp_voxels *v, double c, pp_cells *L);

/** Grow the body by one layer of soft-tissue cells: every outside cell with
 * a body cell among its 26 neighbours becomes PP_VOXEL_SOFT; the grid gains
 * one cell on every side (L->o moves by -c). Why: a body cell is one whose
 * centre lies inside the skin, so the skin bulges out of the staircase
 * between centres (most of the shared body's skin vertices lay outside the
 * snapped mesh, up to 6 mm at 6 mm voxels). The new boundary's corners touch
 * only cells whose centres are outside, which puts it outside the skin
 * except where the skin is thinner than a cell; snapping then pulls it in
 * as far as the tets allow (tet_snap.h), and where a move is refused the
 * mesh stays larger than the skin rather than smaller. */
pose_status pp_cells_dilate(pp_cells *L);

/** Label of cell (x, y, z); PP_VOXEL_OUTSIDE beyond the grid. */
uint16_t pp_cells_at(const pp_cells *L, int x, int y, int z);

void pp_cells_free(pp_cells *L);

#endif /* POSE_PP_TET_CELLS_H */
