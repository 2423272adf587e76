/* SPDX-License-Identifier: Apache-2.0
 *
 * A tiny built-in 5x7 bitmap font for captions and the viewer's HUD, so the
 * examples need no font library or font file. Lower case is drawn as upper
 * case; characters without a glyph are drawn as '?'.
 */
#ifndef POSE_EX_FONT_H
#define POSE_EX_FONT_H

#include <stdint.h>

enum { EX_FONT_W = 5, EX_FONT_H = 7, EX_FONT_ADVANCE = 6 };

/** Rows of character c, top row first; bit 4 of each row is the leftmost pixel. */
const uint8_t *ex_font_glyph(char c);

/** Width in font pixels of a string drawn at scale 1. */
int ex_font_text_width(const char *text);

#endif
