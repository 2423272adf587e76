/* SPDX-License-Identifier: Apache-2.0
 *
 * Binary glTF 2.0 (.glb) for Blender, three.js and every other glTF reader:
 *
 * - ex_gltf_write_posed: the tissues of a state's current pose, one mesh
 *   node per tissue (positions, normals, triangles);
 * - a session (ex_gltf_session_*): the skin and bone tissues as skinned
 *   meshes in the rest pose, bound to the rig's joint hierarchy (nodes at
 *   the joints' rest frames), and one animation with a sample per added
 *   frame: every joint's local rotation, and the root joints' translation.
 *   Tissue vertices take the skinning weights of their embedding tet's
 *   vertices blended by barycentric coordinates, reduced to the 4 largest
 *   and renormalised (glTF's JOINTS_0 / WEIGHTS_0); a bone tissue follows
 *   its own joint rigidly.
 *
 * Functions return 0, or -1 with a message naming the file in err.
 */
#ifndef POSE_EX_GLTF_H
#define POSE_EX_GLTF_H

#include <stddef.h>

#include "pose/pose.h"

/** 1 when this build writes glTF (it needs cJSON), else 0. */
int ex_gltf_available(void);

/** All tissues of the state's current pose into one .glb at `path`. */
int ex_gltf_write_posed(const pose_state *st, const char *path, char *err, size_t err_size);

typedef struct ex_gltf_session ex_gltf_session;

/** Start a session of `rig` (which must outlive it). */
int ex_gltf_session_begin(const pose_rig *rig, ex_gltf_session **out, char *err, size_t err_size);
/** Record the joints of `st` (after its pose_apply) as the sample at `t_s` seconds; times increase. */
int ex_gltf_session_add(ex_gltf_session *s, const pose_state *st, double t_s, char *err, size_t err_size);
/** Write the skinned meshes and the animation of every added frame into `path` (.glb). */
int ex_gltf_session_write(const ex_gltf_session *s, const char *path, char *err, size_t err_size);
/** Free a session; NULL is a no-op. */
void ex_gltf_session_free(ex_gltf_session *s);

/** Number of tissues a session writes as skinned meshes (skin and bones). */
size_t ex_gltf_session_mesh_count(const ex_gltf_session *s);

#endif
