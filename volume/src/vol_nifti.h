/* SPDX-License-Identifier: Apache-2.0
 *
 * NIfTI-1 and NIfTI-2 (.nii, .nii.gz; .hdr/.img pairs too) through
 * nifticlib. Every real scalar datatype reads (uint8 .. float64, int64 and
 * uint64 included: segmentations often come as float64); complex and RGB
 * images are refused by name. The header is checked field by field before
 * nifticlib reads the voxels, so a damaged file gives one message naming
 * the file and the field, never a crash or a huge allocation:
 *   sizeof_hdr and magic; dim[0] 1..7, dim[1..3] >= 1, dims above 3 equal
 *   to 1 (one 3-D volume), no overflow of the voxel count past
 *   PV_MAX_VOXELS; datatype known and scalar, bitpix matching it;
 *   vox_offset at or past the header, a single file long enough for
 *   vox_offset + data (uncompressed); pixdim[1..3] finite and > 0;
 *   scl_slope/scl_inter finite; the sform rows finite when sform_code > 0,
 *   quaternion finite when qform_code > 0.
 */
#ifndef POSE_VOL_NIFTI_H
#define POSE_VOL_NIFTI_H

#include "vol_image.h"

/** Read a 3-D NIfTI image. Returns 0, or -1 with a message that names the
 *  file and the field in err. On failure *out is zeroed. */
int pv_nifti_read(const char *path, pv_image *out, char *err, size_t err_size);

/** Check a header only (what pv_nifti_read checks before the voxels are
 *  read); the exact header bytes are given, `name` is used in messages and
 *  `file_size`, the size of the file that holds the voxels (the .nii, or a
 *  pair's .img; -1 when unknown, e.g. compressed), bounds the data.
 *  Returns the NIfTI version (1 or 2), or -1 with a message. */
int pv_nifti_check_header(const unsigned char *hdr, size_t hdr_len, const char *name,
                          long long file_size, char *err, size_t err_size);

/** Write img (grid, affine, units, intent, description of `img`) as NIfTI.
 *  datatype: NIfTI DT_* code for the file (0 = img->datatype, or float32
 *  when that is 0); integer datatypes round to nearest and clamp. The
 *  version is img->nifti_version (2 writes NIfTI-2; anything else NIfTI-1);
 *  a name ending in .gz is compressed. sform and qform both carry the
 *  affine (qform from its rotation part; codes from img, or 1 "scanner"
 *  when img has none). Returns 0, or -1 with a message. */
int pv_nifti_write(const char *path, const pv_image *img, int datatype, char *err,
                   size_t err_size);

#endif /* POSE_VOL_NIFTI_H */
