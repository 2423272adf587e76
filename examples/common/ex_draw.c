/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_draw.h"

#include <GL/gl.h>

#include "ex_font.h"

static void ex_lights(void)
{
    /* Lights are placed with an identity modelview, so they follow the camera. */
    const GLfloat key[4] = {0.35f, 0.45f, 1.0f, 0.0f}, fill[4] = {-0.6f, -0.2f, 0.4f, 0.0f};
    const GLfloat key_col[4] = {0.85f, 0.85f, 0.85f, 1.0f}, fill_col[4] = {0.3f, 0.3f, 0.35f, 1.0f};
    const GLfloat ambient[4] = {0.22f, 0.22f, 0.22f, 1.0f}, spec[4] = {0.25f, 0.25f, 0.25f, 1.0f};
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glLightfv(GL_LIGHT0, GL_POSITION, key);
    glLightfv(GL_LIGHT0, GL_DIFFUSE, key_col);
    glLightfv(GL_LIGHT0, GL_SPECULAR, spec);
    glLightfv(GL_LIGHT1, GL_POSITION, fill);
    glLightfv(GL_LIGHT1, GL_DIFFUSE, fill_col);
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);
    /* Surfaces of scanned anatomy are not always closed or consistently wound. */
    glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);
    glEnable(GL_LIGHTING);
    glEnable(GL_LIGHT0);
    glEnable(GL_LIGHT1);
    glEnable(GL_COLOR_MATERIAL);
    glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
    const GLfloat mspec[4] = {0.3f, 0.3f, 0.3f, 1.0f};
    glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, mspec);
    glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, 24.0f);
}

static void ex_draw_tissue(const ex_scene *sc, int t)
{
    pose_tissue_info ti;
    size_t n;
    if (pose_rig_tissue_info(sc->rig, t, &ti) < 0 || ti.triangle_count == 0)
        return;
    const float *p = pose_tissue_positions(sc->state, t, &n);
    const float *nr = pose_tissue_normals(sc->state, t, &n);
    if (!p || !nr)
        return;
    glVertexPointer(3, GL_FLOAT, 0, p);
    glNormalPointer(GL_FLOAT, 0, nr);
    glDrawElements(GL_TRIANGLES, (GLsizei)(3 * ti.triangle_count), GL_UNSIGNED_INT, ti.triangles);
}

static void ex_draw_weights(ex_scene *sc)
{
    size_t nv;
    const float *p = pose_tet_positions(sc->state, &nv);
    if (!p || !sc->boundary)
        return;
    ex_scene_update_boundary_normals(sc);
    glVertexPointer(3, GL_FLOAT, 0, p);
    glNormalPointer(GL_FLOAT, 0, sc->boundary_normals);
    /* Colour per vertex: immediate mode keeps this path free of extra buffers. */
    glBegin(GL_TRIANGLES);
    for (size_t f = 0; f < sc->boundary_count; f++)
        for (int k = 0; k < 3; k++) {
            uint32_t v = sc->boundary[3 * f + (size_t)k];
            float rgb[3];
            ex_weight_color(sc->vertex_weight[v], rgb);
            glColor3fv(rgb);
            glArrayElement((GLint)v);
        }
    glEnd();
}

void ex_draw_scene(ex_scene *sc, const ex_camera *cam, int x, int y, int width, int height, const float bg[3])
{
    float view[16], proj[16];
    float aspect = height > 0 ? (float)width / (float)height : 1.0f;
    glViewport(x, y, width, height);
    glClearColor(bg[0], bg[1], bg[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    ex_lights();
    ex_camera_projection(cam, aspect, proj);
    ex_camera_view(cam, view);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixf(proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixf(view);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_NORMAL_ARRAY);

    if (sc->weight_joint >= 0) {
        ex_draw_weights(sc);
    } else {
        float rgba[4];
        int translucent = ex_scene_skin_translucent(sc);
        for (size_t t = 0; t < sc->tissue_count; t++) {
            pose_tissue_info ti;
            if (!sc->tissue_visible[t] || pose_rig_tissue_info(sc->rig, (int)t, &ti) < 0)
                continue;
            if (ti.kind == POSE_TISSUE_SKIN && (translucent || sc->skin_mode == EX_SKIN_HIDDEN))
                continue;
            ex_scene_tissue_color(ti.kind, rgba);
            glColor4f(rgba[0], rgba[1], rgba[2], 1.0f);
            ex_draw_tissue(sc, (int)t);
        }
        if (translucent && sc->skin_mode != EX_SKIN_HIDDEN) {
            /* Back faces, then front faces, without writing depth: a closed
             * translucent surface over what is inside, without sorting. */
            glEnable(GL_BLEND);
            glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
            glDepthMask(GL_FALSE);
            glEnable(GL_CULL_FACE);
            for (int pass = 0; pass < 2; pass++) {
                glCullFace(pass == 0 ? GL_FRONT : GL_BACK);
                for (size_t t = 0; t < sc->tissue_count; t++) {
                    pose_tissue_info ti;
                    if (!sc->tissue_visible[t] || pose_rig_tissue_info(sc->rig, (int)t, &ti) < 0 ||
                        ti.kind != POSE_TISSUE_SKIN)
                        continue;
                    ex_scene_tissue_color(ti.kind, rgba);
                    glColor4fv(rgba);
                    ex_draw_tissue(sc, (int)t);
                }
            }
            glDisable(GL_CULL_FACE);
            glDepthMask(GL_TRUE);
            glDisable(GL_BLEND);
        }
    }
    glDisableClientState(GL_NORMAL_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
}

void ex_draw_joints(const ex_scene *sc, int selected)
{
    glDisable(GL_LIGHTING);
    glDisable(GL_DEPTH_TEST);
    for (int pass = 0; pass < 2; pass++) {
        glPointSize(pass == 0 ? 5.0f : 9.0f);
        glBegin(GL_POINTS);
        for (size_t j = 0; j < pose_rig_joint_count(sc->rig); j++) {
            pose_transform x;
            if ((pass == 1) != ((int)j == selected) || pose_joint_world(sc->state, (int)j, &x) < 0)
                continue;
            if (pass == 1)
                glColor3f(1.0f, 0.9f, 0.1f);
            else
                glColor3f(0.2f, 0.45f, 0.9f);
            glVertex3fv(x.translation);
        }
        glEnd();
    }
    glEnable(GL_DEPTH_TEST);
}

void ex_draw_text(int x, int y, int scale, const float rgba[4], const char *text, int width, int height)
{
    glDisable(GL_LIGHTING);
    glDisable(GL_DEPTH_TEST);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glOrtho(0.0, (double)width, (double)height, 0.0, -1.0, 1.0);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glColor4fv(rgba);
    glBegin(GL_QUADS);
    for (const char *c = text; *c; c++, x += EX_FONT_ADVANCE * scale) {
        const uint8_t *g = ex_font_glyph(*c);
        for (int row = 0; row < EX_FONT_H; row++)
            for (int col = 0; col < EX_FONT_W; col++) {
                if (!(g[row] & (0x10 >> col)))
                    continue;
                float px = (float)(x + col * scale), py = (float)(y + row * scale), s = (float)scale;
                glVertex2f(px, py);
                glVertex2f(px + s, py);
                glVertex2f(px + s, py + s);
                glVertex2f(px, py + s);
            }
    }
    glEnd();
    glEnable(GL_DEPTH_TEST);
}
