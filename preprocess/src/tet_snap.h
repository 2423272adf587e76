/* SPDX-License-Identifier: Apache-2.0
 *
 * Snapping lattice boundary vertices onto a surface (internal to the
 * built-in mesher, tet_lattice.c).
 */
#ifndef POSE_PP_TET_SNAP_H
#define POSE_PP_TET_SNAP_H

#include "pp_types.h"

#include <pose/pose.h>

/**
 * Move each vertex v with dir[3v..3v+2] != 0 (the summed outward normals of
 * its staircase boundary faces) onto `surface`: each coordinate whose axis
 * is set in dir first moves along that axis to the surface, then the point
 * goes to its closest surface point within `reach` (so staircase corners and
 * edges land on the surface's corners and edges). A move is
 * halved up to twice and otherwise dropped when an incident tet would keep
 * less than 10 % of its volume, so no tet inverts. Returns the count moved.
 */
pose_status pp_tet_snap(pp_tetmesh *t, const pp_mesh *surface, const int8_t *dir, float reach,
                        size_t *moved);

#endif /* POSE_PP_TET_SNAP_H */
