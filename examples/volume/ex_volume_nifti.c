/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_volume_nifti.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <pose/volume.h>

#include "vol_nifti.h"

int ex_volume_nifti_available(void)
{
    return 1;
}

int ex_volume_write_nifti(const pose_state *state, const char *prefix, int pad, int *written,
                          char *err, size_t n)
{
    const pose_rig *rig = pose_state_rig(state);
    *written = 0;
    pose_rig_volume v;
    if (pose_rig_volume_count(rig) == 0 || pose_rig_get_volume(rig, 0, &v) != POSE_OK) {
        snprintf(err, n, "--nifti: the rig holds no scan (bake it with pose-bake --labels)");
        return -1;
    }
    pose_volume_grid g = v.grid;
    g.nx += 2u * (uint32_t)pad, g.ny += 2u * (uint32_t)pad, g.nz += 2u * (uint32_t)pad;
    for (int a = 0; a < 3; a++)
        g.affine[a][3] -= (float)pad * (g.affine[a][0] + g.affine[a][1] + g.affine[a][2]);
    pose_volume_desc rest = {v.grid, v.intensity, v.labels, -1024.0f, 0};
    size_t nv = (size_t)g.nx * g.ny * g.nz;
    float *hu = v.intensity ? malloc(nv * sizeof *hu) : NULL;
    uint16_t *lab = v.labels ? malloc(nv * sizeof *lab) : NULL;
    pv_image img;
    memset(&img, 0, sizeof img);
    img.data = malloc(nv * sizeof *img.data);
    pose_volume_sampler *s = NULL;
    int rc = -1;
    if ((v.intensity && !hu) || (v.labels && !lab) || !img.data) {
        snprintf(err, n, "--nifti: out of memory for %zu voxels", nv);
        goto done;
    }
    if (pose_volume_sampler_create(rig, &rest, &g, 0, NULL, &s) != POSE_OK ||
        pose_volume_sample(s, state, hu, lab) != POSE_OK) {
        snprintf(err, n, "--nifti: %s", pose_last_error());
        goto done;
    }
    /* Header: model (m; facing +X, left +Y, up +Z) back to RAS mm: x = -1000 y_m,
     * y = 1000 x_m, z = 1000 z_m. */
    img.nx = g.nx, img.ny = g.ny, img.nz = g.nz;
    for (int c = 0; c < 4; c++) {
        img.affine[0][c] = -1e3 * g.affine[1][c];
        img.affine[1][c] = 1e3 * g.affine[0][c];
        img.affine[2][c] = 1e3 * g.affine[2][c];
    }
    for (int c = 0; c < 3; c++) {
        double l2 = 0;
        for (int r = 0; r < 3; r++)
            l2 += img.affine[r][c] * img.affine[r][c];
        img.spacing[c] = l2 > 0 ? __builtin_sqrt(l2) : 1.0;
    }
    img.sform_code = img.qform_code = 1; /* scanner */
    img.xyz_units = 2;                   /* mm */
    img.nifti_version = 1;
    char path[1024];
    if (hu) {
        memcpy(img.data, hu, nv * sizeof *hu);
        snprintf(img.descrip, sizeof img.descrip, "pose-export: posed '%s'", v.name);
        snprintf(path, sizeof path, "%s_ct.nii.gz", prefix);
        if (pv_nifti_write(path, &img, 4 /* int16 */, err, n) != 0)
            goto done;
        ++*written;
    }
    if (lab) {
        for (size_t i = 0; i < nv; i++)
            img.data[i] = lab[i];
        img.intent_code = 1002; /* NIFTI_INTENT_LABEL */
        snprintf(img.intent_name, sizeof img.intent_name, "labels");
        snprintf(path, sizeof path, "%s_labels.nii.gz", prefix);
        if (pv_nifti_write(path, &img, 512 /* uint16 */, err, n) != 0)
            goto done;
        ++*written;
    }
    rc = 0;
done:
    pose_volume_sampler_free(s);
    free(hu), free(lab), free(img.data);
    return rc;
}
