/* SPDX-License-Identifier: Apache-2.0 */
#include "rt_euler.h"

#include <math.h>

static const int k_axes[6][3] = {
    {0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0},
};
static const char *const k_names[6] = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"};

#define DEG2RAD 0.017453292519943295
#define RAD2DEG 57.29577951308232

void pose__euler_axes(int order, int axes[3])
{
    for (int i = 0; i < 3; i++)
        axes[i] = k_axes[order][i];
}

const char *pose__euler_name(int order)
{
    return order >= 0 && order < 6 ? k_names[order] : "?";
}

void pose__euler_to_quat_d(const double deg[3], int order, double r[4])
{
    r[0] = r[1] = r[2] = 0.0;
    r[3] = 1.0;
    for (int n = 0; n < 3; n++) {
        int axis = k_axes[order][n];
        double half = 0.5 * deg[axis] * DEG2RAD;
        double a[4] = {0.0, 0.0, 0.0, cos(half)};
        a[axis] = sin(half);
        /* r = r * a */
        double x = r[3] * a[0] + r[0] * a[3] + r[1] * a[2] - r[2] * a[1];
        double y = r[3] * a[1] - r[0] * a[2] + r[1] * a[3] + r[2] * a[0];
        double z = r[3] * a[2] + r[0] * a[1] - r[1] * a[0] + r[2] * a[3];
        double w = r[3] * a[3] - r[0] * a[0] - r[1] * a[1] - r[2] * a[2];
        r[0] = x; r[1] = y; r[2] = z; r[3] = w;
    }
}

int pose__quat_to_euler_d(const double qi[4], int order, double deg[3])
{
    double q[4] = {qi[0], qi[1], qi[2], qi[3]};
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (n > 0.0)
        for (int i = 0; i < 4; i++)
            q[i] /= n;
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double m[3][3] = {
        {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
        {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
        {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)},
    };
    int i = k_axes[order][0], j = k_axes[order][1], k = k_axes[order][2];
    /* Writing R in the permuted basis (i, j, k) turns every order into the
     * XYZ case; odd permutations (XZY, YXZ, ZYX) flip signs. */
    double s = ((j - i + 3) % 3 == 1) ? 1.0 : -1.0;
    /* The middle angle from atan2, not asin: asin loses half the digits near
     * +-90 degrees, where its derivative blows up. */
    double sb = s * m[i][k], cb = sqrt(m[i][i] * m[i][i] + m[i][j] * m[i][j]);
    int locked = cb < POSE__GIMBAL_COS;
    if (!locked) {
        deg[i] = atan2(-s * m[j][k], m[k][k]) * RAD2DEG;
        deg[j] = atan2(sb, cb) * RAD2DEG;
        deg[k] = atan2(-s * m[i][j], m[i][i]) * RAD2DEG;
    } else {
        /* Only a + c (or a - c) is defined: put it all on a. */
        deg[i] = atan2(s * m[k][j], m[j][j]) * RAD2DEG;
        deg[j] = sb > 0.0 ? 90.0 : -90.0;
        deg[k] = 0.0;
    }
    return locked;
}

void pose__euler_to_quat(const float deg[3], int order, float q[4])
{
    double d[3] = {deg[0], deg[1], deg[2]}, r[4];
    pose__euler_to_quat_d(d, order, r);
    for (int i = 0; i < 4; i++)
        q[i] = (float)r[i];
}

void pose__quat_to_euler(const float qf[4], int order, float deg[3])
{
    double q[4] = {qf[0], qf[1], qf[2], qf[3]}, d[3];
    pose__quat_to_euler_d(q, order, d);
    for (int i = 0; i < 3; i++)
        deg[i] = (float)d[i];
}
