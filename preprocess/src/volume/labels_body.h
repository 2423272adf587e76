/* SPDX-License-Identifier: Apache-2.0
 * Voxel operations of pose-bake --labels: the body mask, the femoral head
 * sphere. Grids are nx*ny*nz, x fastest, z the axial (slice) axis. */
#ifndef POSE_PP_LABELS_BODY_H
#define POSE_PP_LABELS_BODY_H

#include <stddef.h>
#include <stdint.h>

/** Keep the largest 6-connected region of mask (others set to 0); returns
 *  the voxels removed, or (size_t)-1 when out of memory. */
size_t pp_mask_largest_component(uint8_t *mask, int nx, int ny, int nz);

/** Fill each z slice's background that its border cannot reach
 *  (4-connected); returns the voxels filled, or (size_t)-1. */
size_t pp_mask_fill_slices(uint8_t *mask, int nx, int ny, int nz);

/**
 * Least-squares sphere through the centres of the voxels of label `a` that
 * have a 6-neighbour outside `a` and lie within `reach_mm` of a voxel of
 * label `b` (the femoral head against the acetabulum). Distances use
 * `spacing_mm`; the centre is returned in voxel index coordinates.
 * Returns the points used (0 when fewer than 10: no sphere).
 */
size_t pp_fit_contact_sphere(const uint16_t *labels, int nx, int ny, int nz,
                             const double spacing_mm[3], uint16_t a, uint16_t b, double reach_mm,
                             double centre_ijk[3], double *radius_mm);

#endif /* POSE_PP_LABELS_BODY_H */
