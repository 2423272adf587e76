/* SPDX-License-Identifier: Apache-2.0 */
/* The bridge's Euler helpers (pb_math.h) and libpose's agree: the same
 * angles and quaternions in every order, also near gimbal lock, where two
 * separate implementations disagreed before they became one. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "euler_check.h"
#include "pb_math.h"
#include "pose/pose.h"

static void test_bridge_agrees_near_90(void **unused)
{
    (void)unused;
    for (int o = 0; o < 6; o++)
        for (int m = 0; m < EC_MIDDLES; m++) {
            float deg[3], q[4], d[3];
            ec_angles((pose_euler_order)o, ec_middle[m], deg);
            double degd[3] = {deg[0], deg[1], deg[2]}, qd[4], dd[3];
            pose_euler_to_quat(deg, (pose_euler_order)o, q);
            pb_quat_from_euler(degd, (pose_euler_order)o, qd);
            float qf[4] = {(float)qd[0], (float)qd[1], (float)qd[2], (float)qd[3]};
            assert_true(ec_rotation_deg(q, qf) < 1e-5);
            pose_quat_to_euler(q, (pose_euler_order)o, d);
            double qin[4] = {q[0], q[1], q[2], q[3]};
            pb_quat_to_euler(qin, (pose_euler_order)o, dd);
            for (int k = 0; k < 3; k++)
                if (fabs(dd[k] - d[k]) > 1e-4)
                    fail_msg("order %d, middle %.5f: angle %d is %.6f in the bridge, %.6f in "
                             "libpose", o, ec_middle[m], k, dd[k], (double)d[k]);
            /* and the bridge's angles give back the rotation */
            double back[4];
            pb_quat_from_euler(dd, (pose_euler_order)o, back);
            float bf[4] = {(float)back[0], (float)back[1], (float)back[2], (float)back[3]};
            assert_true(ec_rotation_deg(q, bf) < 1e-3);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bridge_agrees_near_90),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
