/* SPDX-License-Identifier: Apache-2.0
 *
 * Drawing a posed scene with legacy OpenGL (1.1 vertex arrays, fixed-function
 * lighting): the same code runs in the GLFW viewer and under OSMesa, whose
 * software rasterizer offers exactly this profile everywhere.
 */
#ifndef POSE_EX_DRAW_H
#define POSE_EX_DRAW_H

#include "ex_camera.h"
#include "ex_scene.h"

/**
 * Clear the framebuffer to the background and draw the scene's visible
 * tissues (opaque ones first, then the skin, translucent when the scene says
 * so), or the tet boundary coloured by a joint's weight when
 * sc->weight_joint >= 0, into the viewport (x, y, width, height) in GL
 * pixels (origin bottom left).
 */
void ex_draw_scene(ex_scene *sc, const ex_camera *cam, int x, int y, int width, int height, const float bg[3]);

/** Joint centres as points (the selected one larger and yellow), over everything. */
void ex_draw_joints(const ex_scene *sc, int selected);

/** Text in window pixels, top-left origin, with the built-in font. */
void ex_draw_text(int x, int y, int scale, const float rgba[4], const char *text, int width, int height);

#endif
