/* SPDX-License-Identifier: Apache-2.0
 * Mapping files: invalid input first (syntax, fields, unknown joints and
 * channels), then the scalar-channel stages (calibration, inversion,
 * deadband, limits, Euler composition) with hand-computed values, and the
 * ranges of motion a map gives the state it drives. */
#include "bridge_test.h"
#include "pb_warn.h"
#include "mapping.h"
#include "pb_math.h"

static void expect_parse_error(const char *json, const char *fragment)
{
    pb_mapping *m = (pb_mapping *)1;
    pb_error err;
    assert_int_equal(pb_mapping_parse(json, strlen(json), "m.json", &m, &err), POSE_ERR_FORMAT);
    assert_null(m);
    if (!strstr(err.message, fragment))
        fail_msg("message '%s' lacks '%s'", err.message, fragment);
}

static void test_bad_mapping_files(void **state)
{
    (void)state;
    expect_parse_error("{\n\"joints\": {\n\"a\": \"b\",\n}\n}", "m.json:4: invalid JSON");
    expect_parse_error("[1, 2]", "expected a JSON object at the top");
    expect_parse_error("{\"joints\": {\"knee\": 3}}", "joints.knee: expected a clip joint name");
    expect_parse_error("{\"joints\": [\"knee\"]}", "joints: expected an object");
    expect_parse_error("{\"scale\": -1}", "scale: expected a positive number");
    expect_parse_error("{\"root_motion\": \"up\"}", "root_motion: expected");
    expect_parse_error("{\"reference\": 1.5}", "reference: expected \"zero\" or a frame number");
    expect_parse_error("{\"source_axes\": {\"up\": \"+y\", \"forward\": \"-y\"}, \"rig_axes\": {\"up\": \"+z\", \"forward\": \"+x\"}}",
                       "source_axes: expected");
    expect_parse_error("{\"source_axes\": {\"up\": \"+y\", \"forward\": \"+z\"}}", "rig_axes: expected");
    expect_parse_error("{\"filter\": {\"beta\": -1}}", "filter.beta: expected a non-negative number");
    expect_parse_error("{\"channels\": [{\"channel\": \"a\", \"joint\": \"j\", \"axis\": \"w\"}]}",
                       "channels[0].axis: expected");
    expect_parse_error("{\"channels\": [{\"joint\": \"j\", \"axis\": \"x\"}]}", "channels[0]: needs \"channel\" or \"usage\"");
    expect_parse_error("{\"channels\": [{\"channel\": \"a\", \"joint\": \"j\"}]}",
                       "channels[0]: needs \"dof\" (a clinical angle) or \"axis\"");
    expect_parse_error("{\"channels\": [{\"channel\": \"a\", \"joint\": \"j\", \"dof\": \"flexion\", \"axis\": \"x\"}]}",
                       "channels[0]: \"axis\" and \"dof\" exclude each other");
    expect_parse_error("{\"channels\": [{\"channel\": \"a\", \"joint\": \"j\", \"dof\": 3}]}", "channels[0].dof: expected");
    expect_parse_error("{\"channels\": [{\"channel\": \"a\", \"joint\": \"j\", \"axis\": \"x\", \"calibration\": "
                       "{\"raw\": [1, 1], \"deg\": [0, 90]}}]}",
                       "channels[0].calibration.raw: the two points are equal");
    expect_parse_error("{\"channels\": [{\"channel\": \"a\", \"joint\": \"j\", \"axis\": \"x\", \"limits\": [10, -10]}]}",
                       "channels[0].limits: min is above max");
    expect_parse_error("{\"channels\": [{\"usage\": \"0x1zz\", \"joint\": \"j\", \"axis\": \"x\"}]}",
                       "channels[0].usage: expected");
    expect_parse_error("{\"channels\": [{\"channel\": \"a\", \"joint\": \"j\", \"axis\": \"x\", \"order\": \"XXY\"}]}",
                       "channels[0].order: expected");
    expect_parse_error("{\"joints\": {\"a\": \"b\", \"a\": \"c\"}}", "joints.a: rig joint mapped twice");
    expect_parse_error("{\"ranges\": [1]}", "m.json: ranges: expected an object {rig joint: {angle: [min, max]}}");
    expect_parse_error("{\"ranges\": {\"ankle_r\": [-50, 35]}}",
                       "m.json: ranges.ankle_r: expected an object of 1 to 3 angles");
    expect_parse_error("{\"ranges\": {\"ankle_r\": {}}}", "m.json: ranges.ankle_r: expected an object of 1 to 3 angles");
    expect_parse_error("{\"ranges\": {\"ankle_r\": {\"a\": [0, 1], \"b\": [0, 1], \"c\": [0, 1], \"d\": [0, 1]}}}",
                       "ranges.ankle_r: expected an object of 1 to 3 angles");
    expect_parse_error("{\"ranges\": {\"ankle_r\": {\"flexion\": [-50]}}}",
                       "m.json: ranges.ankle_r.flexion: expected [number, number]");
    expect_parse_error("{\"ranges\": {\"ankle_r\": {\"flexion\": [35, -50]}}}",
                       "m.json: ranges.ankle_r.flexion: min 35 is above max -50");
    expect_parse_error("{\"ranges\": {\"ankle_r\": {\"flexion\": [0, 1]}, \"ankle_r\": {\"flexion\": [0, 2]}}}",
                       "m.json: ranges.ankle_r: joint given twice");
    pb_mapping *m;
    pb_error err;
    assert_int_equal(pb_mapping_load("/nonexistent/map.json", &m, &err), POSE_ERR_IO);
    assert_non_null(strstr(err.message, "/nonexistent/map.json"));
}

static const char *BVH = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition "
                         "Zrotation Xrotation Yrotation\nJOINT Arm\n{\nOFFSET 1 0 0\nCHANNELS 3 Zrotation Xrotation "
                         "Yrotation\nEnd Site\n{\nOFFSET 1 0 0\n}\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n"
                         "0 0 0 0 0 0 0 0 0\n";

static void test_unknown_joints(void **state)
{
    (void)state;
    pb_clip *clip;
    pb_rig_skel *rig;
    pb_error err;
    assert_int_equal(pb_bvh_parse(BVH, strlen(BVH), "t.bvh", &clip, &err), POSE_OK);
    assert_int_equal(pb_rig_skel_from_clip(clip, 1.0, &rig, &err), POSE_OK);
    const char *j1 = "{\"joints\": {\"elbow\": \"Arm\"}}";
    const char *j2 = "{\"joints\": {\"Arm\": \"ForeArm\"}}";
    pb_mapping *m;
    pb_retarget *r = (pb_retarget *)1;
    assert_int_equal(pb_mapping_parse(j1, strlen(j1), "m.json", &m, &err), POSE_OK);
    assert_int_equal(pb_retarget_create(m, clip, rig, &r, &err), POSE_ERR_NOT_FOUND);
    assert_null(r);
    assert_string_equal(err.message, "m.json: joints.elbow: the rig has no joint 'elbow'");
    pb_mapping_free(m);
    assert_int_equal(pb_mapping_parse(j2, strlen(j2), "m.json", &m, &err), POSE_OK);
    assert_int_equal(pb_retarget_create(m, clip, rig, &r, &err), POSE_ERR_NOT_FOUND);
    assert_string_equal(err.message, "m.json: joints.Arm: the clip t.bvh has no joint 'ForeArm'");
    pb_mapping_free(m);
    const char *j3 = "{\"joints\": {\"Arm\": \"Arm\"}, \"reference\": 5}";
    assert_int_equal(pb_mapping_parse(j3, strlen(j3), "m.json", &m, &err), POSE_OK);
    assert_int_equal(pb_retarget_create(m, clip, rig, &r, &err), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err.message, "reference: frame 5 is beyond the clip's 1 frames"));
    pb_mapping_free(m);
    /* channels: unknown channel, unknown usage, unknown joint */
    pb_channel ch[2] = {{.name = "A", .usage = 0x00010030}, {.name = "B", .usage = 0x00010030}};
    pb_chanmap *cm;
    const char *c1 = "{\"channels\": [{\"channel\": \"C\", \"joint\": \"Arm\", \"axis\": \"x\"}]}";
    const char *c2 = "{\"channels\": [{\"usage\": \"0x00010030\", \"index\": 2, \"joint\": \"Arm\", \"axis\": \"x\"}]}";
    const char *c3 = "{\"channels\": [{\"channel\": \"A\", \"joint\": \"Leg\", \"axis\": \"x\"}]}";
    const char *c[3] = {c1, c2, c3};
    const char *want[3] = {"m.json: channels[0].channel: the source has no channel 'C'",
                           "m.json: channels[0].usage: the source has no channel #2 with usage 0x00010030",
                           "m.json: channels[0].joint: the rig has no joint 'Leg'"};
    for (int i = 0; i < 3; i++) {
        assert_int_equal(pb_mapping_parse(c[i], strlen(c[i]), "m.json", &m, &err), POSE_OK);
        assert_int_equal(pb_chanmap_create(m, ch, 2, rig, &cm, &err), POSE_ERR_NOT_FOUND);
        assert_string_equal(err.message, want[i]);
        pb_mapping_free(m);
    }
    pb_rig_skel_free(rig);
    pb_clip_free(clip);
}

static void test_channel_stages(void **state)
{
    (void)state;
    pb_clip *clip;
    pb_rig_skel *rig;
    pb_error err;
    assert_int_equal(pb_bvh_parse(BVH, strlen(BVH), "t.bvh", &clip, &err), POSE_OK);
    assert_int_equal(pb_rig_skel_from_clip(clip, 1.0, &rig, &err), POSE_OK);
    const char *js = "{\"channels\": ["
                     "{\"channel\": \"A\", \"joint\": \"Arm\", \"axis\": \"x\", \"order\": \"ZXY\","
                     " \"calibration\": {\"raw\": [100, 300], \"deg\": [-90, 90]}, \"deadband\": 2, \"limits\": [-60, 60]},"
                     "{\"usage\": 65585, \"joint\": \"Arm\", \"axis\": \"z\", \"order\": \"ZXY\","
                     " \"calibration\": {\"offset\": -512, \"scale\": 0.5}, \"invert\": true}]}";
    pb_mapping *m;
    assert_int_equal(pb_mapping_parse(js, strlen(js), "m.json", &m, &err), POSE_OK);
    /* two-point: 100 -> -90, 300 -> 90, so 150 -> -45 */
    assert_near(pb_map_channel_transform(&m->channels[0], 150), -45.0, 1e-12);
    /* linear then inverted: -((700 - 512) * 0.5) = -94 */
    assert_near(pb_map_channel_transform(&m->channels[1], 700), -94.0, 1e-12);
    pb_channel ch[2] = {{.name = "A"}, {.name = "Y", .usage = 0x00010031}};
    pb_chanmap *cm;
    if (pb_chanmap_create(m, ch, 2, rig, &cm, &err) != POSE_OK)
        fail_msg("%s", err.message);
    uint32_t idx[2] = {0, 1};
    double v[2] = {150, 532};
    pb_update u = {.t_ns = 0, .count = 2, .channels = idx, .values = v};
    pb_chanmap_update(cm, &u);
    assert_near(pb_chanmap_value(cm, 0), -45.0, 1e-12);
    assert_near(pb_chanmap_value(cm, 1), -10.0, 1e-12);
    /* deadband 2 deg: 151 -> -44.1 stays -45; 153 -> -42.3 moves */
    v[0] = 151;
    u.t_ns += 10000000;
    pb_chanmap_update(cm, &u);
    assert_near(pb_chanmap_value(cm, 0), -45.0, 1e-12);
    v[0] = 153;
    pb_chanmap_update(cm, &u);
    assert_near(pb_chanmap_value(cm, 0), -42.3, 1e-12);
    /* limits: 280 -> 72 clamps to 60; a NaN sample is dropped */
    v[0] = 280;
    pb_chanmap_update(cm, &u);
    assert_near(pb_chanmap_value(cm, 0), 60.0, 1e-12);
    v[0] = NAN;
    pb_chanmap_update(cm, &u);
    assert_near(pb_chanmap_value(cm, 0), 60.0, 1e-12);
    /* the joint: x = 60, z = -10 composed in ZXY */
    pb_pose pose;
    assert_int_equal(pb_pose_init(&pose, rig->joint_count), 0);
    pb_chanmap_pose(cm, &pose);
    double q[4], deg[3] = {60, 0, -10};
    pb_quat_from_euler(deg, POSE_EULER_ZXY, q);
    int arm = pb_rig_skel_find(rig, "Arm");
    assert_true(pose.active[arm]);
    assert_false(pose.active[0]);
    for (int k = 0; k < 4; k++)
        assert_near(pose.q[arm][k], q[k], 1e-6);
    pb_pose_free(&pose);
    pb_chanmap_free(cm);
    pb_mapping_free(m);
    pb_rig_skel_free(rig);
    pb_clip_free(clip);
}

static void test_shipped_maps_parse(void **state)
{
    (void)state;
    const char *maps[] = {"cmu131_bvh_to_full_body.json", "cmu_cgspeed_bvh_to_full_body.json",
                          "cmu_asf_to_full_body.json", "cmu131_arm_to_bar.json"};
    pb_rig_skel *body;
    pb_error body_err;
    assert_int_equal(pb_rig_skel_schematic_body(&body, &body_err), POSE_OK);
    for (size_t i = 0; i < sizeof maps / sizeof maps[0]; i++) {
        char p[1024];
        bt_path(p, sizeof p, "POSE_DATA_DIR", "../bridge/maps/");
        strncat(p, maps[i], sizeof p - strlen(p) - 1);
        pb_mapping *m;
        pb_error err;
        if (pb_mapping_load(p, &m, &err) != POSE_OK)
            fail_msg("%s", err.message);
        assert_true(m->joint_count >= 4);
        /* the mocap maps' ranges bind to any body with the template's joints */
        for (int k = 0; k < m->range_count; k++) {
            pb_joint_range r;
            if (pb_mapping_resolve_range(m, k, body, &r, &err) != POSE_OK)
                fail_msg("%s", err.message);
        }
        assert_int_equal(m->range_count, strstr(maps[i], "full_body") ? 5 : 0);
        pb_mapping_free(m);
    }
    pb_rig_skel_free(body);
}

/* Clinical entries ("dof"): bound to the rig's clinical angles by generic or
 * joint-specific name, composed as R(flexion axis) R(abduction axis) R(rotation
 * axis) * neutral -- checked against libpose's own pose_clinical_to_local on a
 * rig with clinical data; refused, with the entry named, where the rig has none. */
static void test_clinical_channels(void **state)
{
    (void)state;
    /* a one-joint rig: neutral a quarter turn about x; flexion about -y, abduction about +x, rotation about -z */
    const float h = 0.70710678f;
    pose_joint_desc jd = {.name = "shoulder", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, 0, 0}}};
    pose_joint_clinical cl = {.neutral = {h, 0, 0, h},
                              .axes = {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},
                              .names = {"flexion", "abduction", "internal_rotation"},
                              .limit_flags = 0,
                              .flags = POSE_CLINICAL_DEFINED};
    const float tet_p[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint32_t tet[4] = {0, 1, 2, 3};
    const uint16_t lab[1] = {0}, wj[4] = {0, 0, 0, 0};
    const float w[4] = {1, 1, 1, 1};
    pose_rig_desc d = {.joint_count = 1, .joints = &jd, .tet_vertex_count = 4, .tet_positions = tet_p,
                       .tet_count = 1, .tets = tet, .tet_labels = lab, .influences = 1, .weight_joints = wj,
                       .weights = w, .clinical = &cl};
    pose_rig *prig;
    if (pose_rig_create(&d, NULL, &prig) != POSE_OK)
        fail_msg("%s", pose_last_error());
    pb_rig_skel *rig;
    pb_error err;
    assert_int_equal(pb_rig_skel_from_rig(prig, &rig, &err), POSE_OK);
    const char *js = "{\"channels\": [{\"channel\": \"F\", \"joint\": \"shoulder\", \"dof\": \"flexion\"},"
                     "{\"channel\": \"A\", \"joint\": \"shoulder\", \"dof\": \"abduction\"},"
                     "{\"channel\": \"R\", \"joint\": \"shoulder\", \"dof\": \"internal_rotation\"}]}";
    pb_mapping *m;
    assert_int_equal(pb_mapping_parse(js, strlen(js), "m.json", &m, &err), POSE_OK);
    pb_channel ch[3] = {{.name = "F"}, {.name = "A"}, {.name = "R"}};
    pb_chanmap *cm;
    if (pb_chanmap_create(m, ch, 3, rig, &cm, &err) != POSE_OK)
        fail_msg("%s", err.message);
    uint32_t idx[3] = {0, 1, 2};
    double v[3] = {150, 20, -35};
    pb_update u = {.t_ns = 0, .count = 3, .channels = idx, .values = v};
    pb_chanmap_update(cm, &u);
    pb_pose p;
    assert_int_equal(pb_pose_init(&p, 1), 0);
    pb_chanmap_pose(cm, &p);
    const float deg[3] = {150, 20, -35};
    float want[4];
    assert_int_equal(pose_clinical_to_local(prig, 0, deg, want), POSE_OK);
    double a[4] = {p.q[0][0], p.q[0][1], p.q[0][2], p.q[0][3]}, b[4] = {want[0], want[1], want[2], want[3]};
    assert_true(bt_quat_angle_deg(a, b) < 1e-3);
    /* and back: libpose reads the same clinical angles from the bridge's rotation */
    float got[3];
    assert_int_equal(pose_local_to_clinical(prig, 0, p.q[0], deg, got), POSE_OK);
    for (int k = 0; k < 3; k++)
        assert_near(got[k], deg[k], 1e-3);
    pb_pose_free(&p);
    pb_chanmap_free(cm);
    pb_mapping_free(m);

    /* an angle the joint does not have, and one joint mixing clinical and rest-frame entries */
    const char *bad[2] = {"{\"channels\": [{\"channel\": \"F\", \"joint\": \"shoulder\", \"dof\": \"pronation\"}]}",
                          "{\"channels\": [{\"channel\": \"F\", \"joint\": \"shoulder\", \"dof\": \"flexion\"},"
                          "{\"channel\": \"A\", \"joint\": \"shoulder\", \"axis\": \"x\"}]}"};
    const char *want_msg[2] = {"m.json: channels[0].dof: joint shoulder has no angle 'pronation' (it has flexion, "
                               "abduction, internal_rotation)",
                               "m.json: channels[1]: joint shoulder mixes \"dof\" and \"axis\" entries"};
    for (int i = 0; i < 2; i++) {
        assert_int_equal(pb_mapping_parse(bad[i], strlen(bad[i]), "m.json", &m, &err), POSE_OK);
        assert_true(pb_chanmap_create(m, ch, 3, rig, &cm, &err) < 0);
        assert_string_equal(err.message, want_msg[i]);
        pb_mapping_free(m);
    }
    pb_rig_skel_free(rig);
    pose_rig_free(prig);

    /* a rig without clinical data: "dof" entries are refused, saying what to do */
    pose_rig_desc plain = d;
    plain.clinical = NULL;
    assert_int_equal(pose_rig_create(&plain, NULL, &prig), POSE_OK);
    assert_int_equal(pb_rig_skel_from_rig(prig, &rig, &err), POSE_OK);
    assert_int_equal(pb_mapping_parse(js, strlen(js), "m.json", &m, &err), POSE_OK);
    assert_int_equal(pb_chanmap_create(m, ch, 3, rig, &cm, &err), POSE_ERR_NOT_FOUND);
    assert_non_null(strstr(err.message, "m.json: channels[0].dof: the rig has no neutral posture or clinical axes for "
                                        "joint shoulder"));
    pb_mapping_free(m);
    pb_rig_skel_free(rig);
    pose_rig_free(prig);
}

/* A rig whose root has no clinical data and whose ankle carries the
 * template's names and AAOS ranges. */
static pose_rig *ankle_rig(void)
{
    pose_joint_desc jd[2] = {{.name = "root", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, 0, 0}}},
                             {.name = "ankle", .parent = 0, .rest_model = {{0, 0, 0, 1}, {0, 0, -1}}}};
    pose_joint_clinical cl[2] = {{.flags = 0},
                                 {.neutral = {0, 0, 0, 1},
                                  .axes = {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},
                                  .names = {"dorsiflexion", "inversion", "internal_rotation"},
                                  .limit_flags = POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z,
                                  .limit_min_deg = {-50, -15, -25},
                                  .limit_max_deg = {20, 35, 25},
                                  .flags = POSE_CLINICAL_DEFINED}};
    const float tet_p[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint32_t tet[4] = {0, 1, 2, 3};
    const uint16_t lab[1] = {0}, wj[4] = {0, 0, 0, 0};
    const float w[4] = {1, 1, 1, 1};
    pose_rig_desc d = {.joint_count = 2, .joints = jd, .tet_vertex_count = 4, .tet_positions = tet_p,
                       .tet_count = 1, .tets = tet, .tet_labels = lab, .influences = 1, .weight_joints = wj,
                       .weights = w, .clinical = cl};
    pose_rig *rig;
    if (pose_rig_create(&d, NULL, &rig) != POSE_OK)
        fail_msg("%s", pose_last_error());
    return rig;
}

/* "ranges": bound by generic or the joint's own angle names, the rest of
 * the joint keeping the rig's range; put on a state, which then lets through
 * what the rig's range clamps; refused, naming the map and key, for unknown
 * joints and angles, an angle given twice, and a joint without clinical data. */
static void test_ranges(void **state)
{
    (void)state;
    pose_rig *prig = ankle_rig();
    pb_rig_skel *rig;
    pb_error err;
    assert_int_equal(pb_rig_skel_from_rig(prig, &rig, &err), POSE_OK);
    const char *js = "{\"ranges\": {\"ankle\": {\"dorsiflexion\": [-50, 35], \"rotation\": [-30, 30]}}}";
    pb_mapping *m;
    assert_int_equal(pb_mapping_parse(js, strlen(js), "m.json", &m, &err), POSE_OK);
    assert_int_equal(m->range_count, 1);
    pb_joint_range r;
    assert_int_equal(pb_mapping_resolve_range(m, 0, rig, &r, &err), POSE_OK);
    assert_int_equal(r.joint, 1);
    const float lo[3] = {-50, -15, -30}, hi[3] = {35, 35, 30};
    for (int a = 0; a < 3; a++) {
        assert_true(r.min_deg[a] == lo[a]);
        assert_true(r.max_deg[a] == hi[a]);
    }

    pose_state *st, *plain;
    assert_int_equal(pose_state_create(prig, &st), POSE_OK);
    assert_int_equal(pose_state_create(prig, &plain), POSE_OK);
    assert_int_equal(pb_mapping_apply_ranges(m, rig, st, &err), POSE_OK);
    float got_lo[3], got_hi[3];
    uint32_t flags;
    assert_int_equal(pose_get_joint_range(st, 1, got_lo, got_hi, &flags), POSE_OK);
    assert_memory_equal(got_lo, lo, sizeof lo);
    assert_memory_equal(got_hi, hi, sizeof hi);
    assert_int_equal(flags, POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z);
    const float landing[3] = {30, 0, -28};
    assert_int_equal(pose_set_joint_clinical(st, 1, landing), POSE_OK);
    assert_int_equal(pose_set_joint_clinical(plain, 1, landing), POSE_CLAMPED);
    assert_non_null(strstr(pose_last_error(), "dorsiflexion 30.00 clamped to 20.00"));
    /* once there, applying again changes nothing */
    assert_int_equal(pb_joint_range_apply(&r, st), POSE_OK);
    float deg[3];
    assert_int_equal(pose_get_joint_clinical(st, 1, deg), POSE_OK);
    assert_true(deg[0] == 30.0f && deg[2] == -28.0f);
    pose_state_free(plain);
    pose_state_free(st);
    pb_mapping_free(m);

    const char *bad[4] = {"{\"ranges\": {\"knee\": {\"flexion\": [0, 150]}}}",
                          "{\"ranges\": {\"root\": {\"flexion\": [-10, 10]}}}",
                          "{\"ranges\": {\"ankle\": {\"pronation\": [-10, 10]}}}",
                          "{\"ranges\": {\"ankle\": {\"flexion\": [-50, 35], \"dorsiflexion\": [-50, 30]}}}"};
    const pose_status want_status[4] = {POSE_ERR_NOT_FOUND, POSE_ERR_UNSUPPORTED, POSE_ERR_NOT_FOUND,
                                        POSE_ERR_FORMAT};
    const char *want_msg[4] = {
        "m.json: ranges.knee: the rig has no joint 'knee'",
        "m.json: ranges.root: the rig has no clinical data for joint root, so no range of motion in clinical "
        "angles to replace",
        "m.json: ranges.ankle.pronation: joint ankle has no angle 'pronation' (it has dorsiflexion, inversion, "
        "internal_rotation)",
        "m.json: ranges.ankle.dorsiflexion: the joint's dorsiflexion range is given twice"};
    assert_int_equal(pose_state_create(prig, &st), POSE_OK);
    for (int i = 0; i < 4; i++) {
        assert_int_equal(pb_mapping_parse(bad[i], strlen(bad[i]), "m.json", &m, &err), POSE_OK);
        assert_int_equal(pb_mapping_resolve_range(m, 0, rig, &r, &err), want_status[i]);
        assert_string_equal(err.message, want_msg[i]);
        err.message[0] = '\0';
        assert_int_equal(pb_mapping_apply_ranges(m, rig, st, &err), want_status[i]);
        assert_string_equal(err.message, want_msg[i]);
        pb_mapping_free(m);
    }
    pose_state_free(st);
    pb_rig_skel_free(rig);
    pose_rig_free(prig);
}

/* A key given twice in one object: JSON allows it, every lookup takes the
 * first, so the second was ignored in silence. Now a warning names where. */
static void test_duplicate_keys_warned(void **state)
{
    (void)state;
    static const char json[] = "{\"scale\": 1, \"scale\": 2, \"channels\": [{\"channel\": \"A\", \"joint\": \"j\","
                               " \"axis\": \"x\", \"calibration\": {\"offset\": 1, \"offset\": 3}}]}";
    pb_warnings w;
    memset(&w, 0, sizeof w);
    pb_warnings *prev = pb_warnings_install(&w);
    pb_mapping *m = NULL;
    pb_error err = {{0}};
    const pose_status st = pb_mapping_parse(json, sizeof json - 1, "dup.json", &m, &err);
    pb_warnings_install(prev);
    if (st != POSE_OK)
        fail_msg("%s", err.message);
    pb_mapping_free(m);
    assert_int_equal(w.count, 2);
    assert_string_equal(w.text[0], "dup.json: the top-level object: key \"scale\" appears again; the first one is used");
    assert_string_equal(w.text[1],
                        "dup.json: channels[0].calibration: key \"offset\" appears again; the first one is used");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_mapping_files),
        cmocka_unit_test(test_unknown_joints),
        cmocka_unit_test(test_channel_stages),
        cmocka_unit_test(test_clinical_channels),
        cmocka_unit_test(test_shipped_maps_parse),
        cmocka_unit_test(test_ranges),
        cmocka_unit_test(test_duplicate_keys_warned),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
