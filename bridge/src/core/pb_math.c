/* SPDX-License-Identifier: Apache-2.0
 * The non-inline parts of pb_math.h: Euler extraction and from-to rotation. */
#include "pb_math.h"

void pb_quat_to_euler(const double q[4], pose_euler_order order, double deg[3])
{
    /* Rotation matrix of q, then the classic Tait-Bryan extraction for
     * R = R_a * R_b * R_c (a outermost). Writing R in the permuted basis
     * (a, b, c) turns every order into the XYZ case, with a sign for odd
     * permutations. */
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double m[3][3] = {
        {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
        {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
        {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)},
    };
    int ax[3];
    pb_euler_axes(order, ax);
    int a = ax[0], b = ax[1], c = ax[2];
    /* parity: +1 for cyclic (x,y,z), (y,z,x), (z,x,y) */
    double p = ((b - a + 3) % 3 == 1) ? 1.0 : -1.0;
    /* the middle angle from atan2 (not asin), so it stays accurate near
     * +-90 degrees where asin is ill-conditioned */
    double sb = p * m[a][c], cb = sqrt(m[a][a] * m[a][a] + m[a][b] * m[a][b]);
    double ang_a, ang_b = atan2(sb, cb), ang_c;
    if (cb > 1e-12) {
        ang_a = atan2(-p * m[b][c], m[c][c]);
        ang_c = atan2(-p * m[a][b], m[a][a]);
    } else { /* gimbal lock: put everything into the outer angle */
        ang_a = atan2(p * m[c][b], m[b][b]);
        ang_c = 0.0;
    }
    deg[a] = ang_a * PB_RAD2DEG;
    deg[b] = ang_b * PB_RAD2DEG;
    deg[c] = ang_c * PB_RAD2DEG;
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
