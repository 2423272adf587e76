/* SPDX-License-Identifier: Apache-2.0
 * One Euro filter against values worked out from the paper's equations
 * (Casiez et al. 2012, section 4): min_cutoff 1 Hz, beta 0.1, d_cutoff 1 Hz,
 * samples every Te = 0.1 s.
 *   alpha(fc) = 1 / (1 + 1 / (2 pi fc Te))      alpha(1 Hz) = 0.3858695451
 *   X = 0, 1, 1, 1, 5
 *   i=1: dX = (1 - 0)/0.1 = 10,  dx^ = 0.38587 * 10 = 3.8586954510,
 *        fc = 1 + 0.1 * 3.85870 = 1.3858695451, alpha = 0.4654600364,
 *        x^ = 0.4654600364 * 1 + 0.5345399636 * 0 = 0.4654600364
 *   i=2: dX = (1 - 0.46546)/0.1 = 5.3453996355, dx^ = 4.4323693183,
 *        fc = 1.4432369318, alpha = 0.4755645898, x^ = 0.7196683150
 *   i=3: dX = 2.8033168504, dx^ = 3.8037675836, fc = 1.3803767584,
 *        alpha = 0.4644720866, x^ = 0.8498745577
 *   i=4: dX = 41.501254423, dx^ = 18.350079682, fc = 2.8350079682,
 *        alpha = 0.6404543560, x^ = 3.5078404750 */
#include "bridge_test.h"
#include "one_euro.h"
#include "pb_math.h"

static void test_disabled_and_first_sample(void **state)
{
    (void)state;
    pb_one_euro f;
    pb_one_euro_init(&f, &(pb_one_euro_params){0, 0.5, 1});
    assert_near(pb_one_euro_step(&f, 3.0, 0.1), 3.0, 0);
    assert_near(pb_one_euro_step(&f, -7.0, 0.1), -7.0, 0); /* min_cutoff 0: off */
    pb_one_euro_init(&f, &(pb_one_euro_params){1, 0.1, 1});
    assert_near(pb_one_euro_step(&f, 42.0, 0.1), 42.0, 0); /* the first sample passes */
    assert_near(pb_one_euro_step(&f, 0.0, 0.0), 0.0, 0);   /* no time elapsed: re-prime */
}

static void test_paper_reference_values(void **state)
{
    (void)state;
    assert_near(pb_one_euro_alpha(1.0, 0.1), 0.3858695450950375, 1e-15);
    pb_one_euro f;
    pb_one_euro_init(&f, &(pb_one_euro_params){1.0, 0.1, 1.0});
    const double x[5] = {0, 1, 1, 1, 5};
    const double want[5] = {0, 0.4654600364475293, 0.7196683149638415, 0.8498745576530313, 3.5078404750006813};
    for (int i = 0; i < 5; i++)
        assert_near(pb_one_euro_step(&f, x[i], 0.1), want[i], 1e-12);
    assert_near(f.dx, 18.35007968171872, 1e-10);
}

static void test_jitter_reduced_motion_followed(void **state)
{
    (void)state;
    /* slow: a still value with +-1 noise at 100 Hz is smoothed to well under 1 */
    pb_one_euro f;
    pb_one_euro_init(&f, &(pb_one_euro_params){1.0, 0.007, 1.0});
    double worst = 0;
    for (int i = 0; i < 400; i++) {
        double y = pb_one_euro_step(&f, (i & 1) ? 1.0 : -1.0, 0.01);
        if (i > 100 && fabs(y) > worst)
            worst = fabs(y);
    }
    assert_true(worst < 0.1);
    /* fast: a 200 deg/s ramp with beta is followed with less lag than without */
    pb_one_euro a, b;
    pb_one_euro_init(&a, &(pb_one_euro_params){1.0, 0.5, 1.0});
    pb_one_euro_init(&b, &(pb_one_euro_params){1.0, 0.0, 1.0});
    double ya = 0, yb = 0;
    for (int i = 0; i <= 100; i++) {
        ya = pb_one_euro_step(&a, 2.0 * i, 0.01);
        yb = pb_one_euro_step(&b, 2.0 * i, 0.01);
    }
    assert_true(200.0 - ya < 0.25 * (200.0 - yb));
}

static void test_quaternion_variant(void **state)
{
    (void)state;
    /* rotation about z by angles 0, 10, 10, 10 deg: the filtered angle follows
     * the scalar filter run on the angle itself (rad), since |dX| is the
     * angle to the previous estimate and slerp mixes angles linearly. */
    pb_one_euro_params p = {1.0, 0.1, 1.0};
    pb_one_euro_quat fq;
    pb_one_euro s;
    pb_one_euro_quat_init(&fq, &p);
    pb_one_euro_init(&s, &p);
    const double deg[4] = {0, 10, 10, 10};
    for (int i = 0; i < 4; i++) {
        double q[4];
        pb_quat_axis_deg(2, deg[i], q);
        pb_one_euro_quat_step(&fq, q, 0.1);
        double want = pb_one_euro_step(&s, deg[i] * PB_DEG2RAD, 0.1);
        double got = 2.0 * atan2(q[2], q[3]);
        assert_near(got, want, 1e-12);
        assert_near(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-12);
    }
    /* the antipodal sample (-q) is the same rotation: no jump */
    double q[4];
    pb_quat_axis_deg(2, 10, q);
    for (int k = 0; k < 4; k++)
        q[k] = -q[k];
    pb_one_euro_quat_step(&fq, q, 0.1);
    assert_true(fabs(2.0 * atan2(fabs(q[2]), fabs(q[3])) * PB_RAD2DEG) <= 10.0 + 1e-9);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_disabled_and_first_sample),
        cmocka_unit_test(test_paper_reference_values),
        cmocka_unit_test(test_jitter_reduced_motion_followed),
        cmocka_unit_test(test_quaternion_variant),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
