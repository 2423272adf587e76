/* SPDX-License-Identifier: Apache-2.0
 * The mannequin's sit-to-stand recording as the bridge thread's source
 * (pb_runner): the simulated device paces reports at 8x recorded speed on
 * the runner's thread, the mapping drives the full-body rig, the host reads
 * the newest pose without waiting. At the end the mannequin stands. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>

#include "hid_mannequin.h"
#include "hid_open.h"
#include "mapping.h"
#include "rig_skel.h"
#include "runner.h"
#include "runner_poll.h"

/* Rotation about y by deg: {0, sin(deg/2), 0, cos(deg/2)}. */
static void assert_about_y(const float q[4], double deg, double tol)
{
    double h = deg * 3.14159265358979323846 / 360.0;
    if (fabs(q[0]) > tol || fabs(q[2]) > tol || fabs(q[1] - sin(h)) > tol || fabs(q[3] - cos(h)) > tol)
        fail_msg("q = {%g %g %g %g}, expected %g deg about y", q[0], q[1], q[2], q[3], deg);
}

static void test_runner_hid_replay(void **state)
{
    (void)state;
    pb_rig_skel *skel = NULL;
    pb_error err;
    assert_int_equal(pb_rig_skel_schematic_body(&skel, &err), POSE_OK);
    char map_path[1024], rec[1024];
    snprintf(map_path, sizeof map_path, "%s/../bridge/maps/hid_mannequin_full_body.json", getenv("POSE_DATA_DIR"));
    snprintf(rec, sizeof rec, "%s/hid/mannequin_sit_to_stand.hid", getenv("POSE_DATA_DIR"));
    pb_mapping *map = NULL;
    if (pb_mapping_load(map_path, &map, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_source *src = NULL;
    pb_hid_replay_options ro = {.speed = 8};
    if (pb_hid_open(rec, &ro, &src, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_runner *run = NULL;
    pb_runner_options opt = {.speed = 1};
    if (pb_runner_start_source(src, skel, map, &opt, &run, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_true(runner_poll_fresh(run, 20) > 5);
    assert_int_equal(pb_runner_wait(run, 20000), 1); /* 8 s of recording at 8x: 1 s */
    pb_runner_stats st;
    pb_runner_stats_get(run, &st);
    assert_int_equal(st.state, PB_SOURCE_ENDED);
    assert_true(st.ticks > 1000);
    const pb_pose *p = pb_runner_latest(run, NULL);
    /* Standing at the end: the generator's angles through calibration and filter. */
    double deg[PB_MANNEQUIN_AXES];
    pb_mannequin_pose(PB_MOTION_SIT_TO_STAND, 7.998, deg, NULL);
    const int knee_l = pb_rig_skel_find(skel, "knee_l"), knee_r = pb_rig_skel_find(skel, "knee_r");
    const int elbow_l = pb_rig_skel_find(skel, "elbow_l"), hip_r = pb_rig_skel_find(skel, "hip_r");
    assert_true(p->active[knee_l] && p->active[knee_r] && p->active[hip_r]);
    assert_about_y(p->q[knee_l], deg[12], 0.01);
    assert_about_y(p->q[knee_r], deg[13], 0.01);
    assert_about_y(p->q[elbow_l], deg[6], 0.01);
    /* hip_r carries flexion (y, inverted) and abduction (x): check its y part through w. */
    assert_true(fabsf(p->q[hip_r][3]) > 0.998f);
    assert_false(p->active[pb_rig_skel_find(skel, "clavicle_l")]); /* no sensor drives the clavicles */
    assert_false(p->active[pb_rig_skel_find(skel, "head")]);
    assert_int_equal(pb_runner_stop(run, &err), POSE_OK);
    pb_mapping_free(map);
    pb_rig_skel_free(skel);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_runner_hid_replay),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
