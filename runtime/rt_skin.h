/* SPDX-License-Identifier: Apache-2.0 */
/* Skinning of the tet mesh vertices: LBS, DQS, CoR (design §2).
 *
 * Layout: vertices in blocks of POSE__BLOCK (8) lanes, each field of a block
 * stored lane after lane (x0..x7 y0..y7 z0..z7), so one block is a handful
 * of aligned vector loads. Weights are sorted largest first, and each block
 * records how many of them are non-zero in any lane ("active"): most of a
 * body is bound to a single bone, and such blocks read neither weights nor
 * centres and are moved rigidly.
 *
 * Every method is written in displacement form, v' = v + d(v), with d
 * computed from R - I (never from R then subtracting), so the rest pose
 * reproduces rest positions bit for bit: identity rotations and zero
 * translations give d = 0 exactly.
 */
#ifndef POSE_RT_SKIN_H
#define POSE_RT_SKIN_H

#include <stddef.h>
#include <stdint.h>

#include "rt_quat.h"

/** Lanes per block of vertices. */
#define POSE__BLOCK 8
/** Quantized weights of one vertex sum to exactly this (2^15): scaling by
 *  2^-15 is exact, so partition of unity holds bit for bit. */
#define POSE__WEIGHT_ONE 32768u

enum { POSE__SKIN_LBS = 0, POSE__SKIN_DQS = 1, POSE__SKIN_COR = 2 };

/** Per-joint data the kernels gather each frame: one 64-byte line. */
typedef struct pose__skin_joint {
    float q[4];   /**< rotation {x y z w} */
    float t[4];   /**< translation, t[3] = 0 */
    float d[4];   /**< dual part of the dual quaternion: 0.5 (t, 0) q */
    float pad[4];
} pose__skin_joint;

/** The vertices to skin, in the blocked form built at rig load. */
typedef struct pose__skin_mesh {
    size_t vertex_count;
    size_t block_count;       /**< ceil(vertex_count / 8); padding lanes are valid vertices */
    unsigned influences;      /**< K, 1..8 */
    const float *rest;        /**< block_count * 24: x[8] y[8] z[8] per block */
    const float *cor;         /**< same layout, or NULL */
    const uint8_t *active;    /**< block_count: influences used by some lane (1..K) */
    const uint16_t *joints;   /**< block_count * K * 8 joint indices, [block][k][lane] */
    const uint16_t *weights;  /**< block_count * K * 8, largest first, sum POSE__WEIGHT_ONE */
} pose__skin_mesh;

/** Fill the per-joint palette from the FK skinning transforms. */
void pose__skin_palette(size_t joint_count, const pose__xform *skin, pose__skin_joint *out);

/**
 * Skin blocks [begin, end) with `method` (POSE__SKIN_*), writing xyz
 * interleaved at out + 3 * vertex (padding lanes are not written). Every
 * vertex is computed on its own: any split into block ranges gives
 * bit-identical results.
 */
void pose__skin(int method, const pose__skin_mesh *mesh, const pose__skin_joint *palette,
                size_t begin, size_t end, float *out);

/** Bytes pose__skin reads and writes for the whole mesh (for benchmarks). */
size_t pose__skin_bytes(int method, const pose__skin_mesh *mesh);

/** Kernel variants: the generic C one always exists; others where built and
 *  supported by the CPU. Tests force the generic one to compare results;
 *  POSE_KERNELS=generic in the environment forces it for a whole process. */
void pose__kernels_force_generic(int on);
/** Name of the variant in use ("avx2" or "generic"). */
const char *pose__kernels_variant(void);

#endif /* POSE_RT_SKIN_H */
