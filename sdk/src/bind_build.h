/* SPDX-License-Identifier: Apache-2.0 */
/* Building a multi-anchor binding (rt_bind.h) of points to a rig at rest:
 * shared by pose_binding_create and the rig's tissue vertices outside its
 * tet mesh (rig_prepare.c). */
#ifndef POSE_BIND_BUILD_H
#define POSE_BIND_BUILD_H

#include <stddef.h>

#include "pose/pose.h"
#include "rt_bind.h"

/** Anchor kinds a binding draws from (pose/binding.h's POSE_BINDING_NODES, _BONES). */
enum { POSE__BIND_NODES = 1u << 0, POSE__BIND_JOINTS = 1u << 1 };

/**
 * Bind `count` points (xyz at rest, model space) to their n nearest anchors
 * of the kinds in `sources`: tet mesh vertices (nodes), joints by
 * distance to their bone (the segments from the joint to its children, or
 * the joint's origin for a leaf). Weights fall off smoothly to zero at the
 * distance of the nearest anchor left out (see bind_build.c), so a vertex's
 * position is continuous in its rest position. The mesh's arrays live in
 * one block (*block) allocated with `a`; free it with pose__free.
 */
pose_status pose__bind_build(const pose_rig *rig, const float *xyz, size_t count, unsigned n,
                             unsigned sources, const pose_allocator *a, pose__bind_mesh *mesh,
                             void **block);

#endif /* POSE_BIND_BUILD_H */
