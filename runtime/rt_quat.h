/* SPDX-License-Identifier: Apache-2.0 */
/* Quaternion and rigid-transform arithmetic shared by the kernels.
 * Quaternions are {x, y, z, w}; a rigid transform maps p -> R(q) p + t.
 * Everything is static inline: these run inside per-vertex loops. */
#ifndef POSE_RT_QUAT_H
#define POSE_RT_QUAT_H

#include <math.h>

/** A rigid transform: rotation quaternion plus translation. */
typedef struct pose__xform {
    float q[4];
    float t[3];
} pose__xform;

static inline void pose__quat_identity(float q[4])
{
    q[0] = 0.0f; q[1] = 0.0f; q[2] = 0.0f; q[3] = 1.0f;
}

static inline int pose__quat_is_identity(const float q[4])
{
    return q[0] == 0.0f && q[1] == 0.0f && q[2] == 0.0f && q[3] == 1.0f;
}

/** r = a * b (apply b first, then a). r may alias neither input. */
static inline void pose__quat_mul(float r[4], const float a[4], const float b[4])
{
    r[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    r[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    r[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    r[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
}

static inline void pose__quat_conj(float r[4], const float q[4])
{
    r[0] = -q[0]; r[1] = -q[1]; r[2] = -q[2]; r[3] = q[3];
}

/** Normalize in place; returns the original length (0: q set to identity).
 *  A quaternion that is already exactly unit (e.g. identity) is unchanged. */
static inline float pose__quat_normalize(float q[4])
{
    float n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    if (!(n2 > 1e-30f) || !isfinite(n2)) {
        pose__quat_identity(q);
        return 0.0f;
    }
    if (n2 == 1.0f)
        return 1.0f;
    float n = sqrtf(n2), s = 1.0f / n;
    q[0] *= s; q[1] *= s; q[2] *= s; q[3] *= s;
    return n;
}

/** out = R(q) v (out may alias v). */
/* The rotation matrix of unit quaternion q {x,y,z,w}, row-major. */
static inline void pose__quat_to_matrix(const float q[4], float R[9])
{
    const float x = q[0], y = q[1], z = q[2], w = q[3];
    R[0] = 1.0f - 2.0f * (y * y + z * z);
    R[1] = 2.0f * (x * y - w * z);
    R[2] = 2.0f * (x * z + w * y);
    R[3] = 2.0f * (x * y + w * z);
    R[4] = 1.0f - 2.0f * (x * x + z * z);
    R[5] = 2.0f * (y * z - w * x);
    R[6] = 2.0f * (x * z - w * y);
    R[7] = 2.0f * (y * z + w * x);
    R[8] = 1.0f - 2.0f * (x * x + y * y);
}

static inline void pose__quat_rotate(float out[3], const float q[4], const float v[3])
{
    /* v + 2w (u x v) + 2 u x (u x v), u = q.xyz */
    float ux = q[0], uy = q[1], uz = q[2], w = q[3];
    float cx = uy * v[2] - uz * v[1], cy = uz * v[0] - ux * v[2], cz = ux * v[1] - uy * v[0];
    float dx = uy * cz - uz * cy, dy = uz * cx - ux * cz, dz = ux * cy - uy * cx;
    float x = v[0] + 2.0f * (w * cx + dx);
    float y = v[1] + 2.0f * (w * cy + dy);
    float z = v[2] + 2.0f * (w * cz + dz);
    out[0] = x; out[1] = y; out[2] = z;
}

/** r = a o b: first b, then a. r may not alias a or b. Exact for identities. */
static inline void pose__xform_compose(pose__xform *r, const pose__xform *a, const pose__xform *b)
{
    pose__quat_mul(r->q, a->q, b->q);
    pose__quat_normalize(r->q);
    float t[3];
    pose__quat_rotate(t, a->q, b->t);
    r->t[0] = t[0] + a->t[0];
    r->t[1] = t[1] + a->t[1];
    r->t[2] = t[2] + a->t[2];
}

static inline void pose__xform_identity(pose__xform *x)
{
    pose__quat_identity(x->q);
    x->t[0] = x->t[1] = x->t[2] = 0.0f;
}

#endif /* POSE_RT_QUAT_H */
