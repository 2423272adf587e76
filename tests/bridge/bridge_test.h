/* SPDX-License-Identifier: Apache-2.0
 * Helpers shared by the bridge tests: data paths and small assertions. */
#ifndef POSE_BRIDGE_TEST_H
#define POSE_BRIDGE_TEST_H

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

static inline const char *bt_path(char *buf, size_t n, const char *env, const char *rel)
{
    const char *d = getenv(env);
    snprintf(buf, n, "%s/%s", d ? d : ".", rel);
    return buf;
}

#define BT_DATA(buf, rel) bt_path(buf, sizeof buf, "POSE_DATA_DIR", rel)
#define BT_TMP(buf, rel) bt_path(buf, sizeof buf, "POSE_TEST_TMP", rel)

/* the maps shipped in bridge/maps, found from the data folder */
#define BT_MAP(buf, rel) bt_path(buf, sizeof buf, "POSE_DATA_DIR", "../bridge/maps/" rel)

#define assert_near(a, b, tol)                                                                     \
    do {                                                                                           \
        double a_ = (a), b_ = (b);                                                                 \
        if (!(fabs(a_ - b_) <= (tol)))                                                             \
            fail_msg("%s = %.9g, expected %s = %.9g within %g", #a, a_, #b, b_, (double)(tol));    \
    } while (0)

/* Angle in degrees of the rotation between unit quaternions a and b
 * (normalized here; atan2 form, accurate for tiny angles unlike acos). */
static inline double bt_quat_angle_deg(const double a[4], const double b[4])
{
    double na = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2] + a[3] * a[3]);
    double nb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3]);
    double d = 0, dm = 0, dp = 0;
    for (int i = 0; i < 4; i++)
        d += a[i] * b[i];
    double s = d < 0 ? -1.0 : 1.0;
    for (int i = 0; i < 4; i++) {
        double x = a[i] / na, y = s * b[i] / nb;
        dm += (x - y) * (x - y);
        dp += (x + y) * (x + y);
    }
    return 4.0 * atan2(sqrt(dm), sqrt(dp)) * 57.29577951308232;
}

#endif
