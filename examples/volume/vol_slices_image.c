/* SPDX-License-Identifier: Apache-2.0 */
#include "vol_slices_image.h"

#include <stdio.h>
#include <stdlib.h>

#include "vol_slices.h"

void ex_volume_slice_pixels(const double sp[3], int zoom, int px[3])
{
    double fine = sp[0] < sp[1] ? sp[0] : sp[1];
    fine = fine < sp[2] ? fine : sp[2];
    for (int a = 0; a < 3; a++)
        px[a] = (int)(zoom * sp[a] / fine + 0.5);
}

int ex_volume_slices_zoom(const int n[3], const double spacing[3], int height)
{
    int px[3];
    ex_volume_slice_pixels(spacing, 1, px);
    const int tall = n[1] * px[1] > n[2] * px[2] ? n[1] * px[1] : n[2] * px[2];
    return tall > 0 && height / tall > 1 ? height / tall : 1;
}

int ex_volume_slices_image(ex_image *out, const float *hu, const uint16_t *labels, const int n[3],
                           const double spacing[3], const int c[3], float level, float width,
                           int zoom, const uint8_t bg[4])
{
    int px[3];
    ex_volume_slice_pixels(spacing, zoom, px);
    /* axial (x, y), coronal (x, z), sagittal (y, z) */
    static const int axis[3] = {2, 1, 0}, ua[3] = {0, 0, 1}, va[3] = {1, 2, 2};
    int w = 2 * EX_VOLUME_SLICE_GAP, h = 0;
    for (int s = 0; s < 3; s++) {
        w += n[ua[s]] * px[ua[s]];
        h = n[va[s]] * px[va[s]] > h ? n[va[s]] * px[va[s]] : h;
    }
    int most = n[0] * n[1] > n[0] * n[2] ? n[0] * n[1] : n[0] * n[2];
    most = most > n[1] * n[2] ? most : n[1] * n[2];
    unsigned char *rgb = malloc(3 * (size_t)most);
    if (!rgb || ex_image_init(out, w, h, bg) < 0) {
        free(rgb);
        return -1;
    }
    for (int s = 0, x0 = 0; s < 3; s++) {
        int nu, nv;
        const int pu = px[ua[s]], pv = px[va[s]];
        ex_volume_slice_rgb(hu, labels, n, axis[s], c[axis[s]], level, width, rgb, &nu, &nv);
        for (int y = 0; y < nv * pv; y++)
            for (int x = 0; x < nu * pu; x++) {
                const unsigned char *from = rgb + 3 * ((size_t)(y / pv) * nu + x / pu);
                uint8_t *to = out->rgba + 4 * ((size_t)y * w + x0 + x);
                to[0] = from[0], to[1] = from[1], to[2] = from[2], to[3] = 255;
            }
        x0 += nu * pu + EX_VOLUME_SLICE_GAP;
    }
    free(rgb);
    return 0;
}

int ex_volume_slices_png(const char *path, const float *hu, const uint16_t *labels, const int n[3],
                         const double spacing[3], const int c[3], float level, float width,
                         char *err, size_t err_size)
{
    static const uint8_t black[4] = {0, 0, 0, 255};
    ex_image img;
    if (ex_volume_slices_image(&img, hu, labels, n, spacing, c, level, width, 2, black) < 0) {
        snprintf(err, err_size, "%s: out of memory", path);
        return -1;
    }
    int rc = ex_image_write_png(&img, path, err, err_size);
    ex_image_free(&img);
    return rc;
}
