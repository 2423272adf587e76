/* SPDX-License-Identifier: Apache-2.0
 *
 * Analytic test shapes for the geometry stages (outward-facing, closed
 * unless said otherwise) and a small OBJ writer for loader tests.
 */
#ifndef POSE_TEST_PP_SHAPES_H
#define POSE_TEST_PP_SHAPES_H

#include "pp_types.h"

/** Axis-aligned box [lo, hi], 8 vertices, 12 triangles. */
void shape_box(pp_mesh *m, const float lo[3], const float hi[3]);
/** Sphere of radius r at c: icosahedron subdivided `level` times, projected. */
void shape_sphere(pp_mesh *m, const float c[3], float r, int level);
/** Capped cylinder along z from z0 to z1, radius r, `seg` sides, axis at (cx, cy). */
void shape_cylinder(pp_mesh *m, float cx, float cy, float r, float z0, float z1, int seg);
/** Remove the first `n` triangles (makes a hole). */
void shape_drop_triangles(pp_mesh *m, size_t n);
/** Rotate about the z axis by `rad` around the origin. */
void shape_rotate_z(pp_mesh *m, float rad);
/** Write m as OBJ; returns 0 on success. */
int shape_write_obj(const pp_mesh *m, const char *path);
/** Path under $POSE_TEST_TMP (static buffer per call site is fine in tests). */
const char *shape_tmp(const char *name, char *buf, size_t cap);
/** Path under $POSE_DATA_DIR. */
const char *shape_data(const char *rel, char *buf, size_t cap);

#endif /* POSE_TEST_PP_SHAPES_H */
