/* SPDX-License-Identifier: Apache-2.0
 * Structured tet meshes for preprocessing tests: a box of nx*ny*nz cubes,
 * each split into six positively oriented tets (Kuhn split, conforming). */
#ifndef POSE_TEST_PP_MESH_H
#define POSE_TEST_PP_MESH_H

#include "pp_types.h"

/** Box from the origin, cell edge h; labels 0. Returns 0 on success. */
int pp_test_box(int nx, int ny, int nz, float h, pp_tetmesh *out);
/** Label every tet whose centroid has cell index i (along x) in [i0, i1) as `label`. */
void pp_test_label_slab(pp_tetmesh *m, float h, int i0, int i1, uint16_t label);
/** Vertex index of lattice point (i, j, k) in a box made by pp_test_box. */
size_t pp_test_vertex(int nx, int ny, int i, int j, int k);

#endif
