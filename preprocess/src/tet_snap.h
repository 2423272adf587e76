/* SPDX-License-Identifier: Apache-2.0
 *
 * Snapping lattice boundary vertices onto a surface (internal to the
 * built-in mesher, tet_lattice.c).
 */
#ifndef POSE_PP_TET_SNAP_H
#define POSE_PP_TET_SNAP_H

#include "pp_types.h"

#include <pose/pose.h>

/* Snapping distances in cell edges. Reach: after pp_cells_dilate a boundary
 * corner lies up to ~1.5 cells (2.6 along a diagonal) outside the skin.
 * Margin: see pp_tet_snap; measured on the shared body in tet_snap.c. */
#define PP_SNAP_REACH 3.0
#ifndef PP_SNAP_MARGIN
#define PP_SNAP_MARGIN 0.15
#endif

/**
 * Move each vertex v with dir[3v..3v+2] != 0 (the summed outward normals of
 * its staircase boundary faces) inward to `margin` outside `surface`: each
 * coordinate whose axis is set in dir first moves along that axis to the
 * surface, then the point goes to its closest surface point q within
 * `reach` (so staircase corners and edges land on the surface's corners and
 * edges), and the target is q plus `margin` towards the vertex. The margin
 * covers the sag of the flat tet faces between snapped vertices, so that
 * the surface's own vertices stay inside the mesh. Vertices already inside
 * the surface (along dir) do not move. A move is halved up to twice and
 * otherwise dropped when an incident tet would fall below a shape quality
 * of 0.2 (or its own, if worse), so no tet inverts; a partial move leaves
 * the vertex further out. Returns the count moved in full.
 */
pose_status pp_tet_snap(pp_tetmesh *t, const pp_mesh *surface, const int8_t *dir, float reach,
                        float margin, size_t *moved);

#endif /* POSE_PP_TET_SNAP_H */
