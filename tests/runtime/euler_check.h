/* SPDX-License-Identifier: Apache-2.0 */
/* Cases near gimbal lock shared by the Euler tests of libpose and of the
 * bridge, and the angle between two rotations. */
#ifndef POSE_TEST_EULER_CHECK_H
#define POSE_TEST_EULER_CHECK_H

#include <math.h>

#include "pose/pose.h"

/* Middle angles from well away from lock to exactly locked. */
static const double ec_middle[] = {80.0, 89.0, 89.9, 89.99, 89.999, 89.9999, 89.99999, 90.0,
                                   -89.99, -89.9999, -90.0};
#define EC_MIDDLES ((int)(sizeof ec_middle / sizeof ec_middle[0]))

/* Axis that order `o` turns about second (XYZ -> y). */
static inline int ec_middle_axis(pose_euler_order o)
{
    static const int mid[6] = {1, 2, 0, 2, 0, 1};
    return mid[o];
}

/* Angles {x, y, z} with `middle` on the middle axis and large outer angles. */
static inline void ec_angles(pose_euler_order o, double middle, float deg[3])
{
    int m = ec_middle_axis(o);
    deg[0] = 37.0f;
    deg[1] = -121.0f;
    deg[2] = 64.0f;
    deg[m] = (float)middle;
}

/* Angle in degrees of the rotation taking a to b (either sign). */
static inline double ec_rotation_deg(const float a[4], const float b[4])
{
    double dot = 0.0, na = 0.0, nb = 0.0;
    for (int i = 0; i < 4; i++) {
        dot += (double)a[i] * b[i];
        na += (double)a[i] * a[i];
        nb += (double)b[i] * b[i];
    }
    double c = fabs(dot) / sqrt(na * nb), s = sqrt(fmax(0.0, 1.0 - c * c));
    return 2.0 * atan2(s, c) * 57.29577951308232;
}

#endif /* POSE_TEST_EULER_CHECK_H */
