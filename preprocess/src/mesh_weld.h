/* SPDX-License-Identifier: Apache-2.0
 *
 * Welding and cleaning of a raw triangle soup (internal to mesh_*.c).
 */
#ifndef POSE_PP_MESH_WELD_H
#define POSE_PP_MESH_WELD_H

#include "pp_types.h"

#include <pose/pose.h>

/** Merge vertices with bit-identical positions (-0 == +0), drop triangles
 * with a repeated index or zero area and vertices no triangle uses. In place. */
pose_status pp_mesh_weld(pp_mesh *m);

#endif /* POSE_PP_MESH_WELD_H */
