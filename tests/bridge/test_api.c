/* SPDX-License-Identifier: Apache-2.0
 * pose/bridge.h through its public surface only: every kind of source opened
 * by its string (BVH, ASF/AMC, hid-recorder, candump), bad strings and
 * missing files with the messages pose_last_error() gives, the options size
 * rule and the allocator, POSE_BRIDGE_MANUAL + pose_bridge_pose_at against
 * the bridge thread at the same recorded times, the pose held while a
 * recording's device is silent (the CAN log's KNEE_L 5.0-5.5 s; a HID
 * recording with a gap), status counters, and pause/seek/speed. The rigs are
 * skeletons built here with one token tet (the bridge reads only joints):
 * the 19-joint full-body template with schematic clinical axes, and the
 * synthetic bar for CMU 131_01's right arm. */
#include "bridge_test.h"
#include "pose/bridge.h"
#include "pose_synth.h"

#include <time.h>

/* ------------------------------------------------------------------ rigs */

static pose_rig *skeleton_rig(const char *const *names, const int *parents, int n, int clinical)
{
    pose_joint_desc *j = calloc((size_t)n, sizeof *j);
    pose_joint_clinical *c = calloc((size_t)n, sizeof *c);
    assert_non_null(j);
    assert_non_null(c);
    for (int i = 0; i < n; i++) {
        j[i].name = names[i];
        j[i].parent = parents[i];
        j[i].rest_model.rotation[3] = 1.0f;
        j[i].rest_model.translation[2] = 0.1f * (float)i;
        if (clinical && i > 0) { /* neutral = rest; flexion y, abduction x, rotation z */
            c[i].neutral[3] = 1.0f;
            c[i].axes[0][1] = c[i].axes[1][0] = c[i].axes[2][2] = 1.0f;
            c[i].flags = POSE_CLINICAL_DEFINED;
        }
    }
    static const float tet_p[12] = {0, 0, 0, 0.01f, 0, 0, 0, 0.01f, 0, 0, 0, 0.01f};
    static const uint32_t tet[4] = {0, 1, 2, 3};
    static const uint16_t label[1] = {0}, wj[4] = {0, 0, 0, 0};
    static const float w[4] = {1, 1, 1, 1};
    pose_rig_desc d = {.joint_count = (size_t)n, .joints = j, .tet_vertex_count = 4, .tet_positions = tet_p,
                       .tet_count = 1, .tets = tet, .tet_labels = label, .influences = 1,
                       .weight_joints = wj, .weights = w, .clinical = clinical ? c : NULL};
    pose_rig *rig = NULL;
    pose_status s = pose_rig_create(&d, NULL, &rig);
    if (s != POSE_OK)
        fail_msg("pose_rig_create: %s", pose_last_error());
    free(j);
    free(c);
    return rig;
}

static pose_rig *body_rig(void)
{
    static const char *const names[] = {
        "pelvis", "lumbar", "thorax", "neck", "head", "clavicle_r", "shoulder_r", "elbow_r", "wrist_r",
        "clavicle_l", "shoulder_l", "elbow_l", "wrist_l", "hip_r", "knee_r", "ankle_r", "hip_l", "knee_l", "ankle_l"};
    static const int parents[] = {-1, 0, 1, 2, 3, 2, 5, 6, 7, 2, 9, 10, 11, 0, 13, 14, 0, 16, 17};
    return skeleton_rig(names, parents, 19, 1);
}

static pose_rig *bar_rig(void)
{
    pose_synth_bar_options bo = {.cor = POSE_SYNTH_COR_NONE};
    pose_synth_rig *bar;
    assert_int_equal(pose_synth_bar(&bo, &bar), POSE_OK);
    pose_rig *rig = NULL;
    assert_int_equal(pose_rig_create(pose_synth_desc(bar), NULL, &rig), POSE_OK);
    pose_synth_free(bar);
    return rig;
}

typedef struct fixture {
    pose_rig *body, *bar;
    char bvh[512], amc[512], hid[512], can[512];
    char map_bvh[512], map_amc[512], map_hid[512], map_can[512], map_bar[512];
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    f->body = body_rig();
    f->bar = bar_rig();
    BT_DATA(f->bvh, "mocap/cmu-bvh/131_01.bvh");
    BT_DATA(f->amc, "mocap/cmu-asf-amc/01_01.amc");
    BT_DATA(f->hid, "hid/mannequin_sit_to_stand.hid");
    BT_DATA(f->can, "can-rig/sit_stand_arm_raise.log");
    BT_MAP(f->map_bvh, "cmu131_bvh_to_full_body.json");
    BT_MAP(f->map_amc, "cmu_asf_to_full_body.json");
    BT_MAP(f->map_hid, "hid_mannequin_full_body.json");
    BT_MAP(f->map_can, "can_rig_fullbody.json");
    BT_MAP(f->map_bar, "cmu131_arm_to_bar.json");
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    pose_rig_free(f->body);
    pose_rig_free(f->bar);
    free(f);
    return 0;
}

static pose_bridge *open_ok(const char *source, const pose_rig *rig, const pose_bridge_options *o)
{
    pose_bridge *b = NULL;
    pose_status s = pose_bridge_open(source, rig, o, &b);
    if (s != POSE_OK)
        fail_msg("pose_bridge_open(%s): %s", source, pose_last_error());
    return b;
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* ------------------------------------------------------------ open kinds */

static void expect_kind(const char *source, const pose_rig *rig, const char *map, const char *kind, int joints_min)
{
    pose_bridge_options o = {.size = sizeof o, .map_path = map, .play = POSE_BRIDGE_MANUAL};
    pose_bridge *b = open_ok(source, rig, &o);
    pose_bridge_status st = {.size = sizeof st};
    assert_int_equal(pose_bridge_status_get(b, &st), POSE_OK);
    assert_string_equal(st.kind, kind);
    assert_int_equal(st.connected, 1);
    assert_true(st.duration_s > 1.0);
    pose_state *ps;
    assert_int_equal(pose_state_create(rig, &ps), POSE_OK);
    pose_bridge_frame fr;
    assert_true(pose_bridge_pose_at(b, 1.0, ps, &fr) >= 0);
    assert_true(fr.joints >= joints_min);
    assert_true(fr.fresh);
    assert_true(fr.media_s <= 1.0 + 1e-9 && fr.media_s > 0.9);
    pose_state_free(ps);
    pose_bridge_close(b);
}

static void test_open_each_kind(void **state)
{
    fixture *f = *state;
    expect_kind(f->bvh, f->body, f->map_bvh, "bvh", 10);
    expect_kind(f->amc, f->body, f->map_amc, "asf-amc", 10);
    expect_kind(f->hid, f->body, f->map_hid, "hid-replay", 10);
    expect_kind(f->can, f->body, f->map_can, "candump-replay", 10);
    /* the same files by explicit kind */
    char spec[600];
    snprintf(spec, sizeof spec, "hid-recording:%s", f->hid);
    expect_kind(spec, f->body, f->map_hid, "hid-replay", 10);
    snprintf(spec, sizeof spec, "candump:%s", f->can);
    expect_kind(spec, f->body, f->map_can, "candump-replay", 10);
}

/* ------------------------------------------------------------ bad input */

static void expect_error(const char *source, const pose_rig *rig, const pose_bridge_options *o, pose_status want,
                         const char *needle)
{
    pose_bridge *b = (pose_bridge *)1;
    pose_status s = pose_bridge_open(source, rig, o, &b);
    assert_int_equal(s, want);
    assert_null(b);
    if (!strstr(pose_last_error(), needle))
        fail_msg("pose_bridge_open(%s): message \"%s\" lacks \"%s\"", source ? source : "NULL", pose_last_error(),
                 needle);
}

static void test_bad_sources(void **state)
{
    fixture *f = *state;
    pose_bridge_options hid = {.size = sizeof hid, .map_path = f->map_hid};
    expect_error(NULL, f->body, NULL, POSE_ERR_INVALID_ARGUMENT, "source and rig are required");
    expect_error("", f->body, NULL, POSE_ERR_INVALID_ARGUMENT, "empty source");
    expect_error("motion.xyz", f->body, NULL, POSE_ERR_INVALID_ARGUMENT, "motion.xyz: unknown kind of source");
    expect_error("bvh:", f->body, NULL, POSE_ERR_INVALID_ARGUMENT, "nothing after 'bvh:'");
    expect_error("/nonexistent/walk.bvh", f->body, NULL, POSE_ERR_IO, "/nonexistent/walk.bvh");
    expect_error("/nonexistent/take.hid", f->body, &hid, POSE_ERR_IO, "/nonexistent/take.hid");
    expect_error("hid:zz:1", f->body, &hid, POSE_ERR_INVALID_ARGUMENT, "expected hid:VID:PID");
    /* device sources need a mapping with channels */
    expect_error(f->hid, f->body, NULL, POSE_ERR_INVALID_ARGUMENT, "needs a mapping");
    /* a clip without a mapping drives rig joints of the same name: the bar has none of 131_01's */
    expect_error(f->bvh, f->bar, NULL, POSE_ERR_NOT_FOUND, "no rig joint is driven");
    pose_bridge_options missing = {.size = sizeof missing, .map_path = "/nonexistent/map.json"};
    expect_error(f->hid, f->body, &missing, POSE_ERR_IO, "/nonexistent/map.json");
    /* a mapping that names a joint the rig lacks: the mapping file and the entry */
    pose_bridge_options bad = {.size = sizeof bad, .map_json = "{\"channels\": [{\"channel\": \"Ordinal.1\", "
                                                               "\"joint\": \"tail\", \"axis\": \"x\"}]}"};
    expect_error(f->hid, f->body, &bad, POSE_ERR_NOT_FOUND, "tail");
    pose_bridge_options syntax = {.size = sizeof syntax, .map_json = "{\"channels\": ["};
    expect_error(f->hid, f->body, &syntax, POSE_ERR_FORMAT, "map_json");
    /* a live source cannot be stepped by recorded time */
    pose_bridge_options manual = {.size = sizeof manual, .map_path = f->map_hid, .play = POSE_BRIDGE_MANUAL};
    expect_error("hid:1209:0001", f->body, &manual, POSE_ERR_UNSUPPORTED, "live source");
    /* options: the size rule and values */
    pose_bridge_options small = {.size = 8};
    expect_error(f->bvh, f->body, &small, POSE_ERR_INVALID_ARGUMENT, "options.size 8");
    pose_bridge_options neg = {.size = sizeof neg, .speed = -1};
    expect_error(f->bvh, f->body, &neg, POSE_ERR_INVALID_ARGUMENT, "options.speed");
    pose_bridge_options both = {.size = sizeof both, .map_path = f->map_bvh, .map_json = "{}"};
    expect_error(f->bvh, f->body, &both, POSE_ERR_INVALID_ARGUMENT, "not both");
    assert_int_equal(pose_bridge_open(f->bvh, f->body, NULL, NULL), POSE_ERR_INVALID_ARGUMENT);
}

static void test_calls_on_bad_arguments(void **state)
{
    fixture *f = *state;
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map_can, .play = POSE_BRIDGE_MANUAL};
    pose_bridge *b = open_ok(f->can, f->body, &o);
    pose_state *other;
    assert_int_equal(pose_state_create(f->bar, &other), POSE_OK);
    assert_int_equal(pose_bridge_apply(b, other, NULL), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "another rig"));
    assert_int_equal(pose_bridge_pose_at(b, 99.0, NULL, NULL), POSE_ERR_INVALID_ARGUMENT);
    pose_state *ps;
    assert_int_equal(pose_state_create(f->body, &ps), POSE_OK);
    assert_int_equal(pose_bridge_pose_at(b, 99.0, ps, NULL), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "past the end of the recording"));
    assert_int_equal(pose_bridge_pose_at(b, -1.0, ps, NULL), POSE_ERR_INVALID_ARGUMENT);
    /* MANUAL has no thread to control */
    assert_int_equal(pose_bridge_pause(b, 1), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_bridge_seek(b, 1.0), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_bridge_wait(b, 10), 0);
    pose_bridge_status small = {.size = 4};
    assert_int_equal(pose_bridge_status_get(b, &small), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_bridge_warning_count(b), 0);
    assert_null(pose_bridge_warning(b, 0));
    assert_string_equal(pose_bridge_state_name(POSE_BRIDGE_STALE), "stale");
    pose_state_free(ps);
    pose_state_free(other);
    pose_bridge_close(b);
    pose_bridge_close(NULL);
}

/* ------------------------------------------------ MANUAL == bridge thread */

enum { MAX_SNAPS = 64, MAX_J = 64 };
typedef struct snap {
    double media_s;
    float q[MAX_J][4];
} snap;

static void read_joints(const pose_state *ps, int n, float (*q)[4])
{
    for (int j = 0; j < n; j++)
        assert_int_equal(pose_get_joint(ps, j, q[j]), POSE_OK);
}

/* Poses the bridge thread published at the times the host caught them are
 * the poses pose_bridge_pose_at builds for those times, to the bit. */
static void expect_manual_matches(const char *source, const pose_rig *rig, const char *map)
{
    int n = (int)pose_rig_joint_count(rig);
    assert_true(n <= MAX_J);
    /* The first 1.2 s at x2, from the start: pose_at replays from the start, through the same filters. */
    pose_bridge_options o = {.size = sizeof o, .map_path = map, .speed = 2.0, .end_s = 1.2};
    pose_bridge *run = open_ok(source, rig, &o);
    pose_state *ps;
    assert_int_equal(pose_state_create(rig, &ps), POSE_OK);
    static snap snaps[MAX_SNAPS];
    int count = 0;
    for (int ended = 0; !ended && count < MAX_SNAPS;) {
        ended = pose_bridge_wait(run, 15);
        pose_bridge_frame fr;
        assert_true(pose_bridge_apply(run, ps, &fr) >= 0);
        if (fr.fresh) {
            snaps[count].media_s = fr.media_s;
            read_joints(ps, n, snaps[count].q);
            count++;
        }
    }
    pose_bridge_close(run);
    assert_true(count >= 2);

    o.play = POSE_BRIDGE_MANUAL;
    pose_bridge *man = open_ok(source, rig, &o);
    for (int k = count - 1; k >= 0; k -= (k > 3 ? 3 : 1)) { /* backwards: every request starts over */
        pose_bridge_frame fr;
        if (pose_bridge_pose_at(man, snaps[k].media_s, ps, &fr) < 0)
            fail_msg("pose_bridge_pose_at(%s, %.6f): %s", source, snaps[k].media_s, pose_last_error());
        assert_near(fr.media_s, snaps[k].media_s, 1e-12);
        float q[MAX_J][4];
        read_joints(ps, n, q);
        for (int j = 0; j < n; j++)
            for (int c = 0; c < 4; c++)
                if (q[j][c] != snaps[k].q[j][c])
                    fail_msg("%s at %.6f s: joint %d differs (%g vs %g)", source, snaps[k].media_s, j, q[j][c],
                             snaps[k].q[j][c]);
    }
    pose_bridge_close(man);
    pose_state_free(ps);
}

static void test_manual_matches_thread(void **state)
{
    fixture *f = *state;
    expect_manual_matches(f->bvh, f->bar, f->map_bar);
    expect_manual_matches(f->amc, f->body, f->map_amc);
    expect_manual_matches(f->hid, f->body, f->map_hid);
    expect_manual_matches(f->can, f->body, f->map_can);
}

/* ---------------------------------------------------------------- held */

static void test_held_can_silence(void **state)
{
    fixture *f = *state;
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map_can, .play = POSE_BRIDGE_MANUAL};
    pose_bridge *b = open_ok(f->can, f->body, &o);
    pose_state *ps;
    assert_int_equal(pose_state_create(f->body, &ps), POSE_OK);
    int knee = pose_rig_find_joint(f->body, "knee_l");
    pose_bridge_frame fr;
    assert_true(pose_bridge_pose_at(b, 4.9, ps, &fr) >= 0);
    assert_false(fr.held);
    float before[4], during[4];
    assert_true(pose_bridge_pose_at(b, 5.1, ps, &fr) >= 0);
    assert_true(fr.held); /* KNEE_L silent since 5.0 s */
    pose_get_joint(ps, knee, before);
    assert_true(pose_bridge_pose_at(b, 5.45, ps, &fr) >= 0);
    assert_true(fr.held);
    assert_true(fr.fresh);
    pose_get_joint(ps, knee, during);
    for (int c = 0; c < 4; c++)
        assert_true(before[c] == during[c]); /* the knee holds its last good angle */
    pose_bridge_status st = {.size = sizeof st};
    assert_int_equal(pose_bridge_status_get(b, &st), POSE_OK);
    assert_int_equal(st.state, POSE_BRIDGE_STALE);
    if (!strstr(st.fault, "KNEE_L"))
        fail_msg("fault \"%s\" does not name KNEE_L", st.fault);
    assert_true(pose_bridge_pose_at(b, 5.7, ps, &fr) >= 0);
    assert_false(fr.held); /* the node is back */
    pose_state_free(ps);
    pose_bridge_close(b);
}

/* A copy of the HID recording without its reports in [from, to) seconds. */
static void write_gap_recording(const char *src, const char *dst, double from, double to)
{
    FILE *in = fopen(src, "r"), *out = fopen(dst, "w");
    assert_non_null(in);
    assert_non_null(out);
    char line[4096];
    while (fgets(line, sizeof line, in)) {
        double t;
        if (strncmp(line, "E: ", 3) == 0 && sscanf(line + 3, "%lf", &t) == 1 && t >= from && t < to)
            continue;
        fputs(line, out);
    }
    fclose(in);
    fclose(out);
}

static void test_held_hid_gap_manual(void **state)
{
    fixture *f = *state;
    char gap[512];
    BT_TMP(gap, "gap.hid");
    write_gap_recording(f->hid, gap, 3.0, 4.0);
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map_hid, .play = POSE_BRIDGE_MANUAL};
    pose_bridge *b = open_ok(gap, f->body, &o);
    pose_state *ps;
    assert_int_equal(pose_state_create(f->body, &ps), POSE_OK);
    pose_bridge_frame fr;
    assert_true(pose_bridge_pose_at(b, 2.9, ps, &fr) >= 0);
    assert_false(fr.held);
    assert_true(pose_bridge_pose_at(b, 3.5, ps, &fr) >= 0);
    assert_true(fr.held); /* 0.5 s without a report: beyond stale_after_s (0.25) */
    assert_true(fr.age_s > 0.49 && fr.age_s < 0.51);
    assert_true(pose_bridge_pose_at(b, 4.1, ps, &fr) >= 0);
    assert_false(fr.held);
    pose_state_free(ps);
    pose_bridge_close(b);
}

/* The bridge thread plays the gap at recorded timing: the host sees held
 * (with no fresh poses) during it, and fresh poses again after it. */
static void test_held_hid_gap_thread(void **state)
{
    fixture *f = *state;
    char gap[512];
    BT_TMP(gap, "gap_thread.hid");
    write_gap_recording(f->hid, gap, 3.0, 4.0);
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map_hid, .start_s = 2.6, .end_s = 4.5};
    pose_bridge *b = open_ok(gap, f->body, &o);
    pose_state *ps;
    assert_int_equal(pose_state_create(f->body, &ps), POSE_OK);
    int saw_fresh_before = 0, saw_held = 0, saw_fresh_after = 0;
    for (int i = 0; i < 1000 && pose_bridge_wait(b, 5) == 0; i++) {
        pose_bridge_frame fr;
        assert_true(pose_bridge_apply(b, ps, &fr) >= 0);
        if (fr.fresh && fr.media_s < 3.0)
            saw_fresh_before = 1;
        if (fr.held) {
            saw_held = 1;
            assert_true(fr.media_s < 3.0); /* the last good pose before the gap */
        }
        if (fr.fresh && fr.media_s >= 4.0 && !fr.held)
            saw_fresh_after = 1;
    }
    assert_true(saw_fresh_before);
    assert_true(saw_held);
    assert_true(saw_fresh_after);
    pose_bridge_status st = {.size = sizeof st};
    assert_int_equal(pose_bridge_status_get(b, &st), POSE_OK);
    assert_int_equal(st.state, POSE_BRIDGE_ENDED); /* end_s */
    assert_non_null(strstr(st.fault, "no report for 250 ms"));
    pose_state_free(ps);
    pose_bridge_close(b);
}

/* ------------------------------------------------------------- status */

static void test_status_counters(void **state)
{
    fixture *f = *state;
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map_can, .play = POSE_BRIDGE_AS_FAST_AS_POSSIBLE};
    pose_bridge *b = open_ok(f->can, f->body, &o);
    assert_int_equal(pose_bridge_wait(b, 20000), 1);
    pose_bridge_status st = {.size = sizeof st};
    assert_int_equal(pose_bridge_status_get(b, &st), POSE_OK);
    assert_int_equal(st.state, POSE_BRIDGE_ENDED);
    assert_string_equal(pose_bridge_state_name((pose_bridge_source_state)st.state), "ended");
    assert_true(st.samples > 30000); /* 32,944 frames, most with values */
    assert_true(st.poses == st.samples);
    assert_true(st.drops >= 8);      /* 7 malformed lines and a 2-byte ELBOW_R frame */
    assert_true(st.last_sample_age_s >= 0 && st.last_sample_age_s < 20);
    assert_true(st.media_s > 9.9 && st.media_s < 10.1);
    assert_true(st.duration_s > 9.9 && st.duration_s < 10.1);
    assert_int_equal(st.frame, -1);
    assert_int_equal(st.frame_count, -1);
    assert_true(st.fault[0] != '\0'); /* silence, bus-off ... along the way */
    pose_bridge_close(b);

    /* a clip: frames, frame time, poses */
    pose_bridge_options c = {.size = sizeof c, .map_path = f->map_bar, .play = POSE_BRIDGE_AS_FAST_AS_POSSIBLE,
                             .max_poses = 30};
    b = open_ok(f->bvh, f->bar, &c);
    assert_int_equal(pose_bridge_wait(b, 20000), 1);
    assert_int_equal(pose_bridge_status_get(b, &st), POSE_OK);
    assert_int_equal(st.poses, 30);
    assert_int_equal(st.frame, 29);
    assert_true(st.frame_count > 100);
    assert_near(st.frame_time_s, 1.0 / 120.0, 1e-6);
    assert_near(st.duration_s, (double)(st.frame_count - 1) * st.frame_time_s, 1e-9);
    assert_int_equal(st.last_sample_age_s >= 0, 1);
    pose_bridge_close(b);
}

/* ------------------------------------------------------- pause and seek */

static pose_bridge_frame wait_fresh(pose_bridge *b, pose_state *ps)
{
    for (int i = 0; i < 2000; i++) {
        pose_bridge_frame fr;
        assert_true(pose_bridge_apply(b, ps, &fr) >= 0);
        if (fr.fresh)
            return fr;
        sleep_ms(1);
    }
    fail_msg("no fresh pose within 2 s");
    return (pose_bridge_frame){0};
}

static void test_clip_pause_seek_speed(void **state)
{
    fixture *f = *state;
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map_bar, .start_paused = 1};
    pose_bridge *b = open_ok(f->bvh, f->bar, &o);
    pose_state *ps;
    assert_int_equal(pose_state_create(f->bar, &ps), POSE_OK);
    sleep_ms(30);
    pose_bridge_frame fr;
    assert_int_equal(pose_bridge_apply(b, ps, &fr), POSE_OK);
    assert_false(fr.fresh); /* paused from the start: nothing yet */
    assert_int_equal(fr.seq, 0);
    assert_int_equal(fr.joints, 0);
    assert_int_equal(pose_bridge_seek(b, 2.0), POSE_OK); /* paused: the pose at 2 s shows */
    fr = wait_fresh(b, ps);
    assert_near(fr.media_s, 2.0, 1e-9);
    assert_true(fr.joints > 0);
    pose_bridge_status st = {.size = sizeof st};
    assert_int_equal(pose_bridge_status_get(b, &st), POSE_OK);
    assert_int_equal(st.frame, 240);
    sleep_ms(30);
    assert_int_equal(pose_bridge_apply(b, ps, &fr), POSE_OK);
    assert_false(fr.fresh); /* still paused */
    assert_int_equal(pose_bridge_set_speed(b, 4.0), POSE_OK);
    assert_int_equal(pose_bridge_set_speed(b, 0.0), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_bridge_pause(b, 0), POSE_OK);
    fr = wait_fresh(b, ps);
    assert_true(fr.media_s > 2.0 && fr.media_s < 3.0);
    sleep_ms(100);
    fr = wait_fresh(b, ps);
    assert_true(fr.media_s > 2.2); /* x4: 0.1 s of wall time is 0.4 s of clip */
    pose_state_free(ps);
    pose_bridge_close(b);
}

static void test_recording_pause_seek(void **state)
{
    fixture *f = *state;
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map_can};
    pose_bridge *b = open_ok(f->can, f->body, &o);
    pose_state *ps;
    assert_int_equal(pose_state_create(f->body, &ps), POSE_OK);
    pose_bridge_frame fr = wait_fresh(b, ps);
    assert_true(fr.media_s < 1.0);
    assert_int_equal(pose_bridge_set_speed(b, 2.0), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_bridge_seek(b, 6.0), POSE_OK);
    for (int i = 0; i < 200; i++) {
        fr = wait_fresh(b, ps);
        if (fr.media_s >= 6.0)
            break;
    }
    assert_true(fr.media_s >= 6.0 && fr.media_s < 7.0);
    assert_int_equal(pose_bridge_pause(b, 1), POSE_OK);
    sleep_ms(50);
    pose_bridge_apply(b, ps, &fr); /* whatever came before the pause took effect */
    double at = fr.media_s;
    sleep_ms(200);
    assert_int_equal(pose_bridge_apply(b, ps, &fr), POSE_OK);
    assert_false(fr.fresh);
    assert_near(fr.media_s, at, 1e-12);
    assert_true(fr.age_s >= 0.19);
    assert_int_equal(pose_bridge_pause(b, 0), POSE_OK);
    fr = wait_fresh(b, ps);
    assert_true(fr.media_s > at && fr.media_s < at + 0.1); /* continues where it stopped */
    pose_state_free(ps);
    pose_bridge_close(b);
}

/* ------------------------------------------------------------ allocator */

typedef struct counts {
    long allocs, frees;
} counts;

static void *count_alloc(size_t size, size_t align, void *user)
{
    ((counts *)user)->allocs++;
    void *p = NULL;
    return posix_memalign(&p, align < sizeof(void *) ? sizeof(void *) : align, size) == 0 ? p : NULL;
}

static void count_free(void *p, void *user)
{
    ((counts *)user)->frees++;
    free(p);
}

static void test_allocator(void **state)
{
    fixture *f = *state;
    counts c = {0, 0};
    pose_bridge_options o = {.size = sizeof o, .map_path = f->map_hid, .play = POSE_BRIDGE_MANUAL,
                             .allocator = {count_alloc, count_free, &c}};
    pose_bridge *b = open_ok(f->hid, f->body, &o);
    pose_state *ps;
    assert_int_equal(pose_state_create(f->body, &ps), POSE_OK);
    assert_true(pose_bridge_pose_at(b, 2.0, ps, NULL) >= 0);
    assert_true(c.allocs >= 3); /* the handle, the source string, the scrubber's pose */
    pose_bridge_close(b);
    assert_int_equal(c.allocs, c.frees);
    /* size 0: every option at its default, the rest of the struct unread (no
     * complaint about speed or play; the default mapping matches no bar joint) */
    pose_bridge_options zero = {.size = 0, .speed = -5, .play = (pose_bridge_play)77};
    expect_error(f->bvh, f->bar, &zero, POSE_ERR_NOT_FOUND, "no rig joint is driven");
    pose_state_free(ps);
}

/* ------------------------------------------------------------- warnings */

/* The HID recording with a 0x00 after its descriptor's last item: accepted,
 * as the Linux kernel accepts it, with a warning naming the file and byte. */
static void test_warnings(void **state)
{
    fixture *f = *state;
    char path[512];
    BT_TMP(path, "trailing_zero.hid");
    FILE *in = fopen(f->hid, "r"), *out = fopen(path, "w");
    assert_non_null(in);
    assert_non_null(out);
    char line[4096];
    while (fgets(line, sizeof line, in)) {
        unsigned n;
        char *rest;
        if (strncmp(line, "R: ", 3) == 0 && (n = (unsigned)strtoul(line + 3, &rest, 10)) > 0) {
            rest[strcspn(rest, "\r\n")] = '\0';
            fprintf(out, "R: %u%s 00\n", n + 1, rest);
        } else {
            fputs(line, out);
        }
    }
    fclose(in);
    fclose(out);
    pose_bridge_play plays[2] = {POSE_BRIDGE_MANUAL, POSE_BRIDGE_AS_FAST_AS_POSSIBLE};
    for (int k = 0; k < 2; k++) {
        pose_bridge_options o = {.size = sizeof o, .map_path = f->map_hid, .play = plays[k]};
        pose_bridge *b = open_ok(path, f->body, &o);
        assert_int_equal(pose_bridge_warning_count(b), 1);
        const char *w = pose_bridge_warning(b, 0);
        if (!strstr(w, path) || !strstr(w, "trailing 0x00"))
            fail_msg("warning \"%s\" does not name the file and the trailing byte", w);
        assert_null(pose_bridge_warning(b, 1));
        pose_bridge_close(b);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_sources),
        cmocka_unit_test(test_calls_on_bad_arguments),
        cmocka_unit_test(test_open_each_kind),
        cmocka_unit_test(test_manual_matches_thread),
        cmocka_unit_test(test_held_can_silence),
        cmocka_unit_test(test_held_hid_gap_manual),
        cmocka_unit_test(test_held_hid_gap_thread),
        cmocka_unit_test(test_status_counters),
        cmocka_unit_test(test_clip_pause_seek_speed),
        cmocka_unit_test(test_recording_pause_seek),
        cmocka_unit_test(test_allocator),
        cmocka_unit_test(test_warnings),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
