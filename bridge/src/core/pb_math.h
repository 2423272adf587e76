/* SPDX-License-Identifier: Apache-2.0
 * Small double-precision vector and quaternion helpers for the bridge.
 * Quaternions are {x, y, z, w} like the public API; vectors are double[3].
 * Euler orders follow pose.h: POSE_EULER_ZXY means R = Rz * Rx * Ry
 * (intrinsic, the BVH channel-list convention). */
#ifndef POSE_BRIDGE_MATH_H
#define POSE_BRIDGE_MATH_H

#include <math.h>

#include "pose/pose.h"

#define PB_DEG2RAD 0.017453292519943295
#define PB_RAD2DEG 57.29577951308232
#define PB_PI 3.141592653589793

static inline void pb_quat_identity(double q[4]) { q[0] = q[1] = q[2] = 0.0; q[3] = 1.0; }

static inline void pb_quat_copy(double d[4], const double s[4])
{
    d[0] = s[0]; d[1] = s[1]; d[2] = s[2]; d[3] = s[3];
}

/** out = a * b (apply b first, then a); out may alias a or b. */
static inline void pb_quat_mul(const double a[4], const double b[4], double out[4])
{
    double x = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    double y = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    double z = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    double w = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
    out[0] = x; out[1] = y; out[2] = z; out[3] = w;
}

static inline void pb_quat_conj(const double q[4], double out[4])
{
    out[0] = -q[0]; out[1] = -q[1]; out[2] = -q[2]; out[3] = q[3];
}

static inline void pb_quat_normalize(double q[4])
{
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (n > 0.0) {
        q[0] /= n; q[1] /= n; q[2] /= n; q[3] /= n;
    } else {
        pb_quat_identity(q);
    }
}

/** out = q v q^-1 for a unit q; out may alias v. */
static inline void pb_quat_rotate(const double q[4], const double v[3], double out[3])
{
    /* t = 2 q.xyz x v; v' = v + w t + q.xyz x t */
    double tx = 2.0 * (q[1] * v[2] - q[2] * v[1]);
    double ty = 2.0 * (q[2] * v[0] - q[0] * v[2]);
    double tz = 2.0 * (q[0] * v[1] - q[1] * v[0]);
    double x = v[0] + q[3] * tx + (q[1] * tz - q[2] * ty);
    double y = v[1] + q[3] * ty + (q[2] * tx - q[0] * tz);
    double z = v[2] + q[3] * tz + (q[0] * ty - q[1] * tx);
    out[0] = x; out[1] = y; out[2] = z;
}

/** Rotation of `deg` degrees about axis 0 (x), 1 (y) or 2 (z). */
static inline void pb_quat_axis_deg(int axis, double deg, double q[4])
{
    double h = 0.5 * deg * PB_DEG2RAD;
    q[0] = q[1] = q[2] = 0.0;
    q[axis] = sin(h);
    q[3] = cos(h);
}

/** Quaternion of Euler angles deg = {x, y, z} composed in `order`: libpose's
 *  pose_euler_to_quat (the one implementation; float precision, renormalized
 *  here in double). */
void pb_quat_from_euler(const double deg[3], pose_euler_order order, double q[4]);
/** Euler angles {x, y, z} of q in `order`, middle angle in [-90, 90]:
 *  libpose's pose_quat_to_euler (float precision). */
void pb_quat_to_euler(const double q[4], pose_euler_order order, double deg[3]);

static inline double pb_quat_dot(const double a[4], const double b[4])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
}

/** Shortest-path spherical interpolation, t in [0, 1]. */
static inline void pb_quat_slerp(const double a[4], const double b[4], double t, double out[4])
{
    double s = pb_quat_dot(a, b) < 0.0 ? -1.0 : 1.0, dm = 0.0, dp = 0.0;
    for (int i = 0; i < 4; i++) {
        dm += (a[i] - s * b[i]) * (a[i] - s * b[i]);
        dp += (a[i] + s * b[i]) * (a[i] + s * b[i]);
    }
    /* angle between the 4-vectors, accurate also when tiny (acos of a dot
     * product near 1 is not) */
    double th = 2.0 * atan2(sqrt(dm), sqrt(dp)), wa, wb;
    if (th < 1e-9) {
        wa = 1.0 - t;
        wb = t;
    } else {
        double sn = sin(th);
        wa = sin((1.0 - t) * th) / sn;
        wb = sin(t * th) / sn;
    }
    for (int i = 0; i < 4; i++)
        out[i] = wa * a[i] + s * wb * b[i];
    pb_quat_normalize(out);
}

/** Smallest rotation taking direction u to direction v (need not be unit). */
void pb_quat_from_to(const double u[3], const double v[3], double q[4]);

static inline double pb_vec_len(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

#endif /* POSE_BRIDGE_MATH_H */
