/* SPDX-License-Identifier: Apache-2.0
 *
 * Surfaces of labelled voxel regions, for pose-bake --labels.
 *
 * Marching cubes was the first choice, but Debian 12 packages no small
 * C marching-cubes library (VTK's vtkDiscreteMarchingCubes is the
 * well-kept one, far too heavy for one filter), so this is the cuberille
 * surface: every face between a voxel inside the region and one outside
 * becomes two triangles on the voxel corners (closed and consistently
 * oriented by construction: outward), then Taubin smoothing (lambda 0.5,
 * mu -0.53, which does not shrink) rounds the voxel steps off. Corners
 * where regions touch only along an edge or at a point are shared, which
 * leaves non-manifold edges; the voxelizer's inside test (6 rays, winding
 * number for ties) is robust to them.
 */
#ifndef POSE_PP_LABEL_SURFACE_H
#define POSE_PP_LABEL_SURFACE_H

#include <stddef.h>
#include <stdint.h>

#include "pp_types.h"

/**
 * Surface of the voxels where mask[v] != 0 (nx*ny*nz, x fastest) as a
 * triangle mesh in model space: corner (i - 0.5, j - 0.5, k - 0.5) of voxel
 * (i, j, k) maps through `affine` (voxel index -> model). smooth: Taubin
 * iterations (0 keeps the voxel steps). name: the mesh's name. Returns 0,
 * 1 when the mask is empty (no mesh), or a negative pose_status.
 */
int pp_label_surface(const uint8_t *mask, int nx, int ny, int nz, const double affine[3][4],
                     int smooth, const char *name, pp_mesh *out);

/** Write a mesh as Wavefront OBJ (vertices and triangles). Returns 0 or -1. */
int pp_mesh_write_obj(const pp_mesh *m, const char *path);

#endif /* POSE_PP_LABEL_SURFACE_H */
