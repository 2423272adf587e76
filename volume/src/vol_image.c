/* SPDX-License-Identifier: Apache-2.0 */
#include "vol_image.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void pv_image_free(pv_image *img)
{
    if (!img)
        return;
    free(img->data);
    img->data = NULL;
}

int pv_image_like(const pv_image *like, float fill, pv_image *out)
{
    *out = *like;
    size_t n = pv_image_voxels(like);
    out->data = malloc((n ? n : 1) * sizeof *out->data);
    if (!out->data)
        return -1;
    for (size_t i = 0; i < n; i++)
        out->data[i] = fill;
    return 0;
}

void pv_image_voxel_to_world(const pv_image *img, const double ijk[3], double xyz[3])
{
    for (int r = 0; r < 3; r++)
        xyz[r] = img->affine[r][0] * ijk[0] + img->affine[r][1] * ijk[1] +
                 img->affine[r][2] * ijk[2] + img->affine[r][3];
}

int pv_image_world_to_voxel(const pv_image *img, const double xyz[3], double ijk[3])
{
    const double (*a)[4] = img->affine;
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                 a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                 a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (!(fabs(det) > 1e-300))
        return -1;
    double d[3] = {xyz[0] - a[0][3], xyz[1] - a[1][3], xyz[2] - a[2][3]};
    double inv[3][3] = {
        {a[1][1] * a[2][2] - a[1][2] * a[2][1], a[0][2] * a[2][1] - a[0][1] * a[2][2],
         a[0][1] * a[1][2] - a[0][2] * a[1][1]},
        {a[1][2] * a[2][0] - a[1][0] * a[2][2], a[0][0] * a[2][2] - a[0][2] * a[2][0],
         a[0][2] * a[1][0] - a[0][0] * a[1][2]},
        {a[1][0] * a[2][1] - a[1][1] * a[2][0], a[0][1] * a[2][0] - a[0][0] * a[2][1],
         a[0][0] * a[1][1] - a[0][1] * a[1][0]}};
    for (int r = 0; r < 3; r++)
        ijk[r] = (inv[r][0] * d[0] + inv[r][1] * d[1] + inv[r][2] * d[2]) / det;
    return 0;
}

void pv_image_model_affine(const pv_image *img, double out[3][4])
{
    for (int c = 0; c < 4; c++) {
        out[0][c] = 1e-3 * img->affine[1][c];
        out[1][c] = -1e-3 * img->affine[0][c];
        out[2][c] = 1e-3 * img->affine[2][c];
    }
}
