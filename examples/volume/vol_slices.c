/* SPDX-License-Identifier: Apache-2.0 */
#include "vol_slices.h"

/* A label's colour: hue from the id (golden-angle steps), saturated. */
static void label_rgb(uint16_t id, unsigned char rgb[3])
{
    float h = (float)((id * 137.508) - 360.0 * (int)(id * 137.508 / 360.0)) / 60.0f;
    int i = (int)h;
    float f = h - (float)i, q = 1.0f - f;
    float r = 0, g = 0, b = 0;
    switch (i % 6) {
    case 0: r = 1, g = f; break;
    case 1: r = q, g = 1; break;
    case 2: g = 1, b = f; break;
    case 3: g = q, b = 1; break;
    case 4: r = f, b = 1; break;
    default: r = 1, b = q; break;
    }
    rgb[0] = (unsigned char)(255 * r), rgb[1] = (unsigned char)(255 * g), rgb[2] = (unsigned char)(255 * b);
}

void ex_volume_voxel_rgb(const float *hu, const uint16_t *label, float level, float width,
                         unsigned char rgb[3])
{
    float g = hu ? (*hu - (level - width / 2)) / width : 0.0f;
    g = g < 0 ? 0 : g > 1 ? 1 : g;
    const unsigned char grey = (unsigned char)(255 * g);
    rgb[0] = rgb[1] = rgb[2] = grey;
    if (label && *label) {
        unsigned char lc[3];
        label_rgb(*label, lc);
        for (int k = 0; k < 3; k++)
            rgb[k] = (unsigned char)((grey + lc[k]) / 2);
    }
}

void ex_volume_slice_rgb(const float *hu, const uint16_t *labels, const int n[3], int axis, int at,
                         float level, float width, unsigned char *rgb, int *nu, int *nv)
{
    const size_t stride[3] = {1, (size_t)n[0], (size_t)n[0] * (size_t)n[1]};
    const int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2; /* axes along u and v */
    *nu = n[ua], *nv = n[va];
    for (int y = 0; y < n[va]; y++)
        for (int u = 0; u < n[ua]; u++) {
            const size_t v = (size_t)at * stride[axis] + (size_t)u * stride[ua] +
                             (size_t)(n[va] - 1 - y) * stride[va];
            ex_volume_voxel_rgb(hu ? hu + v : NULL, labels ? labels + v : NULL, level, width,
                                rgb + 3 * ((size_t)y * n[ua] + u));
        }
}
