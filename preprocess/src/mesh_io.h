/* SPDX-License-Identifier: Apache-2.0
 *
 * Loading triangle meshes for pose-bake. Any format Assimp reads (OBJ, STL,
 * PLY, glTF, FBX, ...) is accepted; all meshes and nodes of a file are merged
 * into one pp_mesh in the file's world frame (node transforms applied),
 * triangulated, with exactly coincident vertices welded and degenerate
 * triangles (repeated index, zero area) dropped. Coordinates are taken as
 * metres; no unit conversion is done.
 *
 * Threads: pp_mesh_load is not reentrant (Assimp's C API keeps its last
 * error in a global); load from one thread. The other functions are.
 *
 * Errors: every function returns a pose_status and, on failure, writes a
 * one-line message naming the file into err (if err != NULL), e.g.
 * "data/skin.obj: no triangles" or "x.stl: vertex 12 has a non-finite
 * coordinate". The output is zeroed on failure; nothing needs freeing.
 */
#ifndef POSE_PP_MESH_IO_H
#define POSE_PP_MESH_IO_H

#include "pp_types.h"

#include <pose/pose.h>

/** Load one mesh file. out->name is set to the file's base name without
 * extension ("r_femur"). Free with pp_mesh_free(). */
pose_status pp_mesh_load(const char *path, pp_mesh *out, char *err, size_t errlen);

/** Validate an in-memory mesh (used on meshes built by code): at least one
 * triangle, finite coordinates, indices in range. `what` names the mesh in
 * the message. */
pose_status pp_mesh_validate(const pp_mesh *m, const char *what, char *err, size_t errlen);

/** Append src to dst (indices offset). dst may be empty (zeroed). */
pose_status pp_mesh_append(pp_mesh *dst, const pp_mesh *src);

/** Deep copy. */
pose_status pp_mesh_copy(pp_mesh *dst, const pp_mesh *src);

/** Topology figures used in repair reports. */
typedef struct pp_mesh_topology {
    size_t boundary_edges;     /**< edges used by exactly one triangle (holes) */
    size_t nonmanifold_edges;  /**< edges used by three or more triangles */
    size_t inconsistent_edges; /**< edges two triangles traverse in the same direction */
} pp_mesh_topology;

/** Count boundary, non-manifold and inconsistently oriented edges. A mesh
 * with all three zero is closed and consistently oriented. */
pose_status pp_mesh_topology_count(const pp_mesh *m, pp_mesh_topology *out);

/** Axis-aligned bounds; lo = hi = 0 for an empty mesh. */
void pp_mesh_bounds(const pp_mesh *m, float lo[3], float hi[3]);

/** Signed enclosed volume (divergence theorem, m^3); positive for a closed
 * mesh with outward normals, meaningless for an open one. */
double pp_mesh_volume(const pp_mesh *m);

/** Area-weighted vertex normals, unit length, into normals[3 * vertex_count]
 * (caller's buffer). Vertices on no triangle get (0, 0, 0). */
void pp_mesh_vertex_normals(const pp_mesh *m, float *normals);

#endif /* POSE_PP_MESH_IO_H */
