/* SPDX-License-Identifier: Apache-2.0
 * pose-view's slice plane: an axial, coronal or sagittal slice of the rig's
 * scan, posed as the model is, drawn in place as a textured quad (legacy
 * OpenGL, the colouring of vol_slices.h). */
#ifndef POSE_EX_SLICE_PLANE_H
#define POSE_EX_SLICE_PLANE_H

#include "ex_volume_posed.h"

typedef struct ex_slice_plane {
    int axis;              /* 2 axial, 1 coronal, 0 sagittal, -1 hidden */
    int index;             /* the slice, along axis */
    unsigned texture;      /* GL texture name, 0 before the first draw */
    unsigned char *rgb;    /* the slice's texels, room for the largest face */
    long labelled_texels;  /* texels in a label colour in the last slice drawn */
    unsigned gl_error;     /* the first GL error the drawing met, 0 if none */
} ex_slice_plane;

/** "axial", "coronal", "sagittal" or "off". */
const char *ex_slice_plane_name(int axis);
/** The axis named by `name` (as ex_slice_plane_name), or -2 for an unknown name. */
int ex_slice_plane_parse(const char *name);

/** Show `axis` (or hide it: -1) through the middle of the scan. Returns 0 or -1 (out of memory). */
int ex_slice_plane_show(ex_slice_plane *p, const ex_volume_posed *v, int axis);
/** The next plane: axial, coronal, sagittal, hidden, axial... */
int ex_slice_plane_cycle(ex_slice_plane *p, const ex_volume_posed *v);
/** Move the plane by `step` slices, kept inside the scan. */
void ex_slice_plane_move(ex_slice_plane *p, const ex_volume_posed *v, int step);

/** Draw the plane from v's posed scan with the current GL matrices (model space). */
void ex_slice_plane_draw(ex_slice_plane *p, const ex_volume_posed *v);

/** Release the texture (with the GL context current) and the texels. */
void ex_slice_plane_free(ex_slice_plane *p);

#endif
