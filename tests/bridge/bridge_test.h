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

#endif
