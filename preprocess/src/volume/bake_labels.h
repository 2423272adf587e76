/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-bake --labels: a patient from a labelled CT or MRI (NIfTI). The
 * label image replaces the meshes a bake starts from:
 *   - body: non-background labels plus, with a CT, voxels above an HU
 *     threshold; the largest connected region is kept (the scanner table
 *     and anything else apart from the patient go), and each axial slice's
 *     enclosed background is filled (gas in the bowel, the lungs' air);
 *   - bones: the labels the template names (file stems = label names);
 *     template joints none of whose bones is in the image are dropped,
 *     with their descendants (segments outside the field of view);
 *   - other labels: organs and muscles, embedded as tissues;
 * each becomes a surface (label_surface.h) in the rig's model space
 * (pv_image_model_affine: metres, facing +X, left +Y, up +Z), written as
 * OBJ into a scratch folder with a filtered template, and the ordinary
 * bake (pp_bake) runs on them: the same voxelization, tets, weights,
 * mapping and CoR as a mesh bake.
 * The femoral heads are also fitted directly on the voxels (least-squares
 * sphere of the femur's boundary voxels within 12 mm of the hip bone) as an
 * independent check of the hip joints, reported in --json.
 */
#ifndef POSE_PP_BAKE_LABELS_H
#define POSE_PP_BAKE_LABELS_H

#include <stddef.h>

#include "bake_pipeline.h"

#define PP_LABELS_DEFAULT_HU (-500.0)
#define PP_LABELS_DEFAULT_SMOOTH 8
#define PP_LABELS_MIN_VOXELS 20 /**< smaller labels are not made tissues */

typedef struct pp_labels_options {
    const char *labels_path;   /**< NIfTI label image (any datatype, integer values) */
    const char *names_path;    /**< JSON {"id": "name", ...} */
    const char *volume_path;   /**< optional CT/MRI on the same grid */
    const char *template_path;
    double hu_threshold;       /**< body threshold with a CT; 0 = PP_LABELS_DEFAULT_HU */
    int smooth;                /**< Taubin iterations; 0 = default, < 0 none */
} pp_labels_options;

typedef struct pp_labels_head {
    char joint[PP_NAME_MAX], label[PP_NAME_MAX];
    double centre_model[3];    /**< sphere centre, model space (m) */
    double centre_ras_mm[3];   /**< the same in the image's world (RAS mm) */
    double radius_mm;
    size_t points;
} pp_labels_head;

typedef struct pp_labels_report {
    char work_dir[256];
    char skin_path[320], template_path[320];
    char **bone_paths, **organ_paths;
    size_t bone_count, organ_count;
    int dims[3];
    double spacing_mm[3];
    size_t body_voxels, labelled_voxels, removed_voxels, filled_voxels;
    size_t label_count;        /**< distinct labels in the image */
    char absent_joints[512];   /**< template joints dropped (comma-separated) */
    pp_labels_head heads[8];
    size_t head_count;
    /* The rest image stored in the rig (the volumes section): model-space grid,
     * the CT's intensities (with --volume) and the labels. */
    struct pose_rig_volume *volume; /* one entry, or NULL */
    float *volume_intensity;
    uint16_t *volume_labels;
} pp_labels_report;

/**
 * Read the images, build the surfaces and the filtered template into a new
 * scratch folder, and point `bake`'s skin, bones, organs and template at
 * them (pp_bake can then run), and the scan itself (labels, and the CT
 * with --volume) as the rig's rest image `scan` (the volumes section, on
 * the scan's grid in model space). Returns 0 or a negative pose_status with a
 * message naming the file. Call pp_labels_cleanup in any case.
 */
int pp_labels_prepare(const pp_labels_options *o, pp_bake_options *bake, pp_labels_report *r,
                      char *err, size_t err_size);

/** Remove the scratch folder and free the report's lists. */
void pp_labels_cleanup(pp_labels_report *r);

/** The bake's JSON text with a "volume" object added (femoral heads, body
 *  figures, each hip's distance to its sphere); caller frees. NULL on
 *  failure. */
char *pp_labels_report_json(const char *bake_json, const pp_labels_report *r,
                            const pp_bake_report *bake);

#endif /* POSE_PP_BAKE_LABELS_H */
