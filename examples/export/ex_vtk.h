/* SPDX-License-Identifier: Apache-2.0
 *
 * Tissue surfaces for ParaView: every tissue of a posed state in one VTK XML
 * unstructured grid of triangles (.vtu, binary: base64 DataArrays as VTK
 * writes them, readable by VTK, ParaView and meshio), with point data
 * Normals and displacement (from rest) and cell data tissue (the tissue
 * index, as pose_rig_tissue_info numbers them).
 * A time series is one such file per frame and a ParaView
 * collection (.pvd) naming each with its time.
 *
 * Functions return 0, or -1 with a message naming the file in err.
 */
#ifndef POSE_EX_VTK_H
#define POSE_EX_VTK_H

#include <stddef.h>

#include "pose/pose.h"

/** All tissue surfaces of the state's current pose into `path` (.vtu). */
int ex_vtk_write_surfaces(const pose_state *st, const char *path, char *err, size_t err_size);

typedef struct ex_vtk_series ex_vtk_series;

/** Start a series whose collection is `pvd_path`; frames go beside it as <stem>_NNNNN.vtu. */
int ex_vtk_series_begin(const char *pvd_path, ex_vtk_series **out, char *err, size_t err_size);
/** Write the state's surfaces as the frame at `t_s` seconds. */
int ex_vtk_series_add(ex_vtk_series *s, const pose_state *st, double t_s, char *err, size_t err_size);
/** Write the .pvd naming every frame added. */
int ex_vtk_series_finish(ex_vtk_series *s, char *err, size_t err_size);
/** Free a series; NULL is a no-op. */
void ex_vtk_series_free(ex_vtk_series *s);

#endif
