/* SPDX-License-Identifier: Apache-2.0
 *
 * The two mesh builders behind the built-in backend (internal). Both write
 * a labelled, positively oriented tet mesh of the body cells and, per
 * vertex, the summed outward normals of the outer faces it lies on (3 int8
 * per vertex, zero inside) for snapping.
 */
#ifndef POSE_PP_TET_BUILD_H
#define POSE_PP_TET_BUILD_H

#include "tet_cells.h"

/** Uniform: six Kuhn tets per body cell. */
pose_status pp_tet_kuhn_build(const pp_cells *L, pp_tetmesh *out, int8_t **dir);

/** Graded: a balanced octree whose leaves are at most 2^grading cells wide,
 * one cell wide along every label boundary (tet_octree.c). */
pose_status pp_tet_octree_build(const pp_cells *L, int grading, pp_tetmesh *out, int8_t **dir);

#endif /* POSE_PP_TET_BUILD_H */
