/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_slice_plane.h"

#include <GL/gl.h>
#include <stdlib.h>
#include <string.h>

#include "vol_slices.h"

const char *ex_slice_plane_name(int axis)
{
    static const char *names[3] = {"sagittal", "coronal", "axial"};
    return axis >= 0 && axis < 3 ? names[axis] : "off";
}

int ex_slice_plane_parse(const char *name)
{
    for (int a = -1; a < 3; a++)
        if (!strcmp(name, ex_slice_plane_name(a)))
            return a;
    return -2;
}

int ex_slice_plane_show(ex_slice_plane *p, const ex_volume_posed *v, int axis)
{
    if (axis >= 0 && !p->rgb) {
        const int *n = v->n;
        size_t most = (size_t)n[0] * n[1];
        most = (size_t)n[0] * n[2] > most ? (size_t)n[0] * n[2] : most;
        most = (size_t)n[1] * n[2] > most ? (size_t)n[1] * n[2] : most;
        if (!(p->rgb = malloc(3 * most)))
            return -1;
    }
    p->axis = axis;
    p->index = axis >= 0 ? v->n[axis] / 2 : 0;
    return 0;
}

int ex_slice_plane_cycle(ex_slice_plane *p, const ex_volume_posed *v)
{
    return ex_slice_plane_show(p, v, p->axis == 0 ? -1 : p->axis < 0 ? 2 : p->axis - 1);
}

void ex_slice_plane_move(ex_slice_plane *p, const ex_volume_posed *v, int step)
{
    if (p->axis < 0)
        return;
    int i = p->index + step, n = v->n[p->axis];
    p->index = i < 0 ? 0 : i >= n ? n - 1 : i;
}

/* Model-space point of voxel index (i, j, k) (fractional: the grid's edges are at -0.5, n - 0.5). */
static void model_point(const ex_volume_posed *v, const double idx[3], float out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = (float)(v->grid.affine[r][0] * idx[0] + v->grid.affine[r][1] * idx[1] +
                         v->grid.affine[r][2] * idx[2] + v->grid.affine[r][3]);
}

void ex_slice_plane_draw(ex_slice_plane *p, const ex_volume_posed *v)
{
    if (p->axis < 0)
        return;
    int nu, nv;
    ex_volume_slice_rgb(v->hu, v->labels, v->n, p->axis, p->index, EX_VOLUME_LEVEL, EX_VOLUME_WIDTH, p->rgb,
                        &nu, &nv);
    p->labelled_texels = 0;
    for (size_t t = 0; t < (size_t)nu * nv; t++)
        p->labelled_texels += p->rgb[3 * t] != p->rgb[3 * t + 1] || p->rgb[3 * t + 1] != p->rgb[3 * t + 2];
    if (!p->texture)
        glGenTextures(1, &p->texture);
    glBindTexture(GL_TEXTURE_2D, p->texture);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, nu, nv, 0, GL_RGB, GL_UNSIGNED_BYTE, p->rgb);
    /* The slice's u and v axes as in ex_volume_slice_rgb; texel rows run
     * from the top (v = n - 1) down. */
    const int ua = p->axis == 0 ? 1 : 0, va = p->axis == 2 ? 1 : 2;
    static const double cu[4] = {0, 1, 1, 0}, cv[4] = {0, 0, 1, 1};
    glDisable(GL_LIGHTING);
    glEnable(GL_TEXTURE_2D);
    glColor3f(1.0f, 1.0f, 1.0f);
    glBegin(GL_QUADS);
    for (int c = 0; c < 4; c++) {
        double idx[3];
        float at[3];
        idx[p->axis] = p->index;
        idx[ua] = cu[c] * v->n[ua] - 0.5;
        idx[va] = cv[c] * v->n[va] - 0.5;
        model_point(v, idx, at);
        glTexCoord2f((float)cu[c], 1.0f - (float)cv[c]);
        glVertex3fv(at);
    }
    glEnd();
    glDisable(GL_TEXTURE_2D);
    glEnable(GL_LIGHTING);
    GLenum e = glGetError();
    if (e != GL_NO_ERROR && !p->gl_error)
        p->gl_error = e;
}

void ex_slice_plane_free(ex_slice_plane *p)
{
    if (p->texture)
        glDeleteTextures(1, &p->texture);
    free(p->rgb);
    memset(p, 0, sizeof *p);
    p->axis = -1;
}
