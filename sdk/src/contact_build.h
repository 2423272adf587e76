/* SPDX-License-Identifier: Apache-2.0 */
/* Building a triangle BVH (runtime/rt_bvh.h) once, from rest positions. */
#ifndef POSE_CONTACT_BUILD_H
#define POSE_CONTACT_BUILD_H

#include "pose/pose.h"
#include "rt_bvh.h"

/** Build the tree of `count` triangles (3 indices each into positions, kept
 *  by pointer) with allocations from `a`; the boxes fit `positions`.
 *  POSE_OK or POSE_ERR_OUT_OF_MEMORY (then nothing is left allocated). */
pose_status pose__bvh_build(pose__bvh *t, const pose_allocator *a, const uint32_t *triangles,
                            uint32_t count, const float *positions);
/** Each leaf's distinct corners (pose__bvh.corners) from the tree's
 *  triangles as they are now: the refit then reads each vertex once.
 *  POSE_OK or POSE_ERR_OUT_OF_MEMORY (the tree unchanged). */
pose_status pose__bvh_index_corners(pose__bvh *t, const pose_allocator *a);
/** Free what pose__bvh_build and pose__bvh_index_corners allocated (a
 *  zeroed tree is fine). */
void pose__bvh_release(pose__bvh *t, const pose_allocator *a);

#endif /* POSE_CONTACT_BUILD_H */
