/* SPDX-License-Identifier: Apache-2.0 */
/* Transfer of the tet mesh deformation to tissue vertices, with normals. */
#ifndef POSE_RT_TRANSFER_H
#define POSE_RT_TRANSFER_H

#include <stddef.h>
#include <stdint.h>

/**
 * Tissue vertices in the compact form built at rig load. A vertex lies in a
 * tet (v0..v3) with barycentric coordinates b0..b3; the vertices are ordered
 * so that b0 is the largest (a tissue vertex sitting on a tet vertex then
 * follows it exactly) and only b1..b3 are stored: p = v0 + sum bi (vi - v0).
 *
 * Normals use the tet's affine map F = D' D^-1 (D = [v1-v0 v2-v0 v3-v0]):
 * n' ~ F^-T n = D'^-T (D^T n) = cof(D') (D^T n) / det D'. The constant part
 * key = sign(det D) D^T n_rest is precomputed (direction only, as int16), so
 * a normal costs three cross products of edges the transfer already has.
 */
typedef struct pose__transfer_mesh {
    size_t vertex_count;
    const uint32_t *tet_vertices; /**< 4 * n tet vertex indices, v0 first */
    const float *bary;            /**< 3 * n: b1, b2, b3 */
    const int16_t *normal_key;    /**< 3 * n, see above; 0 0 0 = no normal */
} pose__transfer_mesh;

/** Positions (and normals when nrm != NULL) of vertices [begin, end). */
void pose__transfer(const pose__transfer_mesh *mesh, const float *tet_positions, size_t begin,
                    size_t end, float *pos, float *nrm);

#endif /* POSE_RT_TRANSFER_H */
