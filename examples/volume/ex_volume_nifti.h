/* SPDX-License-Identifier: Apache-2.0
 * pose-export --nifti: the rig's stored scan (its volumes section, written
 * by pose-bake --labels) posed as the state is, as NIfTI files. */
#ifndef POSE_EX_VOLUME_NIFTI_H
#define POSE_EX_VOLUME_NIFTI_H

#include <stddef.h>

#include <pose/pose.h>

/** 1 when this build writes NIfTI (libnifti2-dev was found). */
int ex_volume_nifti_available(void);

/**
 * Pose the rig's first rest image with `state` (after pose_apply) onto its
 * own grid grown by `pad` voxels per side, and write PREFIX_ct.nii.gz
 * (intensities, int16 HU) and/or PREFIX_labels.nii.gz (uint16, intent
 * "label"), millimetres, sform and qform in the scan's RAS (the inverse of
 * pose-bake's model space). *written: files written. Returns 0 or -1 with a
 * message (a rig without a volumes section says so).
 */
int ex_volume_write_nifti(const pose_state *state, const char *prefix, int pad, int *written,
                          char *err, size_t err_size);

#endif
