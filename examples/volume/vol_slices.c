/* SPDX-License-Identifier: Apache-2.0 */
#include "vol_slices.h"

#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

typedef struct canvas {
    int w, h;
    unsigned char *rgb;
} canvas;

/* Paint one slice (u along a, v along b; v drawn upwards) at x offset ox,
 * each voxel scaled to su x sv pixels. */
static void paint(canvas *c, int ox, const float *hu, const uint16_t *lab, size_t base, size_t su_stride,
                  size_t sv_stride, int nu, int nv, int pu, int pv, float lo, float width)
{
    for (int y = 0; y < nv * pv; y++)
        for (int x = 0; x < nu * pu; x++) {
            int u = x / pu, v = nv - 1 - y / pv;
            size_t at = base + (size_t)u * su_stride + (size_t)v * sv_stride;
            float g = (hu[at] - lo) / width;
            g = g < 0 ? 0 : g > 1 ? 1 : g;
            unsigned char *px = c->rgb + 3 * ((size_t)y * c->w + ox + x);
            unsigned char grey = (unsigned char)(255 * g), col[3] = {grey, grey, grey};
            if (lab && lab[at]) {
                unsigned char lc[3];
                label_rgb(lab[at], lc);
                for (int k = 0; k < 3; k++)
                    col[k] = (unsigned char)((col[k] + lc[k]) / 2);
            }
            memcpy(px, col, 3);
        }
}

int ex_volume_slices_png(const char *path, const float *hu, const uint16_t *labels, int nx, int ny,
                         int nz, const double sp[3], int ci, int cj, int ck, float level, float width,
                         char *err, size_t n)
{
    /* Pixels per voxel so that each axis keeps its spacing (2 px per finest mm step). */
    double fine = sp[0] < sp[1] ? sp[0] : sp[1];
    fine = fine < sp[2] ? fine : sp[2];
    int px = (int)(2 * sp[0] / fine + 0.5), py = (int)(2 * sp[1] / fine + 0.5),
        pz = (int)(2 * sp[2] / fine + 0.5);
    const size_t sx = 1, sy = (size_t)nx, sz = (size_t)nx * ny;
    int wa = nx * px, ha = ny * py;  /* axial: x right, y up */
    int wc = nx * px, hc = nz * pz;  /* coronal: x, z */
    int ws = ny * py, hs = nz * pz;  /* sagittal: y, z */
    canvas c = {wa + wc + ws + 8, ha > hc ? (ha > hs ? ha : hs) : (hc > hs ? hc : hs), NULL};
    c.rgb = calloc((size_t)c.w * c.h * 3, 1);
    if (!c.rgb) {
        snprintf(err, n, "%s: out of memory", path);
        return -1;
    }
    float lo = level - width / 2;
    paint(&c, 0, hu, labels, (size_t)ck * sz, sx, sy, nx, ny, px, py, lo, width);
    paint(&c, wa + 4, hu, labels, (size_t)cj * sy, sx, sz, nx, nz, px, pz, lo, width);
    paint(&c, wa + wc + 8, hu, labels, (size_t)ci * sx, sy, sz, ny, nz, py, pz, lo, width);
    FILE *f = fopen(path, "wb");
    png_structp png = f ? png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL) : NULL;
    png_infop info = png ? png_create_info_struct(png) : NULL;
    volatile int rc = -1;
    if (info && !setjmp(png_jmpbuf(png))) {
        png_init_io(png, f);
        png_set_IHDR(png, info, (png_uint_32)c.w, (png_uint_32)c.h, 8, PNG_COLOR_TYPE_RGB,
                     PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
        png_write_info(png, info);
        for (int y = 0; y < c.h; y++)
            png_write_row(png, c.rgb + (size_t)y * c.w * 3);
        png_write_end(png, NULL);
        rc = 0;
    }
    if (png)
        png_destroy_write_struct(&png, info ? &info : NULL);
    if (f && fclose(f) != 0)
        rc = -1;
    if (rc)
        snprintf(err, n, "%s: cannot write the PNG", path);
    free(c.rgb);
    return rc;
}
