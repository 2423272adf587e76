/* SPDX-License-Identifier: Apache-2.0
 *
 * RGBA8 images in memory: what the renderer reads back from OSMesa, composes
 * into panels, captions with the built-in font and writes as PNG (libpng).
 * Rows are stored top row first.
 */
#ifndef POSE_EX_IMAGE_H
#define POSE_EX_IMAGE_H

#include <stddef.h>
#include <stdint.h>

typedef struct ex_image {
    int width, height;
    uint8_t *rgba; /* width * height * 4 bytes, top row first */
} ex_image;

/** Allocate a width x height image filled with one colour; 0 or -1 (out of memory). */
int ex_image_init(ex_image *img, int width, int height, const uint8_t rgba[4]);
void ex_image_free(ex_image *img);
/** Set every pixel to one colour. */
void ex_image_fill(ex_image *img, const uint8_t rgba[4]);

/** Copy src into dst with its top-left corner at (x, y), clipped to dst. */
void ex_image_blit(ex_image *dst, const ex_image *src, int x, int y);

/**
 * Box-filter a bottom-up framebuffer of (width*factor) x (height*factor)
 * pixels down into dst (width x height, top row first): the renderer draws
 * at a higher resolution for anti-aliasing because OSMesa has no multisampling.
 */
void ex_image_downsample_flip(ex_image *dst, const uint8_t *src_bottom_up, int factor);

/** Draw text with its top-left corner at (x, y); each font pixel is scale x scale. */
void ex_image_text(ex_image *img, int x, int y, int scale, const uint8_t rgba[4], const char *text);

/** Write as PNG (8-bit RGBA). Returns 0, or -1 with a message naming the file in err. */
int ex_image_write_png(const ex_image *img, const char *path, char *err, size_t err_size);

#endif
