/* SPDX-License-Identifier: Apache-2.0
 * The bundled device recordings pose a body baked from data/anatomy the way
 * the mannequin stands (fixture body_rig_bake writes $POSE_TEST_TMP/body.rig).
 * The goniometers read clinical angles, 0 in the anatomical neutral posture;
 * the shipped maps (bridge/maps/hid_mannequin_full_body.json,
 * can_rig_fullbody.json) drive the rig's clinical angles, which libpose
 * composes onto the neutral posture pose-bake found. Checked here, through
 * the decoder, the mapping and pose_set_joint as every host uses them:
 *  - postures: seated thighs horizontal and shanks vertical, standing limbs
 *    vertical, arms at the sides hanging down, shoulder flexion 150 with the
 *    hand above the head, forward flexion 90 with the arm horizontal forward;
 *  - every angle of the recordings' truth (the CAN rig's truth file, the HID
 *    mannequin's generator) measured back from the posed joint's world
 *    rotation in the clinical convention, within 2 degrees, wherever the
 *    rig's range of motion does not limit it. */
#include "bridge_apply.h"
#include "bridge_test.h"
#include "can_bus.h"
#include "can_source.h"
#include "clinical_check.h"
#include "hid_mannequin.h"
#include "hid_open.h"
#include "mapping.h"
#include "pb_math.h"

typedef struct fixture {
    pose_rig *rig;
    pose_state *st;
    pb_rig_skel *skel;
    double up[3], forward[3]; /* the body's axes, from its rest skeleton */
} fixture;

static void joint_pos(const fixture *f, const char *name, double p[3])
{
    pose_transform w;
    int j = pose_rig_find_joint(f->rig, name);
    if (j < 0 || pose_joint_world(f->st, j, &w) != POSE_OK)
        fail_msg("no joint %s", name);
    for (int k = 0; k < 3; k++)
        p[k] = w.translation[k];
}

static void normalize(double v[3])
{
    double n = pb_vec_len(v);
    for (int k = 0; k < 3; k++)
        v[k] /= n;
}

static int setup(void **state)
{
    static fixture f;
    char p[1024];
    if (pose_rig_load(BT_TMP(p, "body.rig"), &f.rig) < 0) {
        print_error("%s (written by the ctest fixture body_rig_bake)\n", pose_last_error());
        return -1;
    }
    pb_error err;
    if (pb_rig_skel_from_rig(f.rig, &f.skel, &err) != POSE_OK || pose_state_create(f.rig, &f.st) != POSE_OK) {
        print_error("%s\n", err.message);
        return -1;
    }
    pose_set_threads(f.st, 1);
    pose_apply(f.st);
    /* up: pelvis to head; forward: the right-handed completion of (left, up) */
    double pel[3], head[3], hl[3], hr[3], left[3];
    joint_pos(&f, "pelvis", pel);
    joint_pos(&f, "head", head);
    joint_pos(&f, "hip_l", hl);
    joint_pos(&f, "hip_r", hr);
    for (int k = 0; k < 3; k++) {
        f.up[k] = head[k] - pel[k];
        left[k] = hl[k] - hr[k];
    }
    normalize(f.up);
    double d = left[0] * f.up[0] + left[1] * f.up[1] + left[2] * f.up[2];
    for (int k = 0; k < 3; k++)
        left[k] -= d * f.up[k];
    normalize(left);
    f.forward[0] = left[1] * f.up[2] - left[2] * f.up[1];
    f.forward[1] = left[2] * f.up[0] - left[0] * f.up[2];
    f.forward[2] = left[0] * f.up[1] - left[1] * f.up[0];
    *state = &f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    pose_state_free(f->st);
    pb_rig_skel_free(f->skel);
    pose_rig_free(f->rig);
    return 0;
}

/* Angle (deg) between the direction from joint a to joint b and axis v. */
static double seg_angle(const fixture *f, const char *a, const char *b, const double v[3])
{
    double pa[3], pb[3], d[3];
    joint_pos(f, a, pa);
    joint_pos(f, b, pb);
    for (int k = 0; k < 3; k++)
        d[k] = pb[k] - pa[k];
    normalize(d);
    double c = d[0] * v[0] + d[1] * v[1] + d[2] * v[2];
    return acos(c > 1 ? 1 : c < -1 ? -1 : c) * 180.0 / PB_PI;
}

/* Height of joint b above joint a along the body's up axis (metres). */
static double above(const fixture *f, const char *b, const char *a)
{
    double pa[3], pb[3];
    joint_pos(f, a, pa);
    joint_pos(f, b, pb);
    return (pb[0] - pa[0]) * f->up[0] + (pb[1] - pa[1]) * f->up[1] + (pb[2] - pa[2]) * f->up[2];
}

/* ------------------------------------------------------ replaying a source */

typedef struct replay {
    pb_source *src;
    pb_chanmap *cm;
    pb_mapping *map;
    pb_pose pose;
    int64_t t0;
    int started, have_next;
    pb_update next;
    uint32_t next_ch[64];
    double next_val[64];
} replay;

static void replay_open(replay *r, const fixture *f, const char *source, const char *map_rel)
{
    char mp[1024], sp[1024], rel[256];
    pb_error err;
    memset(r, 0, sizeof *r);
    snprintf(rel, sizeof rel, "../bridge/maps/%s", map_rel);
    BT_DATA(mp, rel);
    BT_DATA(sp, source);
    if (pb_mapping_load(mp, &r->map, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pose_status s;
    if (strstr(source, ".log")) {
        pb_can_bus *bus = NULL;
        if (pb_can_bus_load(mp, &bus, &err) != POSE_OK)
            fail_msg("%s", err.message);
        s = pb_candump_replay_open(sp, bus, &(pb_candump_replay_options){.as_fast_as_possible = 1}, &r->src, &err);
    } else {
        s = pb_hid_open(sp, &(pb_hid_replay_options){.as_fast_as_possible = 1}, &r->src, &err);
    }
    if (s != POSE_OK)
        fail_msg("%s", err.message);
    if (pb_chanmap_create(r->map, r->src->channels, r->src->channel_count, f->skel, &r->cm, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(pb_pose_init(&r->pose, f->skel->joint_count), 0);
}

static void replay_close(replay *r)
{
    pb_pose_free(&r->pose);
    pb_chanmap_free(r->cm);
    pb_source_destroy(r->src);
    pb_mapping_free(r->map);
}

/* Feed every update up to recorded time t_s (from the first update), then
 * pose the state with the mapping's output: what a host sees at t_s. */
static void replay_pose_at(replay *r, fixture *f, double t_s)
{
    const int64_t want = (int64_t)(t_s * 1e9 + 0.5);
    for (;;) {
        pb_update u;
        if (r->have_next) {
            u = r->next;
        } else if (pb_source_read(r->src, &u, 1000) != 1) {
            if (r->src->state == PB_SOURCE_ENDED)
                break;
            continue; /* a fault the recording holds (silent node, bus-off): plays on */
        }
        if (!r->started) {
            r->t0 = u.t_ns;
            r->started = 1;
        }
        if (u.t_ns - r->t0 > want) {
            if (!r->have_next) {
                size_t n = u.count < 64 ? u.count : 64;
                memcpy(r->next_ch, u.channels, n * sizeof *u.channels);
                memcpy(r->next_val, u.values, n * sizeof *u.values);
                r->next = (pb_update){.t_ns = u.t_ns, .count = n, .channels = r->next_ch, .values = r->next_val};
                r->have_next = 1;
            }
            break;
        }
        r->have_next = 0;
        pb_chanmap_update(r->cm, &u);
    }
    pb_chanmap_pose(r->cm, &r->pose);
    pose_reset(f->st);
    assert_true(pb_pose_apply_to_state(&r->pose, f->st, NULL) >= 0);
    assert_int_equal(pose_apply(f->st), POSE_OK);
}

/* --------------------------------------------------- clinical angles back */

typedef struct truth_channel {
    const char *column; /* truth name */
    const char *joint;
    int dof;
} truth_channel;

typedef struct truth_stats {
    double worst, worst_t;
    const char *worst_name;
    long compared;
} truth_stats;

/* Compare every angle of the table with the posed joints at time t. */
static void compare_all(const fixture *f, const truth_channel *tab, int n, const double *truth, double t,
                        truth_stats *s)
{
    for (int i = 0; i < n; i++) {
        double want[3] = {0, 0, 0}; /* the joint's truth angles; undriven ones are 0 */
        for (int k = 0; k < n; k++)
            if (!strcmp(tab[k].joint, tab[i].joint))
                want[tab[k].dof] = truth[k];
        int j = pose_rig_find_joint(f->rig, tab[i].joint);
        assert_true(j >= 0);
        if (!tc_in_range(f->rig, j, want))
            continue;
        float hint[3] = {(float)want[0], (float)want[1], (float)want[2]}, got[3];
        tc_clinical_back(f->rig, f->st, j, hint, got);
        double e = fabs(got[tab[i].dof] - truth[i]);
        s->compared++;
        if (e > s->worst) {
            s->worst = e;
            s->worst_t = t;
            s->worst_name = tab[i].column;
        }
    }
}

/* -------------------------------------------------------------- CAN rig */

static const truth_channel CAN_TRUTH[] = {
    {"LUMBAR.flex", "lumbar", 0},         {"THORAX.flex", "thorax", 0},         {"NECK.flex", "neck", 0},
    {"SHOULDER_L.flex", "shoulder_l", 0}, {"SHOULDER_L.abd", "shoulder_l", 1}, {"SHOULDER_R.flex", "shoulder_r", 0},
    {"SHOULDER_R.abd", "shoulder_r", 1},  {"ELBOW_L.flex", "elbow_l", 0},       {"ELBOW_R.flex", "elbow_r", 0},
    {"HIP_L.flex", "hip_l", 0},           {"HIP_R.flex", "hip_r", 0},           {"KNEE_L.flex", "knee_l", 0},
    {"KNEE_R.flex", "knee_r", 0},         {"WRIST_L.angle", "wrist_l", 0},      {"WRIST_R.angle", "wrist_r", 0},
    {"ANKLE_L.angle", "ankle_l", 0},      {"ANKLE_R.angle", "ankle_r", 0},      {"HEAD.pitch", "head", 0},
    {"HEAD.roll", "head", 1},
};
enum { CAN_TRUTH_N = sizeof CAN_TRUTH / sizeof CAN_TRUTH[0] };

static void test_can_postures(void **state)
{
    fixture *f = *state;
    replay r;
    replay_open(&r, f, "can-rig/sit_stand_arm_raise.log", "can_rig_fullbody.json");
    double down[3] = {-f->up[0], -f->up[1], -f->up[2]};
    /* seated (0.8 s): hips and knees at 90 */
    replay_pose_at(&r, f, 0.8);
    for (int s = 0; s < 2; s++) {
        const char *hip = s ? "hip_l" : "hip_r", *knee = s ? "knee_l" : "knee_r", *ankle = s ? "ankle_l" : "ankle_r";
        double thigh = seg_angle(f, hip, knee, f->forward), shank = seg_angle(f, knee, ankle, down);
        print_message("CAN seated %s: thigh %.1f deg from horizontal forward, shank %.1f deg from vertical\n", hip,
                      thigh, shank);
        assert_true(thigh < 20.0);
        assert_true(shank < 20.0);
    }
    /* standing, arms at the sides (4.2 s) */
    replay_pose_at(&r, f, 4.2);
    static const char *const vertical[][2] = {{"hip_r", "knee_r"},   {"knee_r", "ankle_r"},    {"hip_l", "knee_l"},
                                              {"knee_l", "ankle_l"}, {"shoulder_r", "elbow_r"}, {"shoulder_l", "elbow_l"}};
    for (int i = 0; i < 6; i++) {
        double a = seg_angle(f, vertical[i][0], vertical[i][1], down);
        print_message("CAN standing: %s-%s %.1f deg from straight down\n", vertical[i][0], vertical[i][1], a);
        assert_true(a < 15.0);
    }
    /* both shoulders flexed 150 (7.6 s): hands above the head */
    replay_pose_at(&r, f, 7.6);
    for (int s = 0; s < 2; s++) {
        const char *sh = s ? "shoulder_l" : "shoulder_r", *el = s ? "elbow_l" : "elbow_r", *wr = s ? "wrist_l" : "wrist_r";
        print_message("CAN flexion 150 %s: elbow %+.3f m, wrist %+.3f m above the shoulder, wrist %+.3f m above "
                      "the head joint\n",
                      sh, above(f, el, sh), above(f, wr, sh), above(f, wr, "head"));
        assert_true(above(f, el, sh) > 0.0);
        assert_true(above(f, wr, sh) > 0.0);
        assert_true(above(f, wr, "head") > 0.0);
    }
    replay_close(&r);
}

static void test_can_truth(void **state)
{
    fixture *f = *state;
    char p[1024], line[4096];
    FILE *csv = fopen(BT_DATA(p, "can-rig/sit_stand_arm_raise_truth.csv"), "r");
    assert_non_null(csv);
    assert_non_null(fgets(line, sizeof line, csv));
    char names[32][32];
    int ncol = 0;
    for (char *tok = strtok(line, ",\n"); tok && ncol < 32; tok = strtok(NULL, ",\n"))
        snprintf(names[ncol++], sizeof names[0], "%s", tok);
    int col[CAN_TRUTH_N];
    for (int i = 0; i < CAN_TRUTH_N; i++) {
        col[i] = -1;
        for (int c = 1; c < ncol; c++)
            if (!strcmp(names[c], CAN_TRUTH[i].column))
                col[i] = c;
        if (col[i] < 0)
            fail_msg("the truth file has no column %s", CAN_TRUTH[i].column);
    }
    replay r;
    replay_open(&r, f, "can-rig/sit_stand_arm_raise.log", "can_rig_fullbody.json");
    truth_stats s = {0, 0, "", 0};
    while (fgets(line, sizeof line, csv)) {
        double v[32], truth[CAN_TRUTH_N];
        int n = 0;
        for (char *tok = strtok(line, ",\n"); tok && n < 32; tok = strtok(NULL, ",\n"))
            v[n++] = atof(tok);
        assert_int_equal(n, ncol);
        for (int i = 0; i < CAN_TRUTH_N; i++)
            truth[i] = v[col[i]];
        replay_pose_at(&r, f, v[0]);
        compare_all(f, CAN_TRUTH, CAN_TRUTH_N, truth, v[0], &s);
    }
    fclose(csv);
    replay_close(&r);
    print_message("CAN truth: %ld angles compared, worst %.2f deg (%s at %.2f s)\n", s.compared, s.worst,
                  s.worst_name, s.worst_t);
    assert_true(s.compared > 3000);
    assert_true(s.worst < 2.0);
}

/* ---------------------------------------------------------- HID mannequin */

/* The generator's axes (pb_mannequin_axis_names) as joint angles. */
static const truth_channel HID_TRUTH[PB_MANNEQUIN_AXES] = {
    {"lumbar.flexion", "lumbar", 0},
    {"neck.flexion", "neck", 0},
    {"shoulder_l.flexion", "shoulder_l", 0},
    {"shoulder_l.abduction", "shoulder_l", 1},
    {"shoulder_r.flexion", "shoulder_r", 0},
    {"shoulder_r.abduction", "shoulder_r", 1},
    {"elbow_l.flexion", "elbow_l", 0},
    {"elbow_r.flexion", "elbow_r", 0},
    {"hip_l.flexion", "hip_l", 0},
    {"hip_l.abduction", "hip_l", 1},
    {"hip_r.flexion", "hip_r", 0},
    {"hip_r.abduction", "hip_r", 1},
    {"knee_l.flexion", "knee_l", 0},
    {"knee_r.flexion", "knee_r", 0},
    {"ankle_l.dorsiflexion", "ankle_l", 0},
    {"ankle_r.dorsiflexion", "ankle_r", 0},
};

static void hid_truth(fixture *f, const char *file, pb_mannequin_motion motion, double seconds, truth_stats *s)
{
    replay r;
    replay_open(&r, f, file, "hid_mannequin_full_body.json");
    double last_hold = -1.0;
    for (int i = 0; i < PB_MANNEQUIN_AXES; i++)
        assert_string_equal(pb_mannequin_axis_names[i], HID_TRUTH[i].column);
    for (double t = 0.05; t < seconds - 0.01; t += 0.05) {
        double deg[PB_MANNEQUIN_AXES];
        int hold;
        pb_mannequin_pose(motion, t, deg, &hold);
        replay_pose_at(&r, f, t);
        if (hold)
            last_hold = t;
        if (last_hold >= 0 && t - last_hold < 0.5)
            continue; /* the hold button freezes the joints; the filters catch up after */
        compare_all(f, HID_TRUTH, PB_MANNEQUIN_AXES, deg, t, s);
    }
    replay_close(&r);
}

static void test_hid_truth(void **state)
{
    fixture *f = *state;
    truth_stats a = {0, 0, "", 0}, b = {0, 0, "", 0};
    hid_truth(f, "hid/mannequin_sit_to_stand.hid", PB_MOTION_SIT_TO_STAND, 8.0, &a);
    hid_truth(f, "hid/mannequin_arm_raise.hid", PB_MOTION_ARM_RAISE, 10.0, &b);
    print_message("HID truth: sit to stand %ld angles, worst %.2f deg (%s at %.2f s); arm raise %ld angles, worst "
                  "%.2f deg (%s at %.2f s)\n",
                  a.compared, a.worst, a.worst_name, a.worst_t, b.compared, b.worst, b.worst_name, b.worst_t);
    assert_true(a.compared > 1500 && b.compared > 1500);
    assert_true(a.worst < 2.0);
    assert_true(b.worst < 2.0);
}

static void test_hid_postures(void **state)
{
    fixture *f = *state;
    double down[3] = {-f->up[0], -f->up[1], -f->up[2]};
    replay r;
    replay_open(&r, f, "hid/mannequin_sit_to_stand.hid", "hid_mannequin_full_body.json");
    replay_pose_at(&r, f, 0.3); /* seated */
    double thigh = seg_angle(f, "hip_r", "knee_r", f->forward), shank = seg_angle(f, "knee_r", "ankle_r", down);
    print_message("HID seated: thigh %.1f deg from horizontal forward, shank %.1f from vertical\n", thigh, shank);
    assert_true(thigh < 20.0 && shank < 20.0);
    replay_pose_at(&r, f, 7.8); /* standing */
    assert_true(seg_angle(f, "hip_l", "knee_l", down) < 15.0);
    assert_true(seg_angle(f, "knee_l", "ankle_l", down) < 15.0);
    assert_true(seg_angle(f, "shoulder_l", "elbow_l", down) < 15.0);
    replay_close(&r);

    /* the right arm's forward flexion passes 90 on its way up (6-8 s) */
    double t90 = 6.0, deg[PB_MANNEQUIN_AXES];
    for (; t90 < 8.0; t90 += 0.002) {
        pb_mannequin_pose(PB_MOTION_ARM_RAISE, t90, deg, NULL);
        if (deg[4] >= 90.0)
            break;
    }
    replay_open(&r, f, "hid/mannequin_arm_raise.hid", "hid_mannequin_full_body.json");
    replay_pose_at(&r, f, t90);
    double fwd = seg_angle(f, "shoulder_r", "elbow_r", f->forward);
    print_message("HID forward flexion 90 at %.2f s: upper arm %.1f deg from horizontal forward\n", t90, fwd);
    assert_true(fwd < 15.0);
    replay_close(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_can_postures),
        cmocka_unit_test(test_can_truth),
        cmocka_unit_test(test_hid_postures),
        cmocka_unit_test(test_hid_truth),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
