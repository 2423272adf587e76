/* SPDX-License-Identifier: Apache-2.0
 * Slices of a CT with its labels, coloured: intensities through a window
 * (grey), labels blended in a colour per id. One colouring for pose-volume's
 * slice PNGs, pose-render --slices and pose-view's slice plane. */
#ifndef POSE_EX_VOL_SLICES_H
#define POSE_EX_VOL_SLICES_H

#include <stddef.h>
#include <stdint.h>

/* The default window: soft tissue and bone both readable. */
#define EX_VOLUME_LEVEL 40.0f
#define EX_VOLUME_WIDTH 500.0f

/** The colour of one voxel: hu through the window [level - width/2,
 *  level + width/2] as grey (black when hu is NULL), averaged with the
 *  label's colour when the label is not 0. */
void ex_volume_voxel_rgb(const float *hu, const uint16_t *label, float level, float width,
                         unsigned char rgb[3]);

/** Slice `at` across `axis` of an n[0] x n[1] x n[2] image (x fastest) as
 *  RGB, one pixel per voxel, top row first: axis 2 (axial) has x right and
 *  y up, axis 1 (coronal) x right and z up, axis 0 (sagittal) y right and
 *  z up. *nu x *nv pixels are written to rgb. hu or labels may be NULL. */
void ex_volume_slice_rgb(const float *hu, const uint16_t *labels, const int n[3], int axis, int at,
                         float level, float width, unsigned char *rgb, int *nu, int *nv);

#endif
