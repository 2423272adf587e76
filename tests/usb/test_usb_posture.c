/* SPDX-License-Identifier: Apache-2.0
 * The reference USB goniometer box's captures through the public API
 * (pose/bridge.h) pose the body baked from data/anatomy (fixture
 * body_rig_bake) as the capture's truth file says: every true angle,
 * measured back from the posed joint's world rotation in the clinical
 * convention, within 2 degrees wherever the rig's range of motion does not
 * limit it (as tests/bridge/test_device_posture.c checks the HID mannequin
 * and the CAN rig). The faulty capture played by the bridge thread reports
 * its 12 drops, and bad source strings and maps fail with their reasons. */
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

#include "clinical_check.h"
#include "pose/bridge.h"
#include "pose/pose.h"

enum { AXES = 16 };

static const char *path(char *buf, size_t n, const char *env, const char *rel)
{
    const char *d = getenv(env);
    snprintf(buf, n, "%s/%s", d ? d : ".", rel);
    return buf;
}

typedef struct fixture {
    pose_rig *rig;
    pose_state *st;
    char map[1024];
} fixture;

static int setup(void **state)
{
    static fixture f;
    char p[1024];
    if (pose_rig_load(path(p, sizeof p, "POSE_TEST_TMP", "body.rig"), &f.rig) < 0) {
        print_error("%s (written by the ctest fixture body_rig_bake)\n", pose_last_error());
        return -1;
    }
    if (pose_state_create(f.rig, &f.st) != POSE_OK)
        return -1;
    pose_set_threads(f.st, 1);
    path(f.map, sizeof f.map, "POSE_DATA_DIR", "../bridge/maps/usb_gonio_full_body.json");
    *state = &f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    pose_state_free(f->st);
    pose_rig_free(f->rig);
    return 0;
}

/* "knee_l.flexion" -> joint "knee_l", angle 0 (flexion, dorsiflexion) or 1 (abduction) */
static void axis_joint(const char *name, char *joint, size_t n, int *dof)
{
    const char *dot = strchr(name, '.');
    snprintf(joint, n, "%.*s", (int)(dot - name), name);
    *dof = strstr(dot, "abduction") ? 1 : 0;
}

typedef struct stats {
    double worst, worst_t;
    char worst_name[64];
    long compared;
} stats;

static void truth_run(fixture *f, const char *capture, const char *truth_file, stats *s)
{
    char cp[1024], tp[1024], line[4096];
    pose_bridge *b;
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map, .play = POSE_BRIDGE_MANUAL};
    if (pose_bridge_open(path(cp, sizeof cp, "POSE_DATA_DIR", capture), f->rig, &o, &b) != POSE_OK)
        fail_msg("%s", pose_last_error());
    FILE *csv = fopen(path(tp, sizeof tp, "POSE_DATA_DIR", truth_file), "r");
    assert_non_null(csv);
    assert_non_null(fgets(line, sizeof line, csv));
    char names[AXES + 2][48];
    int ncol = 0;
    for (char *tok = strtok(line, ",\n"); tok && ncol < AXES + 2; tok = strtok(NULL, ",\n"))
        snprintf(names[ncol++], sizeof names[0], "%s", tok);
    assert_int_equal(ncol, AXES + 2);
    double last_hold = -1;
    while (fgets(line, sizeof line, csv)) {
        double v[AXES + 2];
        int n = 0;
        for (char *tok = strtok(line, ",\n"); tok && n < AXES + 2; tok = strtok(NULL, ",\n"))
            v[n++] = atof(tok);
        assert_int_equal(n, AXES + 2);
        double t = v[0];
        pose_reset(f->st);
        pose_bridge_frame fr;
        pose_status ps = pose_bridge_pose_at(b, t, f->st, &fr);
        if (ps < 0)
            fail_msg("pose_at %.2f: %s", t, pose_last_error());
        assert_int_equal(pose_apply(f->st), POSE_OK);
        if (v[AXES + 1] != 0)
            last_hold = t;
        if (last_hold >= 0 && t - last_hold < 0.5)
            continue; /* the hold button froze the joints; the filters catch up after */
        for (int i = 1; i <= AXES; i++) {
            char joint[48];
            int dof;
            axis_joint(names[i], joint, sizeof joint, &dof);
            double want[3] = {0, 0, 0};
            for (int k = 1; k <= AXES; k++) {
                char jk[48];
                int dk;
                axis_joint(names[k], jk, sizeof jk, &dk);
                if (!strcmp(jk, joint))
                    want[dk] = v[k];
            }
            int j = pose_rig_find_joint(f->rig, joint);
            assert_true(j >= 0);
            if (!tc_in_range(f->rig, j, want))
                continue;
            float hint[3] = {(float)want[0], (float)want[1], (float)want[2]}, got[3];
            tc_clinical_back(f->rig, f->st, j, hint, got);
            double e = fabs(got[dof] - v[i]);
            s->compared++;
            if (e > s->worst) {
                s->worst = e;
                s->worst_t = t;
                snprintf(s->worst_name, sizeof s->worst_name, "%s", names[i]);
            }
        }
    }
    fclose(csv);
    pose_bridge_close(b);
}

static void test_truth(void **state)
{
    fixture *f = *state;
    stats a = {0}, b = {0};
    truth_run(f, "usb/gonio_sit_to_stand.usbmon", "usb/gonio_sit_to_stand_truth.csv", &a);
    truth_run(f, "usb/gonio_arm_raise.usbmon", "usb/gonio_arm_raise_truth.csv", &b);
    print_message("USB truth: sit to stand %ld angles, worst %.2f deg (%s at %.2f s); arm raise %ld angles, worst "
                  "%.2f deg (%s at %.2f s)\n",
                  a.compared, a.worst, a.worst_name, a.worst_t, b.compared, b.worst, b.worst_name, b.worst_t);
    assert_true(a.compared > 1500 && b.compared > 1500);
    assert_true(a.worst < 2.0);
    assert_true(b.worst < 2.0);
}

/* The bridge thread plays the faulty capture to its end: 12 drops, the held pose, the faults named. */
static void test_faulty_capture_status(void **state)
{
    fixture *f = *state;
    char cp[1024];
    pose_bridge *b;
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map, .play = POSE_BRIDGE_AS_FAST_AS_POSSIBLE};
    if (pose_bridge_open(path(cp, sizeof cp, "POSE_DATA_DIR", "usb/gonio_reach_faults.usbmon"), f->rig, &o, &b) !=
        POSE_OK)
        fail_msg("%s", pose_last_error());
    pose_bridge_status s = {.size = sizeof s};
    for (int i = 0; i < 3000; i++) {
        assert_int_equal(pose_bridge_status_get(b, &s), POSE_OK);
        if (s.state == POSE_BRIDGE_ENDED)
            break;
        struct timespec ts = {0, 5000000};
        nanosleep(&ts, NULL);
    }
    print_message("faulty capture via pose/bridge.h: kind %s, samples %llu, drops %llu, poses %llu, fault '%s'\n",
                  s.kind, (unsigned long long)s.samples, (unsigned long long)s.drops, (unsigned long long)s.poses,
                  s.fault);
    assert_int_equal(s.state, POSE_BRIDGE_ENDED);
    assert_string_equal(s.kind, "usbmon-replay");
    assert_int_equal(s.drops, 12);
    assert_int_equal(s.samples, 3795);
    pose_bridge_frame fr;
    assert_true(pose_bridge_apply(b, f->st, &fr) >= 0);
    pose_bridge_close(b);
}

static void test_open_errors(void **state)
{
    fixture *f = *state;
    pose_bridge *b = NULL;
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map};
    assert_true(pose_bridge_open("usb:12", f->rig, &o, &b) < 0);
    assert_non_null(strstr(pose_last_error(), "expected usb:VID:PID"));
    pose_bridge_options no_usb = {.size = sizeof o,
                                  .map_json = "{\"channels\": [{\"channel\": \"x\", \"joint\": \"knee_l\", \"dof\": "
                                              "\"flexion\"}]}",
                                  .play = POSE_BRIDGE_AS_FAST_AS_POSSIBLE};
    char cp[1024];
    assert_true(pose_bridge_open(path(cp, sizeof cp, "POSE_DATA_DIR", "usb/gonio_arm_raise.usbmon"), f->rig, &no_usb,
                                 &b) < 0);
    assert_non_null(strstr(pose_last_error(), "no \"usb\" object describing the device's frame"));
    assert_true(pose_bridge_open("usbmon:/nonexistent/capture", f->rig, &o, &b) < 0);
    assert_non_null(strstr(pose_last_error(), "/nonexistent/capture"));
    o.play = POSE_BRIDGE_MANUAL;
    assert_true(pose_bridge_open("usb:1209:0002", f->rig, &o, &b) < 0); /* live: no recorded times */
    assert_null(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_truth),
        cmocka_unit_test(test_faulty_capture_status),
        cmocka_unit_test(test_open_errors),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
