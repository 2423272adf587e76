/* SPDX-License-Identifier: Apache-2.0
 * Axial, coronal and sagittal slices of a CT with its labels as one PNG:
 * intensities through a window (grey), labels blended in colours. */
#ifndef POSE_EX_VOL_SLICES_H
#define POSE_EX_VOL_SLICES_H

#include <stddef.h>
#include <stdint.h>

/** Write the three slices through voxel (ci, cj, ck) of an nx*ny*nz image
 *  (x fastest; spacing per axis, for the aspect) side by side to a PNG.
 *  labels may be NULL. Returns 0 or -1 (message in err). */
int ex_volume_slices_png(const char *path, const float *hu, const uint16_t *labels, int nx, int ny,
                         int nz, const double spacing[3], int ci, int cj, int ck, float level,
                         float width, char *err, size_t err_size);

#endif
