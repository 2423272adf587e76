/* SPDX-License-Identifier: Apache-2.0 */
/* pose_euler_to_quat / pose_quat_to_euler, the one Euler implementation:
 * exact round trips in every order, and accuracy near gimbal lock (+-90
 * degrees on the middle axis), where an asin-based decomposition loses
 * half its digits and a wide gimbal threshold moves the rotation. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "euler_check.h"
#include "pose/pose.h"

static void test_round_trip_every_order(void **unused)
{
    (void)unused;
    const float angles[5][3] = {{10, 20, 30}, {-70, 45, 120}, {179, -30, 5}, {0, 0, -90}, {-150, 80, 170}};
    for (int o = 0; o < 6; o++)
        for (int a = 0; a < 5; a++) {
            float q[4], d[3], back[4];
            pose_euler_to_quat(angles[a], (pose_euler_order)o, q);
            pose_quat_to_euler(q, (pose_euler_order)o, d);
            pose_euler_to_quat(d, (pose_euler_order)o, back);
            assert_true(ec_rotation_deg(q, back) < 1e-4);
        }
    /* Composition order: XYZ is Rx * Ry * Rz (intrinsic x, then y, then z). */
    const float xy[3] = {90, 90, 0};
    float q[4];
    pose_euler_to_quat(xy, POSE_EULER_XYZ, q);
    const float want[4] = {0.5f, 0.5f, 0.5f, 0.5f}; /* Rx(90) * Ry(90) */
    assert_true(ec_rotation_deg(q, want) < 1e-4);
}

static void test_near_gimbal_lock(void **unused)
{
    (void)unused;
    for (int o = 0; o < 6; o++)
        for (int m = 0; m < EC_MIDDLES; m++) {
            float deg[3], q[4], d[3], back[4];
            ec_angles((pose_euler_order)o, ec_middle[m], deg);
            pose_euler_to_quat(deg, (pose_euler_order)o, q);
            pose_quat_to_euler(q, (pose_euler_order)o, d);
            pose_euler_to_quat(d, (pose_euler_order)o, back);
            int mid = ec_middle_axis((pose_euler_order)o);
            if (fabs(d[mid] - ec_middle[m]) > 1e-3 || ec_rotation_deg(q, back) > 1e-3)
                fail_msg("order %d, middle %.5f: read back middle %.6f, rotation off by %.2e deg",
                         o, ec_middle[m], (double)d[mid], ec_rotation_deg(q, back));
        }
}

static void test_unknown_order(void **unused)
{
    (void)unused;
    const float deg[3] = {10, 20, 30};
    float q[4] = {9, 9, 9, 9}, d[3] = {9, 9, 9};
    pose_euler_to_quat(deg, (pose_euler_order)6, q);
    assert_true(q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 1);
    pose_quat_to_euler(q, (pose_euler_order)-1, d);
    assert_true(d[0] == 0 && d[1] == 0 && d[2] == 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_every_order),
        cmocka_unit_test(test_near_gimbal_lock),
        cmocka_unit_test(test_unknown_order),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
