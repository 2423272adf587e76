/* SPDX-License-Identifier: Apache-2.0
 * The reference rig's log as the bridge thread's source (pb_runner): the
 * replay paces frames at 20x recorded speed on the runner's thread, the
 * mapping drives the full-body rig, and the host side reads the newest
 * pose without waiting. At the end the mannequin stands, arms down. */
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

#include "can_source.h"
#include "mapping.h"
#include "rig_skel.h"
#include "runner.h"
#include "runner_poll.h"

static void test_runner_replay(void **state)
{
    (void)state;
    pb_rig_skel *skel = NULL;
    pb_error err;
    assert_int_equal(pb_rig_skel_schematic_body(&skel, &err), POSE_OK);
    char map_path[1024], log[1024];
    snprintf(map_path, sizeof map_path, "%s/../bridge/maps/can_rig_fullbody.json", getenv("POSE_DATA_DIR"));
    snprintf(log, sizeof log, "%s/can-rig/sit_stand_arm_raise.log", getenv("POSE_DATA_DIR"));
    pb_mapping *map = NULL;
    if (pb_mapping_load(map_path, &map, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_can_bus *bus = NULL;
    if (pb_can_bus_load(map_path, &bus, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_source *src = NULL;
    pb_candump_replay_options ro = {.speed = 20};
    if (pb_candump_replay_open(log, bus, &ro, &src, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_runner *run = NULL;
    pb_runner_options opt = {.speed = 1};
    if (pb_runner_start_source(src, skel, map, &opt, &run, &err) != POSE_OK)
        fail_msg("%s", err.message);
    /* host frames while it plays: poses come, never blocking */
    assert_true(runner_poll_fresh(run, 20) > 5);
    assert_int_equal(pb_runner_wait(run, 10000), 1); /* 10 s of log at 20x: 0.5 s */
    pb_runner_stats st;
    pb_runner_stats_get(run, &st);
    assert_int_equal(st.state, PB_SOURCE_ENDED);
    assert_true(st.ticks > 30000); /* one pose per frame with channel values */
    const pb_pose *p = pb_runner_latest(run, NULL);
    const int knee = pb_rig_skel_find(skel, "knee_l"), elbow = pb_rig_skel_find(skel, "elbow_r");
    const int shoulder = pb_rig_skel_find(skel, "shoulder_l"), clav = pb_rig_skel_find(skel, "clavicle_l");
    /* standing: knee straight (identity), elbow at 20 deg about y: {0, sin 10, 0, cos 10} */
    assert_true(p->active[knee]);
    assert_true(fabsf(p->q[knee][3]) > 0.9995f);
    assert_true(fabsf(p->q[elbow][1] - 0.17365f) < 0.005f && fabsf(p->q[elbow][3] - 0.98481f) < 0.005f);
    /* arms down again after the raise (shoulder flexion back near 0) */
    assert_true(fabsf(p->q[shoulder][3]) > 0.999f);
    assert_false(p->active[clav]); /* no sensor drives the clavicles */
    assert_int_equal(pb_runner_stop(run, &err), POSE_OK);
    pb_mapping_free(map);
    pb_rig_skel_free(skel);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_runner_replay),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
