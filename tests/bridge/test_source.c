/* SPDX-License-Identifier: Apache-2.0
 * The source interface through its mocap backend: channel naming, timed
 * reads (poll, timeout, pacing), end of clip with a status callback, seek,
 * loop, bad arguments; and a scalar-channel mapping over such a source. */
#include "bridge_test.h"
#include "clock.h"
#include "mapping.h"
#include "mocap_source.h"
#include "pb_math.h"

static const char *BVH = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
                         "JOINT Arm\n{\nOFFSET 1 0 0\nCHANNELS 2 Zrotation Xrotation\nEnd Site\n{\nOFFSET 1 0 0\n}\n}\n}\n"
                         "MOTION\nFrames: 3\nFrame Time: 0.05\n0 0 0 10 1\n1 0 0 20 2\n2 0 0 30 3\n";

typedef struct seen {
    int calls;
    pb_source_state last;
} seen;

static void on_status(pb_source *src, pb_source_state st, const char *msg, void *user)
{
    (void)src;
    (void)msg;
    seen *s = user;
    s->calls++;
    s->last = st;
}

static pb_clip *small_clip(void)
{
    pb_clip *c;
    pb_error err;
    if (pb_bvh_parse(BVH, strlen(BVH), "s.bvh", &c, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return c;
}

static void test_bad_arguments(void **state)
{
    (void)state;
    pb_clip *c = small_clip();
    pb_source *s = (pb_source *)1;
    pb_error err;
    assert_int_equal(pb_mocap_source_open(c, -1.0, 0, &s, &err), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pb_mocap_source_open(NULL, 1.0, 0, &s, &err), POSE_ERR_INVALID_ARGUMENT);
    pb_update u;
    assert_int_equal(pb_source_read(NULL, &u, 0), -1);
    assert_int_equal(pb_source_seek(NULL, 0), -1);
    pb_source_destroy(NULL);
    assert_string_equal(pb_source_state_name(PB_SOURCE_STALE), "stale");
    pb_clip_free(c);
}

static void test_afap_reads_seek_end(void **state)
{
    (void)state;
    pb_clip *c = small_clip();
    pb_source *s;
    pb_error err;
    assert_int_equal(pb_mocap_source_open(c, 0.0, 0, &s, &err), POSE_OK);
    seen sn = {0, PB_SOURCE_OK};
    s->on_status = on_status;
    s->on_status_user = &sn;
    assert_int_equal(s->channel_count, 5);
    assert_string_equal(s->channels[3].name, "Arm.Zrotation");
    assert_string_equal(s->channels[3].unit, "deg");
    assert_int_equal(pb_source_find_channel(s, "Hips.Yposition"), 1);
    assert_int_equal(pb_source_find_channel(s, "Arm.Yrotation"), -1);
    assert_int_equal(s->state, PB_SOURCE_WAITING);
    for (int f = 0; f < 3; f++) {
        pb_update u;
        assert_int_equal(pb_source_read(s, &u, 0), 1);
        assert_int_equal(u.count, 5);
        assert_int_equal(u.t_ns, (int64_t)f * 50000000);
        assert_near(u.values[3], 10.0 * (f + 1), 0);
        assert_int_equal(u.channels[4], 4);
    }
    assert_int_equal(s->state, PB_SOURCE_OK);
    pb_update u;
    assert_int_equal(pb_source_read(s, &u, 0), -1);
    assert_int_equal(s->state, PB_SOURCE_ENDED);
    assert_int_equal(sn.last, PB_SOURCE_ENDED);
    assert_non_null(strstr(s->message, "end of clip after 3 frames"));
    assert_int_equal(pb_source_seek(s, 50000000), 0);
    assert_int_equal(pb_source_read(s, &u, 0), 1);
    assert_near(u.values[0], 1.0, 0);
    pb_source_destroy(s);
    /* loop: frame 0 follows frame 2 */
    assert_int_equal(pb_mocap_source_open(c, 0.0, 1, &s, &err), POSE_OK);
    for (int i = 0; i < 4; i++)
        assert_int_equal(pb_source_read(s, &u, 0), 1);
    assert_near(u.values[0], 0.0, 0);
    pb_source_destroy(s);
    pb_clip_free(c);
}

static void test_paced_reads(void **state)
{
    (void)state;
    pb_clip *c = small_clip();
    pb_source *s;
    pb_error err;
    assert_int_equal(pb_mocap_source_open(c, 1.0, 0, &s, &err), POSE_OK);
    pb_update u;
    int64_t t0 = pb_now_ns();
    assert_int_equal(pb_source_read(s, &u, 0), 1); /* frame 0 is due at once */
    assert_int_equal(pb_source_read(s, &u, 0), 0); /* frame 1 not before 50 ms: a poll returns 0 */
    assert_int_equal(pb_source_read(s, &u, 1), 0); /* nor within a 1 ms timeout */
    assert_int_equal(pb_source_read(s, &u, -1), 1);
    assert_int_equal(pb_source_read(s, &u, -1), 1);
    double took = (double)(pb_now_ns() - t0) * 1e-9;
    assert_true(took >= 0.1 - 1e-4); /* frame 2 is due 100 ms after frame 0 */
    assert_near(u.values[3], 30.0, 0);
    pb_source_destroy(s);
    pb_clip_free(c);
}

static void test_channel_mapping_over_source(void **state)
{
    (void)state;
    pb_clip *c = small_clip();
    pb_source *s;
    pb_rig_skel *rig;
    pb_mapping *m;
    pb_chanmap *cm;
    pb_error err;
    assert_int_equal(pb_mocap_source_open(c, 0.0, 0, &s, &err), POSE_OK);
    assert_int_equal(pb_rig_skel_from_clip(c, 1.0, &rig, &err), POSE_OK);
    const char *js = "{\"channels\": [{\"channel\": \"Arm.Zrotation\", \"joint\": \"Arm\", \"axis\": \"z\", \"order\": \"ZXY\"},"
                     "{\"channel\": \"Arm.Xrotation\", \"joint\": \"Arm\", \"axis\": \"x\", \"order\": \"ZXY\"}]}";
    assert_int_equal(pb_mapping_parse(js, strlen(js), "m.json", &m, &err), POSE_OK);
    if (pb_chanmap_create(m, s->channels, s->channel_count, rig, &cm, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_pose pose;
    assert_int_equal(pb_pose_init(&pose, rig->joint_count), 0);
    pb_update u;
    assert_int_equal(pb_source_read(s, &u, 0), 1);
    assert_int_equal(pb_source_read(s, &u, 0), 1);
    pb_chanmap_update(cm, &u);
    pb_chanmap_pose(cm, &pose);
    /* the same rotation as the clip's own decoding of frame 1 (Rz 20 * Rx 2) */
    double lq[3][4], lt[3][3];
    pb_clip_local(c, pb_clip_frame(c, 1), lq, lt);
    double got[4] = {pose.q[1][0], pose.q[1][1], pose.q[1][2], pose.q[1][3]};
    assert_true(bt_quat_angle_deg(got, lq[1]) < 1e-4);
    pb_pose_free(&pose);
    pb_chanmap_free(cm);
    pb_mapping_free(m);
    pb_rig_skel_free(rig);
    pb_source_destroy(s);
    pb_clip_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_arguments),
        cmocka_unit_test(test_afap_reads_seek_end),
        cmocka_unit_test(test_paced_reads),
        cmocka_unit_test(test_channel_mapping_over_source),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
