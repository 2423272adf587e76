/* SPDX-License-Identifier: Apache-2.0 */
/* The k nearest tets of points (multi-anchor binding, bind_build.c). */
#ifndef POSE_BIND_SEARCH_H
#define POSE_BIND_SEARCH_H

#include <stddef.h>
#include <stdint.h>

#include "pose/pose.h"

/** A tet near a point: its index, the distance from the point to its
 *  centroid, the exact point-tet distance (0 inside) and the tet's point
 *  nearest to the point (model space). */
typedef struct pose__bind_hit {
    uint32_t tet;
    float distance;
    double gap;
    double foot[3];
} pose__bind_hit;

/**
 * For each of `count` points (xyz interleaved), the k tets of the rig
 * whose centroids are nearest at rest, nearest first (ties by tet index),
 * into hits + k * point; found[point] says how many: fewer than k when the
 * mesh has fewer tets, or when some of the k have (near) zero volume (no
 * frame: dropped). Exact: centroids are binned into a uniform
 * grid and rings of cells are searched outward until the k-th distance is
 * inside the rings.
 * Temporary memory from `a`; POSE_ERR_OUT_OF_MEMORY if it fails.
 */
pose_status pose__bind_nearest_tets(const pose_rig *rig, const float *xyz, size_t count,
                                    unsigned k, const pose_allocator *a, pose__bind_hit *hits,
                                    unsigned *found);

#endif /* POSE_BIND_SEARCH_H */
