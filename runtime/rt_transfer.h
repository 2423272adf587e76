/* SPDX-License-Identifier: Apache-2.0 */
/* Transfer of the tet mesh deformation to tissue vertices, with normals. */
#ifndef POSE_RT_TRANSFER_H
#define POSE_RT_TRANSFER_H

#include <stddef.h>
#include <stdint.h>

/**
 * Tissue vertices in the blocked form built at rig load (8 lanes per block,
 * fields lane after lane, as pose__skin_mesh). A vertex lies in a tet
 * (v0..v3) with barycentric coordinates b0..b3; the tet's vertices are
 * ordered so that b0 is the largest (a tissue vertex sitting on a tet vertex
 * then follows it exactly) and only b1..b3 are stored:
 * p = v0 + sum bi (vi - v0).
 *
 * Normals use the tet's affine map F = D' D^-1 (D = [v1-v0 v2-v0 v3-v0],
 * corners ordered so that det D > 0): n' ~ F^-T n = D'^-T (D^T n) =
 * cof(D') (D^T n) / det D'. The constant part key = D^T n_rest is
 * precomputed (direction only, as int16), so a normal costs three cross
 * products of edges the transfer already has: no second pass over the
 * surface, no triangles read per frame. Where the pose squashes a tet flat
 * or turns it inside out (deep creases), F says nothing useful about the
 * surface: such vertices are listed and get the area-weighted normal of
 * their deformed triangles instead (pose__transfer_fix_normals).
 */
typedef struct pose__transfer_mesh {
    size_t vertex_count;
    size_t block_count;           /**< ceil(vertex_count / 8) */
    const uint32_t *tet_vertices; /**< block_count * 32: [block][corner][lane], v0 first */
    const float *bary;            /**< block_count * 24: b1[8] b2[8] b3[8] */
    const int16_t *normal_key;    /**< block_count * 24, see above; 0 0 0 = no normal */
    const uint32_t *fan_offset;   /**< vertex_count + 1: start of each vertex's fan */
    const uint32_t *fan;          /**< pairs (a, b): triangle (v, a, b) around vertex v */
} pose__transfer_mesh;

/**
 * Positions (and normals when nrm != NULL) of blocks [begin, end); xyz
 * interleaved at pos/nrm + 3 * vertex; padding lanes are not written.
 * tet_positions must stay readable for 16 bytes past its last vertex
 * (vertices are loaded 16 bytes at a time). With normals, the vertices whose
 * tet is flat or inverted (det D' <= 0) are written to `flagged` (room for 8
 * per block) and their count returned; their normals are left for
 * pose__transfer_fix_normals once every position is known.
 */
size_t pose__transfer(const pose__transfer_mesh *mesh, const float *tet_positions, size_t begin,
                      size_t end, float *pos, float *nrm, uint32_t *flagged);

/** Area-weighted normals from the deformed triangles for the `count`
 *  vertices listed in `flagged` (positions of all vertices must be final). */
void pose__transfer_fix_normals(const pose__transfer_mesh *mesh, const float *pos,
                                const uint32_t *flagged, size_t count, float *nrm);

/** Bytes pose__transfer streams per call over the whole mesh, counting the
 *  deformed tet vertices once (for benchmarks). */
size_t pose__transfer_bytes(const pose__transfer_mesh *mesh, size_t tet_vertex_count,
                            int normals);

#endif /* POSE_RT_TRANSFER_H */
