/* SPDX-License-Identifier: Apache-2.0
 *
 * assert_near: the installed cmocka has no floating-point equality assert.
 * Include after <cmocka.h>.
 */
#ifndef POSE_TEST_PP_ASSERT_H
#define POSE_TEST_PP_ASSERT_H

#include <math.h>

#define assert_near(a, b, tol)                                                                \
    do {                                                                                      \
        double a_ = (double)(a), b_ = (double)(b), t_ = (double)(tol);                        \
        if (!(fabs(a_ - b_) <= t_)) {                                                         \
            print_error("%s = %.9g, expected %.9g +- %.3g\n", #a, a_, b_, t_);               \
            fail();                                                                           \
        }                                                                                     \
    } while (0)

#endif /* POSE_TEST_PP_ASSERT_H */
