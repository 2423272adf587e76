/* SPDX-License-Identifier: Apache-2.0
 * The scan a rig stores (pose-bake --labels: its volumes section) posed as
 * a state is, on its own grid: what pose-render --slices and pose-view's
 * slice plane show. libpose only (no NIfTI). */
#ifndef POSE_EX_VOLUME_POSED_H
#define POSE_EX_VOLUME_POSED_H

#include <stddef.h>
#include <stdint.h>

#include <pose/pose.h>
#include <pose/volume.h>

typedef struct ex_volume_posed {
    pose_volume_sampler *sampler;
    pose_volume_grid grid;  /* the rest image's grid (model space) */
    int n[3];               /* voxels per axis */
    double spacing[3];      /* voxel edge per axis, model units */
    float *hu;              /* posed intensities, or NULL (the scan has none) */
    uint16_t *labels;       /* posed labels, or NULL */
} ex_volume_posed;

/** Set up v for the rig's first scan (threads as pose_volume_sampler_create).
 *  Returns 0, or -1 with a message (a rig without a scan says so). */
int ex_volume_posed_open(ex_volume_posed *v, const pose_rig *rig, int threads, char *err,
                         size_t err_size);

/** Pose the scan as `state` is (after pose_apply). Returns 0 or -1 with a message. */
int ex_volume_posed_update(ex_volume_posed *v, const pose_state *state, char *err, size_t err_size);

/** The voxel index nearest to model-space point p, clamped to the grid. */
void ex_volume_posed_index(const ex_volume_posed *v, const float p[3], int c[3]);

void ex_volume_posed_close(ex_volume_posed *v);

#endif
