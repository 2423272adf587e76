/* SPDX-License-Identifier: Apache-2.0
 * The non-inline parts of pb_math.h: Euler angles (through libpose, so the
 * bridge and the SDK read and write angles identically) and from-to rotation. */
#include "pb_math.h"

void pb_quat_from_euler(const double deg[3], pose_euler_order order, double q[4])
{
    float d[3] = {(float)deg[0], (float)deg[1], (float)deg[2]}, f[4];
    pose_euler_to_quat(d, order, f);
    for (int i = 0; i < 4; i++)
        q[i] = f[i];
    pb_quat_normalize(q);
}

void pb_quat_to_euler(const double q[4], pose_euler_order order, double deg[3])
{
    float f[4] = {(float)q[0], (float)q[1], (float)q[2], (float)q[3]}, d[3];
    pose_quat_to_euler(f, order, d);
    for (int i = 0; i < 3; i++)
        deg[i] = d[i];
}

void pb_quat_from_to(const double u[3], const double v[3], double q[4])
{
    double lu = pb_vec_len(u), lv = pb_vec_len(v);
    if (lu <= 0.0 || lv <= 0.0) {
        pb_quat_identity(q);
        return;
    }
    double a[3] = {u[0] / lu, u[1] / lu, u[2] / lu}, b[3] = {v[0] / lv, v[1] / lv, v[2] / lv};
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    if (d < -0.999999) { /* opposite: half turn about any axis orthogonal to a */
        double o[3] = {0, -a[2], a[1]};
        if (pb_vec_len(o) < 1e-6) {
            o[0] = a[2]; o[1] = 0; o[2] = -a[0];
        }
        double l = pb_vec_len(o);
        q[0] = o[0] / l; q[1] = o[1] / l; q[2] = o[2] / l; q[3] = 0.0;
        return;
    }
    q[0] = a[1] * b[2] - a[2] * b[1];
    q[1] = a[2] * b[0] - a[0] * b[2];
    q[2] = a[0] * b[1] - a[1] * b[0];
    q[3] = 1.0 + d;
    pb_quat_normalize(q);
}
