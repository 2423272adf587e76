/* SPDX-License-Identifier: Apache-2.0
 *
 * Writing a posed state to files other tools open: tissues as Wavefront OBJ
 * (one file, one object per tissue: Blender, MeshLab) or PLY (one binary
 * file per tissue, with normals), the tet mesh as VTK XML unstructured grid
 * (.vtu: ParaView) with tet labels, rest-to-posed displacement and skinning
 * weights as fields. Functions return 0, or -1 with a message naming the
 * file in err.
 */
#ifndef POSE_EX_EXPORT_H
#define POSE_EX_EXPORT_H

#include <stddef.h>

#include "pose/pose.h"

/** All tissues of the state's current pose into one OBJ file at `path`. */
int ex_export_obj(const pose_state *st, const char *path, char *err, size_t err_size);

/** Each tissue into `dir`/<tissue name>.ply (binary little-endian, with normals). */
int ex_export_ply(const pose_state *st, const char *dir, char *err, size_t err_size);

/**
 * The posed tet mesh into `path` (.vtu). Point data: displacement from rest,
 * the dominant joint, and the weight of `weight_joint` when >= 0; cell data:
 * the tet label (0 soft tissue, j + 1 bone of joint j).
 */
int ex_export_vtu(const pose_state *st, const char *path, int weight_joint, char *err, size_t err_size);

/** A tissue name made safe as a file name (letters, digits, '-', '_', '.'). */
void ex_export_file_name(const char *name, char *out, size_t out_size);

#endif
