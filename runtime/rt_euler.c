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

void pose__euler_to_quat(const float deg[3], int order, float q[4])
{
    /* Compose in double: the result is rounded to float once. */
    double r[4] = {0.0, 0.0, 0.0, 1.0};
    for (int n = 0; n < 3; n++) {
        int axis = k_axes[order][n];
        double half = 0.5 * (double)deg[axis] * DEG2RAD;
        double a[4] = {0.0, 0.0, 0.0, cos(half)};
        a[axis] = sin(half);
        /* r = r * a */
        double x = r[3] * a[0] + r[0] * a[3] + r[1] * a[2] - r[2] * a[1];
        double y = r[3] * a[1] - r[0] * a[2] + r[1] * a[3] + r[2] * a[0];
        double z = r[3] * a[2] + r[0] * a[1] - r[1] * a[0] + r[2] * a[3];
        double w = r[3] * a[3] - r[0] * a[0] - r[1] * a[1] - r[2] * a[2];
        r[0] = x; r[1] = y; r[2] = z; r[3] = w;
    }
    for (int i = 0; i < 4; i++)
        q[i] = (float)r[i];
}

void pose__quat_to_euler(const float qf[4], int order, float deg[3])
{
    double q[4] = {qf[0], qf[1], qf[2], qf[3]};
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
    /* Cyclic orders (XYZ, YZX, ZXY) and their mirrors differ only in signs. */
    double s = ((j - i + 3) % 3 == 1) ? 1.0 : -1.0;
    double sb = s * m[i][k];
    if (sb > 1.0) sb = 1.0;
    if (sb < -1.0) sb = -1.0;
    double a, b = asin(sb), c;
    if (fabs(sb) < 0.9999999) {
        a = atan2(-s * m[j][k], m[k][k]);
        c = atan2(-s * m[i][j], m[i][i]);
    } else {
        /* Gimbal lock: only a + c (or a - c) is defined; put it all on a. */
        a = atan2(s * m[k][j], m[j][j]);
        c = 0.0;
    }
    deg[i] = (float)(a * RAD2DEG);
    deg[j] = (float)(b * RAD2DEG);
    deg[k] = (float)(c * RAD2DEG);
}
