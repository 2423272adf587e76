/* SPDX-License-Identifier: Apache-2.0
 *
 * Voxelize and label the body: a regular grid over the skin and bones whose
 * voxels are 0 outside, 1 soft tissue (inside the skin), 2 + j bone of joint
 * j (inside a bone mesh whose label is j).
 *
 * The inside test tolerates holes and bad orientation. For every voxel
 * centre, six axis-aligned rays (+x -x +y -y +z -z) each give a winding
 * number from signed crossings of the mesh (rasterized per voxel column with
 * a watertight top-left rule, so a closed mesh is never leaked through an
 * edge or vertex); a voxel is inside when at least 4 rays say so, outside
 * when at most 2 do, and the 3:3 ties, which only occur in the shadow of
 * holes, are decided by the exact generalized winding number
 * (sum of solid angles / 4 pi >= 1/2). For a closed mesh all six agree.
 *
 * Repairs, all counted in pp_voxel_report:
 *  - bone voxels outside the skin become part of the body (bones poking out);
 *  - a voxel inside two bones keeps the first bone in input order;
 *  - a bone too thin to contain any voxel centre is marked by the voxels
 *    holding its vertices, so every joint keeps at least one bone voxel;
 *    this holds also where the skin around it is too thin to hold a voxel
 *    centre (fingers at coarse spacings): such voxels join the body.
 */
#ifndef POSE_PP_VOXELIZE_H
#define POSE_PP_VOXELIZE_H

#include "pp_types.h"

#include <pose/pose.h>

/** Voxel label values (pp_voxels.labels). */
enum {
    PP_VOXEL_OUTSIDE = 0,
    PP_VOXEL_SOFT = 1,
    PP_VOXEL_BONE0 = 2 /**< bone of joint j is PP_VOXEL_BONE0 + j */
};

/** Limits on the grid (a larger grid is refused with a clear message). */
#define PP_VOXEL_MAX_COUNT ((size_t)400 * 1000 * 1000)
#define PP_VOXEL_MIN_SPACING 1e-4f /**< 0.1 mm */
#define PP_VOXEL_MAX_SPACING 1.0f  /**< 1 m */
/** Ties x triangles above which ties are taken as inside without the exact
 * winding number (a mesh that is mostly holes); about a second of work. */
#define PP_VOXEL_WINDING_BUDGET 2e9

/** What voxelization found and repaired. */
typedef struct pp_voxel_report {
    size_t total_voxels;          /**< nx * ny * nz */
    size_t body_voxels;           /**< label != 0 */
    size_t soft_voxels;           /**< label == 1 */
    size_t bone_voxels;           /**< label >= 2 */
    double body_volume;           /**< m^3, body_voxels * spacing^3 */
    double skin_volume;           /**< m^3, voxels inside the skin alone */
    size_t skin_boundary_edges;   /**< holes in the skin (0 for a closed skin) */
    size_t open_bone_meshes;      /**< bones with boundary or non-manifold edges */
    size_t bone_voxels_outside_skin; /**< promoted to body */
    size_t overlap_voxels;        /**< inside two or more bones (first bone kept) */
    size_t ambiguous_voxels;      /**< 3:3 ray ties settled by the winding number */
    size_t thin_bones;            /**< bones marked by their vertices only */
    size_t empty_joints;          /**< labels j < joint count with no bone voxel */
    double seconds;
} pp_voxel_report;

/**
 * Build the labelled voxel image.
 * @param skin        closed (or nearly closed) body surface, metres
 * @param bones       bone_count meshes (may be NULL when bone_count == 0)
 * @param bone_label  joint index j per bone (voxel label 2 + j); several
 *                    bones may share a joint
 * @param spacing     voxel edge, metres (1e-4 .. 1)
 * @param out         the image; the grid covers skin and bones plus one
 *                    outside voxel on every side. Free with pp_voxels_free().
 * @param report      optional (NULL): counts and repairs
 * @return POSE_OK, POSE_ERR_INVALID_ARGUMENT (bad spacing, empty mesh,
 *         non-finite coordinate, grid too large; message names the mesh),
 *         POSE_ERR_INVALID_DATA (a bone with no voxel inside the skin and
 *         most of its vertices outside the skin's bounding box grown by one
 *         voxel: wrong units or frame; message names the bone),
 *         POSE_ERR_OUT_OF_MEMORY.
 */
pose_status pp_voxelize(const pp_mesh *skin, const pp_mesh *bones, const uint16_t *bone_label,
                        size_t bone_count, float spacing, pp_voxels *out,
                        pp_voxel_report *report, char *err, size_t errlen);

/**
 * Inside test of one mesh on a grid (the building block of pp_voxelize,
 * exposed for tests and for extra tissues): inside[i] = 1 for every voxel
 * centre of the nx*ny*nz grid (origin = centre of voxel 0, x fastest) that
 * the mesh encloses. Returns the number of 3:3 ties through *ambiguous.
 */
pose_status pp_voxel_inside(const pp_mesh *m, const float origin[3], float spacing, int nx,
                            int ny, int nz, uint8_t *inside, size_t *ambiguous);

/** Label of the voxel containing point p (PP_VOXEL_OUTSIDE beyond the grid). */
uint16_t pp_voxels_sample(const pp_voxels *v, const float p[3]);

#endif /* POSE_PP_VOXELIZE_H */
