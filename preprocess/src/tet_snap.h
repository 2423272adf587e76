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
 * Move each vertex v with dir[3v..3v+2] != 0 onto `surface`, along its
 * direction (the summed outward normals of its boundary faces, so box
 * corners and edges land on corners and edges) or, when that ray misses
 * within `reach`, to the closest surface point within `reach`. A move is
 * halved up to twice and otherwise dropped when an incident tet would keep
 * less than 10 % of its volume, so no tet inverts. Returns the count moved.
 */
pose_status pp_tet_snap(pp_tetmesh *t, const pp_mesh *surface, const int8_t *dir, float reach,
                        size_t *moved);

#endif /* POSE_PP_TET_SNAP_H */
