/* SPDX-License-Identifier: Apache-2.0 */
/* Skinning of the tet mesh vertices: LBS, DQS, CoR (design §2). */
#ifndef POSE_RT_SKIN_H
#define POSE_RT_SKIN_H

#include <stddef.h>
#include <stdint.h>

#include "rt_quat.h"

/** Quantized weights of one vertex sum to exactly this (2^15): scaling by
 *  2^-15 is exact, so partition of unity holds bit for bit. */
#define POSE__WEIGHT_ONE 32768u

enum { POSE__SKIN_LBS = 0, POSE__SKIN_DQS = 1, POSE__SKIN_COR = 2 };

/** Per-joint data a kernel reads each frame (80 bytes, 16-byte aligned rows). */
typedef struct pose__skin_joint {
    float m[12]; /**< row-major 3x4 [R | t] */
    float q[4];  /**< rotation */
    float d[4];  /**< dual part of the dual quaternion: 0.5 (t, 0) q */
} pose__skin_joint;

/** The vertices to skin, in the compact form built at rig load. */
typedef struct pose__skin_mesh {
    size_t vertex_count;
    unsigned influences;       /**< K, 1..8 */
    const float *rest;         /**< 3 * n */
    const float *cor;          /**< 3 * n centres of rotation, or NULL */
    const uint8_t *joints8;    /**< K * n joint indices (rigs with <= 256 joints) ... */
    const uint16_t *joints16;  /**< ... or these (one of the two is NULL) */
    const uint16_t *weights;   /**< K * n, largest first, summing to POSE__WEIGHT_ONE */
} pose__skin_mesh;

/** Fill the per-joint palette from the FK skinning transforms. */
void pose__skin_palette(size_t joint_count, const pose__xform *skin, pose__skin_joint *out);

/**
 * Skin vertices [begin, end) with `method` (POSE__SKIN_*), writing
 * 3 floats per vertex at out + 3 * i. Each vertex is computed on its own,
 * so any partition of the range gives bit-identical results.
 */
void pose__skin(int method, const pose__skin_mesh *mesh, const pose__skin_joint *palette,
                size_t begin, size_t end, float *out);

#endif /* POSE_RT_SKIN_H */
