/* SPDX-License-Identifier: Apache-2.0
 * CMU clips retargeted onto a body baked by pose-bake from data/anatomy with
 * preprocess/templates/full_body.json (fixture bridge_body_bake writes
 * $POSE_TEST_TMP/body.rig): the rig's real rest frames and joint limits, as
 * the demo uses them. Through libpose (pose_set_joint, so with its clamping)
 * the thighs, shanks, upper arms, forearms and trunk point where the clip's
 * do, in the rig's axes, and joint limits clamp rarely.
 *
 * This is what a skeleton without limits and rest frames could not catch:
 * aligning the clip's schematic spine tilted the pelvis and lumbar spine,
 * hinge axes twisted apart turned knee and elbow flexion into abduction,
 * and Euler limits with the flexion axis in the middle could not hold a knee
 * past 90 degrees; limits then clamped about a quarter of all joint targets
 * and bent the trunk and knees. */
#include "bridge_apply.h"
#include "bridge_test.h"
#include "mapping.h"
#include "pb_math.h"

typedef struct segment {
    const char *rig[2];
    const char *clip[2];
} segment;

typedef struct body_case {
    const char *clip, *map;
    segment seg[9];
    double max_deg;        /* worst angle between a rig segment and the clip's */
    double max_clamp_rate; /* clamped targets / driven targets */
} body_case;

static const body_case CASES[] = {
    {"mocap/cmu-bvh/131_01.bvh",
     "cmu131_bvh_to_full_body.json",
     {{{"hip_r", "knee_r"}, {"RightHip", "RightKnee"}},
      {{"knee_r", "ankle_r"}, {"RightKnee", "RightAnkle"}},
      {{"hip_l", "knee_l"}, {"LeftHip", "LeftKnee"}},
      {{"knee_l", "ankle_l"}, {"LeftKnee", "LeftAnkle"}},
      {{"shoulder_r", "elbow_r"}, {"RightShoulder", "RightElbow"}},
      {{"elbow_r", "wrist_r"}, {"RightElbow", "RightWrist"}},
      {{"shoulder_l", "elbow_l"}, {"LeftShoulder", "LeftElbow"}},
      {{"elbow_l", "wrist_l"}, {"LeftElbow", "LeftWrist"}},
      {{"pelvis", "neck"}, {"Hips", "lowerneck"}}},
     15.0,
     0.06},
    {"mocap/cmu-bvh/01_01.bvh",
     "cmu_cgspeed_bvh_to_full_body.json",
     {{{"hip_r", "knee_r"}, {"RightUpLeg", "RightLeg"}},
      {{"knee_r", "ankle_r"}, {"RightLeg", "RightFoot"}},
      {{"hip_l", "knee_l"}, {"LeftUpLeg", "LeftLeg"}},
      {{"knee_l", "ankle_l"}, {"LeftLeg", "LeftFoot"}},
      {{"shoulder_r", "elbow_r"}, {"RightArm", "RightForeArm"}},
      {{"elbow_r", "wrist_r"}, {"RightForeArm", "RightHand"}},
      {{"shoulder_l", "elbow_l"}, {"LeftArm", "LeftForeArm"}},
      {{"elbow_l", "wrist_l"}, {"LeftForeArm", "LeftHand"}},
      {{"pelvis", "neck"}, {"Hips", "Neck"}}},
     15.0,
     0.06},
    {"mocap/cmu-asf-amc/01_01.amc",
     "cmu_asf_to_full_body.json",
     {{{"hip_r", "knee_r"}, {"rfemur", "rtibia"}},
      {{"knee_r", "ankle_r"}, {"rtibia", "rfoot"}},
      {{"hip_l", "knee_l"}, {"lfemur", "ltibia"}},
      {{"knee_l", "ankle_l"}, {"ltibia", "lfoot"}},
      {{"shoulder_r", "elbow_r"}, {"rhumerus", "rradius"}},
      {{"elbow_r", "wrist_r"}, {"rradius", "rwrist"}},
      {{"shoulder_l", "elbow_l"}, {"lhumerus", "lradius"}},
      {{"elbow_l", "wrist_l"}, {"lradius", "lwrist"}},
      {{"pelvis", "neck"}, {"root", "lowerneck"}}},
     15.0,
     0.06},
};

typedef struct fixture {
    pose_rig *rig;
    pb_rig_skel *skel;
} fixture;

static int setup(void **state)
{
    static fixture f;
    char p[1024];
    if (pose_rig_load(BT_TMP(p, "body.rig"), &f.rig) < 0) {
        print_error("%s (written by the ctest fixture bridge_body_bake)\n", pose_last_error());
        return -1;
    }
    pb_error err;
    if (pb_rig_skel_from_rig(f.rig, &f.skel, &err) != POSE_OK) {
        print_error("%s\n", err.message);
        return -1;
    }
    *state = &f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    pb_rig_skel_free(f->skel);
    pose_rig_free(f->rig);
    return 0;
}

/* angle in degrees between two vectors */
static double angle_deg(const double a[3], const double b[3])
{
    double x[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return atan2(pb_vec_len(x), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * PB_RAD2DEG;
}

static void run_case(const fixture *fx, const body_case *bc)
{
    char p[1024];
    pb_clip *clip;
    pb_mapping *map;
    pb_retarget *rt;
    pb_error err;
    char mp[1024];
    snprintf(mp, sizeof mp, "%s/../bridge/maps/%s", getenv("POSE_DATA_DIR"), bc->map);
    if (pb_clip_load(BT_DATA(p, bc->clip), NULL, &clip, &err) != POSE_OK || pb_mapping_load(mp, &map, &err) != POSE_OK ||
        pb_retarget_create(map, clip, fx->skel, &rt, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(pb_retarget_mapped_count(rt), fx->skel->joint_count);
    int ri[9][2], ci[9][2];
    for (int i = 0; i < 9; i++)
        for (int e = 0; e < 2; e++) {
            ri[i][e] = pb_rig_skel_find(fx->skel, bc->seg[i].rig[e]);
            ci[i][e] = pb_clip_find_joint(clip, bc->seg[i].clip[e]);
            assert_true(ri[i][e] >= 0 && ci[i][e] >= 0);
        }
    pose_state *st;
    assert_int_equal(pose_state_create(fx->rig, &st), POSE_OK);
    size_t nc = (size_t)clip->joint_count, nr = (size_t)fx->skel->joint_count;
    double (*lq)[4] = malloc(nc * sizeof *lq), (*lt)[3] = malloc(nc * sizeof *lt);
    double (*cq)[4] = malloc(nc * sizeof *cq), (*cp)[3] = malloc(nc * sizeof *cp);
    double (*rq)[4] = malloc(nr * sizeof *rq), (*rp)[3] = malloc(nr * sizeof *rp);
    float (*q)[4] = malloc(nr * sizeof *q);
    long *clamps = calloc(nr, sizeof *clamps);
    assert_true(lq && lt && cq && cp && rq && rp && q && clamps);
    pb_pose pose;
    assert_int_equal(pb_pose_init(&pose, (int)nr), 0);
    double worst[9] = {0}, sum = 0;
    size_t worst_f[9] = {0};
    long clamped = 0, targets = 0, samples = 0;
    for (size_t f = 0; f < clip->frame_count; f += 4) {
        pb_clip_local(clip, pb_clip_frame(clip, f), lq, lt);
        pb_retarget_apply(rt, (const double (*)[4])lq, (const double (*)[3])lt, 0, &pose);
        pb_clip_world(clip, (const double (*)[4])lq, (const double (*)[3])lt, cq, cp);
        /* what the user gets: the targets after libpose's limits */
        for (size_t j = 0; j < nr; j++) {
            if (!pose.active[j])
                continue;
            pose_status s = pose_set_joint(st, (int)j, pose.q[j]);
            assert_true(s >= 0);
            clamps[j] += s == POSE_CLAMPED;
            clamped += s == POSE_CLAMPED;
            targets++;
            assert_int_equal(pose_get_joint(st, (int)j, q[j]), POSE_OK);
        }
        pb_rig_skel_fk(fx->skel, (const float (*)[4])q, pose.root_t, pose.root_q, rq, rp);
        for (int i = 0; i < 9; i++) {
            double vr[3], vc[3];
            for (int a = 0; a < 3; a++)
                vr[a] = rp[ri[i][1]][a] - rp[ri[i][0]][a];
            /* the clip's axes (Y up, Z forward, X left) in the rig's (Z up, X forward, Y left) */
            vc[0] = cp[ci[i][1]][2] - cp[ci[i][0]][2];
            vc[1] = cp[ci[i][1]][0] - cp[ci[i][0]][0];
            vc[2] = cp[ci[i][1]][1] - cp[ci[i][0]][1];
            double ang = angle_deg(vr, vc);
            if (ang > worst[i]) {
                worst[i] = ang;
                worst_f[i] = f;
            }
            sum += ang;
            samples++;
        }
    }
    double rate = (double)clamped / (double)targets;
    print_message("%s onto the baked body: %ld of %ld joint targets clamped (%.1f%%), mean segment error %.2f deg\n",
                  bc->clip, clamped, targets, 100.0 * rate, sum / (double)samples);
    for (size_t j = 0; j < nr; j++)
        if (clamps[j])
            print_message("  %-11s clamped %ld times\n", fx->skel->joints[j].name, clamps[j]);
    for (int i = 0; i < 9; i++) {
        print_message("  %s->%s: worst %.1f deg (frame %zu)\n", bc->seg[i].rig[0], bc->seg[i].rig[1], worst[i],
                      worst_f[i]);
        if (worst[i] > bc->max_deg)
            fail_msg("%s frame %zu: %s->%s points %.1f deg away from the clip's %s->%s", bc->clip, worst_f[i],
                     bc->seg[i].rig[0], bc->seg[i].rig[1], worst[i], bc->seg[i].clip[0], bc->seg[i].clip[1]);
    }
    if (rate > bc->max_clamp_rate)
        fail_msg("%s: %.1f%% of the joint targets clamped (at most %.1f%% expected)", bc->clip, 100.0 * rate,
                 100.0 * bc->max_clamp_rate);
    pb_pose_free(&pose);
    pose_state_free(st);
    free(lq);
    free(lt);
    free(cq);
    free(cp);
    free(rq);
    free(rp);
    free(q);
    free(clamps);
    pb_retarget_free(rt);
    pb_mapping_free(map);
    pb_clip_free(clip);
}

static void test_walk_131(void **state) { run_case(*state, &CASES[0]); }
static void test_jumps_01(void **state) { run_case(*state, &CASES[1]); }
static void test_jumps_01_asf_amc(void **state) { run_case(*state, &CASES[2]); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_walk_131),
        cmocka_unit_test(test_jumps_01),
        cmocka_unit_test(test_jumps_01_asf_amc),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
