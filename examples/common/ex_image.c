/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_image.h"

#include <errno.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ex_font.h"

int ex_image_init(ex_image *img, int width, int height, const uint8_t rgba[4])
{
    img->width = width;
    img->height = height;
    img->rgba = malloc((size_t)width * (size_t)height * 4);
    if (!img->rgba)
        return -1;
    ex_image_fill(img, rgba);
    return 0;
}

void ex_image_fill(ex_image *img, const uint8_t rgba[4])
{
    for (size_t i = 0; i < (size_t)img->width * (size_t)img->height; i++)
        memcpy(img->rgba + 4 * i, rgba, 4);
}

void ex_image_free(ex_image *img)
{
    free(img->rgba);
    img->rgba = NULL;
    img->width = img->height = 0;
}

void ex_image_blit(ex_image *dst, const ex_image *src, int x, int y)
{
    for (int row = 0; row < src->height; row++) {
        int dy = y + row;
        if (dy < 0 || dy >= dst->height)
            continue;
        int x0 = x < 0 ? -x : 0;
        int x1 = src->width;
        if (x + x1 > dst->width)
            x1 = dst->width - x;
        if (x1 <= x0)
            continue;
        memcpy(dst->rgba + ((size_t)dy * (size_t)dst->width + (size_t)(x + x0)) * 4,
               src->rgba + ((size_t)row * (size_t)src->width + (size_t)x0) * 4, (size_t)(x1 - x0) * 4);
    }
}

void ex_image_downsample_flip(ex_image *dst, const uint8_t *src, int factor)
{
    size_t sw = (size_t)dst->width * (size_t)factor;
    size_t sh = (size_t)dst->height * (size_t)factor;
    unsigned n = (unsigned)(factor * factor);
    for (int y = 0; y < dst->height; y++) {
        size_t sy0 = sh - (size_t)(y + 1) * (size_t)factor; /* bottom-up source */
        for (int x = 0; x < dst->width; x++) {
            unsigned acc[4] = {0, 0, 0, 0};
            for (int j = 0; j < factor; j++) {
                const uint8_t *p = src + ((sy0 + (size_t)j) * sw + (size_t)x * (size_t)factor) * 4;
                for (int i = 0; i < factor; i++, p += 4)
                    for (int c = 0; c < 4; c++)
                        acc[c] += p[c];
            }
            uint8_t *d = dst->rgba + ((size_t)y * (size_t)dst->width + (size_t)x) * 4;
            for (int c = 0; c < 4; c++)
                d[c] = (uint8_t)((acc[c] + n / 2) / n);
        }
    }
}

void ex_image_text(ex_image *img, int x, int y, int scale, const uint8_t rgba[4], const char *text)
{
    for (const char *c = text; *c; c++, x += EX_FONT_ADVANCE * scale) {
        const uint8_t *g = ex_font_glyph(*c);
        for (int row = 0; row < EX_FONT_H; row++)
            for (int col = 0; col < EX_FONT_W; col++) {
                if (!(g[row] & (0x10 >> col)))
                    continue;
                for (int sy = 0; sy < scale; sy++)
                    for (int sx = 0; sx < scale; sx++) {
                        int px = x + col * scale + sx, py = y + row * scale + sy;
                        if (px >= 0 && py >= 0 && px < img->width && py < img->height)
                            memcpy(img->rgba + ((size_t)py * (size_t)img->width + (size_t)px) * 4, rgba, 4);
                    }
            }
    }
}

int ex_image_write_png(const ex_image *img, const char *path, char *err, size_t err_size)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        snprintf(err, err_size, "%s: cannot create: %s", path, strerror(errno));
        return -1;
    }
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    png_bytep *rows = malloc(sizeof *rows * (size_t)img->height);
    if (!png || !info || !rows) {
        snprintf(err, err_size, "%s: out of memory", path);
        png_destroy_write_struct(&png, &info);
        free(rows);
        fclose(f);
        return -1;
    }
    /* libpng reports errors by longjmp; everything it touches is set up above. */
    if (setjmp(png_jmpbuf(png))) {
        snprintf(err, err_size, "%s: libpng failed to write the image", path);
        png_destroy_write_struct(&png, &info);
        free(rows);
        fclose(f);
        return -1;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)img->width, (png_uint_32)img->height, 8, PNG_COLOR_TYPE_RGB_ALPHA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 9);
    for (int y = 0; y < img->height; y++)
        rows[y] = img->rgba + (size_t)y * (size_t)img->width * 4;
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    free(rows);
    if (fclose(f) != 0) {
        snprintf(err, err_size, "%s: write failed: %s", path, strerror(errno));
        return -1;
    }
    return 0;
}
