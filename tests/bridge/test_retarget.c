/* SPDX-License-Identifier: Apache-2.0
 * Retargeting: a clip played onto a skeleton identical to its own reproduces
 * its joint world positions; onto the full-body template (joint centres of
 * data/anatomy/skeleton_hint.json, Z up, facing +X, arbitrary rest frames)
 * the limbs point where the clip's limbs point; a recorded session replays
 * to the same joint targets. */
#include "bridge_test.h"
#include "mapping.h"
#include "pb_math.h"
#include "recorder.h"

static pb_clip *load(const char *rel, const char *skel_rel)
{
    char p[1024], s[1024];
    pb_clip *c;
    pb_error err;
    if (pb_clip_load(BT_DATA(p, rel), skel_rel ? BT_DATA(s, skel_rel) : NULL, &c, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return c;
}

/* identity mapping onto the clip's own skeleton; compare world positions */
static void check_identical_skeleton(const pb_clip *clip, double tol)
{
    pb_rig_skel *rig;
    pb_mapping *map;
    pb_retarget *rt;
    pb_error err;
    assert_int_equal(pb_rig_skel_from_clip(clip, 1.0, &rig, &err), POSE_OK);
    assert_int_equal(pb_mapping_identity(&map, &err), POSE_OK);
    if (pb_retarget_create(map, clip, rig, &rt, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(pb_retarget_mapped_count(rt), clip->joint_count);
    size_t n = (size_t)clip->joint_count;
    double *s = malloc(n * 14 * sizeof(double));
    double (*lq)[4] = (double (*)[4])s, (*lt)[3] = (double (*)[3])(s + 4 * n);
    double (*cq)[4] = (double (*)[4])(s + 7 * n), (*cp)[3] = (double (*)[3])(s + 11 * n);
    double (*rq)[4] = malloc(n * sizeof *rq), (*rp)[3] = malloc(n * sizeof *rp);
    pb_pose pose;
    assert_int_equal(pb_pose_init(&pose, rig->joint_count), 0);
    double worst = 0;
    for (size_t f = 0; f < clip->frame_count; f += 37) {
        pb_clip_local(clip, pb_clip_frame(clip, f), lq, lt);
        pb_retarget_apply(rt, (const double (*)[4])lq, (const double (*)[3])lt, clip->frame_time, &pose);
        pb_clip_world(clip, (const double (*)[4])lq, (const double (*)[3])lt, cq, cp);
        assert_true(pose.has_root);
        pb_rig_skel_fk(rig, (const float (*)[4])pose.q, pose.root_t, pose.root_q, rq, rp);
        for (size_t j = 0; j < n; j++)
            for (int k = 0; k < 3; k++) {
                double e = fabs(rp[j][k] - cp[j][k]);
                if (e > tol)
                    fail_msg("frame %zu joint %s axis %d: rig %g, clip %g", f, clip->joints[j].name, k, rp[j][k],
                             cp[j][k]);
                worst = e > worst ? e : worst;
            }
    }
    print_message("%s onto itself: worst position error %.3g units\n", clip->path, worst);
    pb_pose_free(&pose);
    free(s);
    free(rq);
    free(rp);
    pb_retarget_free(rt);
    pb_mapping_free(map);
    pb_rig_skel_free(rig);
}

static void test_identical_skeleton_bvh(void **state)
{
    (void)state;
    pb_clip *c = load("mocap/cmu-bvh/131_01.bvh", NULL);
    /* float quaternions (rel. 6e-8) along chains of ~40 units */
    check_identical_skeleton(c, 1e-4);
    pb_clip_free(c);
}

static void test_identical_skeleton_asf_amc(void **state)
{
    (void)state;
    pb_clip *c = load("mocap/cmu-asf-amc/11_01.amc", "mocap/cmu-asf-amc/11.asf");
    check_identical_skeleton(c, 1e-4);
    pb_clip_free(c);
}

/* The full_body template's joints placed at the anatomy's joint centres
 * (data/anatomy/skeleton_hint.json), with rest frames deliberately rotated:
 * retargeting must not depend on them. */
static const struct {
    const char *name;
    int parent;
    double p[3];
} BODY[] = {
    {"pelvis", -1, {-0.006276, 0.0, 0.871315}},
    {"lumbar", 0, {-0.058, -1.2e-05, 1.010805}},
    {"thorax", 1, {-0.060627, -3.7e-05, 1.131227}},
    {"neck", 2, {-0.065995, -9.9e-05, 1.435279}},
    {"head", 3, {-0.043004, 0.0, 1.52}},
    {"clavicle_r", 2, {-0.007238, -0.02556, 1.415432}},
    {"shoulder_r", 5, {-0.05671, -0.161549, 1.426581}},
    {"elbow_r", 6, {-0.037968, -0.449125, 1.388244}},
    {"wrist_r", 7, {-0.013356, -0.705095, 1.406704}},
    {"clavicle_l", 2, {-0.007238, 0.02556, 1.415432}},
    {"shoulder_l", 9, {-0.056369, 0.161861, 1.426135}},
    {"elbow_l", 10, {-0.040404, 0.448702, 1.381553}},
    {"wrist_l", 11, {-0.019984, 0.705382, 1.394969}},
    {"hip_r", 0, {-0.006276, -0.07726, 0.871315}},
    {"knee_r", 13, {-0.006276, -0.075995, 0.46689}},
    {"ankle_r", 14, {-0.016276, -0.075995, 0.06689}},
    {"hip_l", 0, {-0.006276, 0.07726, 0.871315}},
    {"knee_l", 16, {-0.006276, 0.075995, 0.46689}},
    {"ankle_l", 17, {-0.016276, 0.075995, 0.06689}},
};
#define NBODY (sizeof BODY / sizeof BODY[0])

static pb_rig_skel *body_template(void)
{
    pose_joint_desc d[NBODY];
    memset(d, 0, sizeof d);
    for (size_t j = 0; j < NBODY; j++) {
        d[j].name = BODY[j].name;
        d[j].parent = BODY[j].parent;
        double q[4], e[3] = {17.0 * (double)j, -31.0 + 7.0 * (double)j, 5.0 * (double)j};
        pb_quat_from_euler(e, POSE_EULER_XYZ, q);
        for (int k = 0; k < 4; k++)
            d[j].rest_model.rotation[k] = (float)q[k];
        for (int k = 0; k < 3; k++)
            d[j].rest_model.translation[k] = (float)BODY[j].p[k];
    }
    pb_rig_skel *s;
    pb_error err;
    if (pb_rig_skel_from_desc(d, NBODY, &s, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return s;
}

/* rig limb (from, to) and the clip joints driving them, per naming */
static const char *LIMB_RIG[8][2] = {{"shoulder_r", "elbow_r"}, {"elbow_r", "wrist_r"}, {"shoulder_l", "elbow_l"},
                                     {"elbow_l", "wrist_l"},    {"hip_r", "knee_r"},     {"knee_r", "ankle_r"},
                                     {"hip_l", "knee_l"},       {"knee_l", "ankle_l"}};
static const char *LIMB_131[8][2] = {{"RightShoulder", "RightElbow"}, {"RightElbow", "RightWrist"},
                                     {"LeftShoulder", "LeftElbow"},   {"LeftElbow", "LeftWrist"},
                                     {"RightHip", "RightKnee"},       {"RightKnee", "RightAnkle"},
                                     {"LeftHip", "LeftKnee"},         {"LeftKnee", "LeftAnkle"}};
static const char *LIMB_CGS[8][2] = {{"RightArm", "RightForeArm"}, {"RightForeArm", "RightHand"},
                                     {"LeftArm", "LeftForeArm"},   {"LeftForeArm", "LeftHand"},
                                     {"RightUpLeg", "RightLeg"},   {"RightLeg", "RightFoot"},
                                     {"LeftUpLeg", "LeftLeg"},     {"LeftLeg", "LeftFoot"}};
static const char *LIMB_ASF[8][2] = {{"rhumerus", "rradius"}, {"rradius", "rwrist"}, {"lhumerus", "lradius"},
                                     {"lradius", "lwrist"},   {"rfemur", "rtibia"},  {"rtibia", "rfoot"},
                                     {"lfemur", "ltibia"},    {"ltibia", "lfoot"}};

static void limb_directions(const char *clip_rel, const char *skel_rel, const char *map_name,
                            const char *limb_clip[8][2], const char *root)
{
    pb_clip *clip = load(clip_rel, skel_rel);
    pb_rig_skel *rig = body_template();
    char p[1024];
    pb_mapping *map;
    pb_retarget *rt;
    pb_error err;
    bt_path(p, sizeof p, "POSE_DATA_DIR", "../bridge/maps/");
    strncat(p, map_name, sizeof p - strlen(p) - 1);
    if (pb_mapping_load(p, &map, &err) != POSE_OK)
        fail_msg("%s", err.message);
    if (pb_retarget_create(map, clip, rig, &rt, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(pb_retarget_mapped_count(rt), 19);
    size_t n = (size_t)clip->joint_count;
    double *s = malloc(n * 14 * sizeof(double));
    double (*lq)[4] = (double (*)[4])s, (*lt)[3] = (double (*)[3])(s + 4 * n);
    double (*cq)[4] = (double (*)[4])(s + 7 * n), (*cp)[3] = (double (*)[3])(s + 11 * n);
    double rq[NBODY][4], rp[NBODY][3];
    pb_pose pose;
    assert_int_equal(pb_pose_init(&pose, rig->joint_count), 0);
    double worst = 0, walked = 0;
    for (size_t f = 0; f < clip->frame_count; f += 11) {
        pb_clip_local(clip, pb_clip_frame(clip, f), lq, lt);
        pb_retarget_apply(rt, (const double (*)[4])lq, (const double (*)[3])lt, clip->frame_time, &pose);
        pb_clip_world(clip, (const double (*)[4])lq, (const double (*)[3])lt, cq, cp);
        pb_rig_skel_fk(rig, (const float (*)[4])pose.q, pose.root_t, pose.root_q, rq, rp);
        for (size_t i = 0; i < 8; i++) {
            int a = pb_rig_skel_find(rig, LIMB_RIG[i][0]), b = pb_rig_skel_find(rig, LIMB_RIG[i][1]);
            int ca = pb_clip_find_joint(clip, limb_clip[i][0]), cb = pb_clip_find_joint(clip, limb_clip[i][1]);
            assert_true(ca >= 0 && cb >= 0);
            double vr[3] = {rp[b][0] - rp[a][0], rp[b][1] - rp[a][1], rp[b][2] - rp[a][2]};
            /* the clip's direction in rig axes: (x, y, z) Y up, Z forward, X left -> (z, x, y) */
            double vc[3] = {cp[cb][2] - cp[ca][2], cp[cb][0] - cp[ca][0], cp[cb][1] - cp[ca][1]};
            double x[3] = {vr[1] * vc[2] - vr[2] * vc[1], vr[2] * vc[0] - vr[0] * vc[2], vr[0] * vc[1] - vr[1] * vc[0]};
            double ang = atan2(pb_vec_len(x), vr[0] * vc[0] + vr[1] * vc[1] + vr[2] * vc[2]) * PB_RAD2DEG;
            if (ang > 0.001)
                fail_msg("%s frame %zu %s->%s points %g deg away from the clip's %s->%s", clip_rel, f, LIMB_RIG[i][0],
                         LIMB_RIG[i][1], ang, limb_clip[i][0], limb_clip[i][1]);
            worst = ang > worst ? ang : worst;
        }
    }
    /* root motion: the clip's root displacement from its first frame (the maps'
     * "root_origin": "first_frame"), in metres (x 0.056444), clip (x, y, z) ->
     * rig (z, x, y): the rig starts where it rests, not a hip height above it */
    int hips = pb_clip_find_joint(clip, root);
    double o[3];
    memcpy(o, cp[hips], sizeof o); /* the last frame's, kept while frame 0 is computed */
    double last[3] = {o[0], o[1], o[2]};
    pb_clip_local(clip, pb_clip_frame(clip, 0), lq, lt);
    pb_clip_world(clip, (const double (*)[4])lq, (const double (*)[3])lt, cq, cp);
    memcpy(o, cp[hips], sizeof o);
    memcpy(cp[hips], last, sizeof last);
    assert_near(pose.root_t[0], 0.056444 * (cp[hips][2] - o[2]), 1e-6);
    assert_near(pose.root_t[1], 0.056444 * (cp[hips][0] - o[0]), 1e-6);
    assert_near(pose.root_t[2], 0.056444 * (cp[hips][1] - o[1]), 1e-6);
    walked = sqrt(pose.root_t[0] * pose.root_t[0] + pose.root_t[1] * pose.root_t[1]);
    print_message("%s onto the body template: worst limb direction %.2g deg; root moved %.2f m\n", clip_rel, worst,
                  walked);
    pb_pose_free(&pose);
    free(s);
    pb_retarget_free(rt);
    pb_mapping_free(map);
    pb_rig_skel_free(rig);
    pb_clip_free(clip);
}

static void test_body_template_limb_directions(void **state)
{
    (void)state;
    limb_directions("mocap/cmu-bvh/131_01.bvh", NULL, "cmu131_bvh_to_full_body.json", LIMB_131, "Hips");
    limb_directions("mocap/cmu-bvh/01_01.bvh", NULL, "cmu_cgspeed_bvh_to_full_body.json", LIMB_CGS, "Hips");
    limb_directions("mocap/cmu-asf-amc/01_01.amc", "mocap/cmu-asf-amc/01.asf", "cmu_asf_to_full_body.json", LIMB_ASF,
                    "root");
}

static void test_recording_replays_same_targets(void **state)
{
    (void)state;
    pb_clip *clip = load("mocap/cmu-bvh/131_01.bvh", NULL);
    pb_rig_skel *rig = body_template();
    char p[1024], out[1024];
    pb_mapping *map, *same;
    pb_retarget *rt, *rt2;
    pb_recorder *rec;
    pb_error err;
    assert_int_equal(pb_mapping_load(BT_MAP(p, "cmu131_bvh_to_full_body.json"), &map, &err), POSE_OK);
    assert_int_equal(pb_retarget_create(map, clip, rig, &rt, &err), POSE_OK);
    BT_TMP(out, "session.bvh");
    assert_int_equal(pb_recorder_open(out, rig, clip->frame_time, &rec, &err), POSE_OK);
    enum { FRAMES = 40, STRIDE = 20 };
    size_t n = (size_t)clip->joint_count;
    double *s = malloc(n * 7 * sizeof(double));
    double (*lq)[4] = (double (*)[4])s, (*lt)[3] = (double (*)[3])(s + 4 * n);
    pb_pose pose[FRAMES];
    for (int i = 0; i < FRAMES; i++) {
        assert_int_equal(pb_pose_init(&pose[i], rig->joint_count), 0);
        pb_clip_local(clip, pb_clip_frame(clip, (size_t)(i * STRIDE)), lq, lt);
        pb_retarget_apply(rt, (const double (*)[4])lq, (const double (*)[3])lt, 0, &pose[i]);
        assert_int_equal(pb_recorder_write(rec, &pose[i], &err), POSE_OK);
        if (i == 9) { /* flushed as it goes: the file is a valid BVH mid-session */
            pb_clip *partial;
            if (pb_bvh_load(out, &partial, &err) != POSE_OK)
                fail_msg("%s", err.message);
            assert_int_equal(partial->frame_count, 10);
            pb_clip_free(partial);
        }
    }
    assert_int_equal(pb_recorder_close(rec, &err), POSE_OK);
    pb_clip *again;
    if (pb_bvh_load(out, &again, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(again->frame_count, FRAMES);
    assert_int_equal(pb_mapping_identity(&same, &err), POSE_OK);
    if (pb_retarget_create(same, again, rig, &rt2, &err) != POSE_OK)
        fail_msg("%s", err.message);
    size_t m = (size_t)again->joint_count;
    double *s2 = malloc(m * 7 * sizeof(double));
    double worst = 0;
    pb_pose back;
    assert_int_equal(pb_pose_init(&back, rig->joint_count), 0);
    for (int i = 0; i < FRAMES; i++) {
        pb_clip_local(again, pb_clip_frame(again, (size_t)i), (double (*)[4])s2, (double (*)[3])(s2 + 4 * m));
        pb_retarget_apply(rt2, (const double (*)[4])s2, (const double (*)[3])(s2 + 4 * m), 0, &back);
        for (int j = 0; j < rig->joint_count; j++) {
            double a[4] = {pose[i].q[j][0], pose[i].q[j][1], pose[i].q[j][2], pose[i].q[j][3]};
            double b[4] = {back.q[j][0], back.q[j][1], back.q[j][2], back.q[j][3]};
            double ang = bt_quat_angle_deg(a, b);
            /* Euler angles written with 6 decimals; floats in between */
            if (ang > 0.001)
                fail_msg("frame %d joint %s: replayed rotation %g deg off (%g %g %g %g vs %g %g %g %g)", i,
                         rig->joints[j].name, ang, a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]);
            worst = ang > worst ? ang : worst;
        }
        for (int k = 0; k < 3; k++)
            assert_near(back.root_t[k], pose[i].root_t[k], 2e-6);
    }
    print_message("recorded session replays within %.2g deg\n", worst);
    for (int i = 0; i < FRAMES; i++)
        pb_pose_free(&pose[i]);
    pb_pose_free(&back);
    free(s);
    free(s2);
    pb_retarget_free(rt);
    pb_retarget_free(rt2);
    pb_mapping_free(map);
    pb_mapping_free(same);
    pb_clip_free(again);
    pb_rig_skel_free(rig);
    pb_clip_free(clip);
}

/* a quaternion One Euro filter from the mapping: the first pose passes, a
 * jump is followed part way (the filter's alpha), a held pose converges */
static void test_filtered_retarget(void **state)
{
    (void)state;
    pb_clip *clip = load("mocap/cmu-bvh/131_01.bvh", NULL);
    pb_rig_skel *rig;
    pb_mapping *map;
    pb_retarget *rt;
    pb_error err;
    assert_int_equal(pb_rig_skel_from_clip(clip, 1.0, &rig, &err), POSE_OK);
    const char *js = "{\"joints\": {\"RightElbow\": {\"source\": \"RightElbow\", \"filter\": {\"min_cutoff\": 1.0, \"beta\": 0}}}}";
    assert_int_equal(pb_mapping_parse(js, strlen(js), "m.json", &map, &err), POSE_OK);
    if (pb_retarget_create(map, clip, rig, &rt, &err) != POSE_OK)
        fail_msg("%s", err.message);
    int j = pb_rig_skel_find(rig, "RightElbow");
    size_t n = (size_t)clip->joint_count;
    double *s = malloc(n * 14 * sizeof(double));
    double (*lq)[4] = (double (*)[4])s, (*lt)[3] = (double (*)[3])(s + 4 * n);
    double (*wq)[4] = (double (*)[4])(s + 7 * n), (*wp)[3] = (double (*)[3])(s + 11 * n);
    pb_pose pose;
    assert_int_equal(pb_pose_init(&pose, rig->joint_count), 0);
    pb_clip_local(clip, pb_clip_frame(clip, 0), lq, lt);
    double a[4], b[4], got[4];
    pb_retarget_apply(rt, (const double (*)[4])lq, (const double (*)[3])lt, 0.01, &pose);
    for (int k = 0; k < 4; k++)
        a[k] = pose.q[j][k];
    /* only this joint is driven, its rig parents stay at rest: its target is
     * the clip joint's world rotation (the reference pose is all zeros) */
    pb_clip_world(clip, (const double (*)[4])lq, (const double (*)[3])lt, wq, wp);
    assert_true(bt_quat_angle_deg(a, wq[j]) < 1e-4); /* passes unfiltered */
    pb_clip_local(clip, pb_clip_frame(clip, 600), lq, lt);
    pb_clip_world(clip, (const double (*)[4])lq, (const double (*)[3])lt, wq, wp);
    for (int k = 0; k < 4; k++)
        b[k] = wq[j][k];
    double whole = bt_quat_angle_deg(a, b);
    assert_true(whole > 5.0);
    pb_retarget_apply(rt, (const double (*)[4])lq, (const double (*)[3])lt, 0.01, &pose);
    for (int k = 0; k < 4; k++)
        got[k] = pose.q[j][k];
    double alpha = pb_one_euro_alpha(1.0, 0.01); /* beta 0: the cutoff stays at min_cutoff */
    assert_near(bt_quat_angle_deg(a, got), alpha * whole, 1e-3);
    for (int i = 0; i < 2000; i++)
        pb_retarget_apply(rt, (const double (*)[4])lq, (const double (*)[3])lt, 0.01, &pose);
    for (int k = 0; k < 4; k++)
        got[k] = pose.q[j][k];
    assert_true(bt_quat_angle_deg(got, b) < 1e-3);
    pb_pose_free(&pose);
    free(s);
    pb_retarget_free(rt);
    pb_mapping_free(map);
    pb_rig_skel_free(rig);
    pb_clip_free(clip);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_identical_skeleton_bvh),
        cmocka_unit_test(test_identical_skeleton_asf_amc),
        cmocka_unit_test(test_body_template_limb_directions),
        cmocka_unit_test(test_recording_replays_same_targets),
        cmocka_unit_test(test_filtered_retarget),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
