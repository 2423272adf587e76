/* SPDX-License-Identifier: Apache-2.0
 * Axial, coronal and sagittal slices (vol_slices.h) side by side in one
 * image: pose-volume's slice PNGs and pose-render --slices. */
#ifndef POSE_EX_VOL_SLICES_IMAGE_H
#define POSE_EX_VOL_SLICES_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#include "ex_image.h"

/** Gap in pixels between two slices of the image. */
#define EX_VOLUME_SLICE_GAP 4

/** Pixels per voxel along each axis: `zoom` pixels for the finest
 *  spacing, the others in proportion (each axis keeps its spacing). */
void ex_volume_slice_pixels(const double spacing[3], int zoom, int px[3]);

/** The largest zoom (at least 1) whose slices are at most `height` pixels tall. */
int ex_volume_slices_zoom(const int n[3], const double spacing[3], int height);

/**
 * The slices through voxel c of an n[0] x n[1] x n[2] image into a new
 * image (ex_image_free it), background `bg`: axial at x = 0, coronal after
 * it, sagittal last, EX_VOLUME_SLICE_GAP apart, all from the top row;
 * voxels drawn ex_volume_slice_pixels(spacing, zoom) wide. Returns 0 or -1
 * (out of memory).
 */
int ex_volume_slices_image(ex_image *out, const float *hu, const uint16_t *labels, const int n[3],
                           const double spacing[3], const int c[3], float level, float width,
                           int zoom, const uint8_t bg[4]);

/** ex_volume_slices_image at zoom 2 written as a PNG. Returns 0 or -1 (message in err). */
int ex_volume_slices_png(const char *path, const float *hu, const uint16_t *labels, const int n[3],
                         const double spacing[3], const int c[3], float level, float width,
                         char *err, size_t err_size);

#endif
