/* SPDX-License-Identifier: Apache-2.0
 *
 * A 3-D scalar image as the tools hold it: float voxels, x fastest, and
 * the voxel -> world affine of its NIfTI header (millimetres, RAS+). The
 * header fields a tool must carry from input to output (units, intent,
 * description) travel with it.
 */
#ifndef POSE_VOL_IMAGE_H
#define POSE_VOL_IMAGE_H

#include <stddef.h>
#include <stdint.h>

/** Largest image the tools take (voxels); 2^31 keeps every index an int64
 *  product and a float image under 8 GiB. */
#define PV_MAX_VOXELS ((int64_t)1 << 31)

typedef struct pv_image {
    int64_t nx, ny, nz;    /**< voxels per axis (>= 1) */
    float *data;           /**< nx*ny*nz values (scl_slope/scl_inter applied), x fastest */
    double affine[3][4];   /**< voxel (i, j, k) centre -> world mm: sform, else qform, else pixdim */
    double spacing[3];     /**< pixdim[1..3] (mm when xyz_units is mm) */
    int affine_source;     /**< 2 sform, 1 qform, 0 neither (pixdim scaling only) */
    int sform_code, qform_code;
    int datatype;          /**< NIfTI DT_* code of the file (output keeps it by default) */
    int nifti_version;     /**< 1 or 2 */
    int xyz_units, time_units;
    int intent_code;
    char intent_name[16];
    char descrip[80];
} pv_image;

/** Free the voxels (the struct itself is the caller's). */
void pv_image_free(pv_image *img);

/** Voxel count nx*ny*nz. */
static inline size_t pv_image_voxels(const pv_image *img)
{
    return (size_t)img->nx * (size_t)img->ny * (size_t)img->nz;
}

/** A new image of the same grid and header as `like`, voxels set to `fill`.
 *  Returns 0, or -1 when out of memory. */
int pv_image_like(const pv_image *like, float fill, pv_image *out);

/** world = affine * (i, j, k, 1). */
void pv_image_voxel_to_world(const pv_image *img, const double ijk[3], double xyz[3]);

/** The inverse (i, j, k) of a world point; returns -1 for a singular affine. */
int pv_image_world_to_voxel(const pv_image *img, const double xyz[3], double ijk[3]);

/**
 * The rig model space of an image baked by pose-bake --labels: metres,
 * facing +X (anterior), left +Y, up +Z (the templates' convention), from
 * NIfTI's RAS+ millimetres: model = (y, -x, z) * 1e-3. out = that map
 * composed with the image's voxel -> world affine (voxel index -> model),
 * as pose_volume_grid and the bake use it.
 */
void pv_image_model_affine(const pv_image *img, double out[3][4]);

#endif /* POSE_VOL_IMAGE_H */
