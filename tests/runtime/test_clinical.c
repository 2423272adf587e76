/* SPDX-License-Identifier: Apache-2.0 */
/* Clinical angles on a small arm rig that rests in a T-pose and whose
 * clinical data puts the arm down at neutral: postures measured back from
 * pose_joint_world, conversions both ways (both triples, hints, gimbal
 * lock), clamping in the clinical range of motion from every setter, a
 * state's own ranges (pose_set_joint_range), the neutral posture, and rigs
 * without clinical data. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pose/pose.h"
#include "test_math.h"

/* Model space: x to the patient's left, y up, z forward. The left arm rests
 * along +x (T-pose); every arm joint's rest frame is turned 90 degrees about
 * z, so the arm runs along the frames' -y. */
enum { SPINE, SHOULDER, ELBOW, WRIST, JOINTS };
static const float k_shoulder[3] = {0.2f, 1.4f, 0.0f};
#define UPPER_ARM 0.3f
#define FOREARM 0.25f
#define S45 0.70710678f
#define DEG (3.14159265358979323846 / 180.0)

typedef struct arm {
    pose_joint_desc joints[JOINTS];
    pose_joint_clinical clinical[JOINTS];
    float tet_positions[12];
    uint32_t tets[4];
    uint16_t labels[1];
    uint16_t weight_joints[4];
    float weights[4];
    pose_rig_desc desc;
} arm;

static pose_rig *arm_rig(int with_clinical)
{
    static arm a;
    memset(&a, 0, sizeof a);
    static const char *const names[JOINTS] = {"spine", "shoulder_l", "elbow_l", "wrist_l"};
    const float x[JOINTS] = {0.0f, k_shoulder[0], k_shoulder[0] + UPPER_ARM,
                             k_shoulder[0] + UPPER_ARM + FOREARM};
    for (int j = 0; j < JOINTS; j++) {
        pose_joint_desc *d = &a.joints[j];
        d->name = names[j];
        d->parent = j - 1;
        d->rest_model.translation[0] = x[j];
        d->rest_model.translation[1] = j == SPINE ? 1.0f : k_shoulder[1];
        d->rest_model.rotation[2] = j == SPINE ? 0.0f : S45;
        d->rest_model.rotation[3] = j == SPINE ? 1.0f : S45;
    }
    /* Rest-frame limits that would clamp any real shoulder motion: joints
     * with clinical data use their clinical range instead. */
    a.joints[SHOULDER].limit_flags = POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z;
    a.joints[WRIST].limit_flags = POSE_LIMIT_Z;
    for (int k = 0; k < 3; k++) {
        a.joints[SHOULDER].limit_min_deg[k] = a.joints[WRIST].limit_min_deg[k] = -10.0f;
        a.joints[SHOULDER].limit_max_deg[k] = a.joints[WRIST].limit_max_deg[k] = 10.0f;
    }

    /* Shoulder: neutral = arm down = -90 degrees about the frame's z (= model
     * z). Axes in the rest frame (model direction in brackets): flexion +y
     * (-x: forward raise), abduction +z (+z: sideways raise), internal
     * rotation -x (-y, distally along the hanging arm): a left-handed set,
     * as for a left limb. AAOS ranges. */
    pose_joint_clinical *s = &a.clinical[SHOULDER];
    s->flags = POSE_CLINICAL_DEFINED;
    s->neutral[2] = -S45;
    s->neutral[3] = S45;
    static const float shoulder_axes[3][3] = {{0, 1, 0}, {0, 0, 1}, {-1, 0, 0}};
    memcpy(s->axes, shoulder_axes, sizeof shoulder_axes);
    s->limit_flags = POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z;
    static const float s_lo[3] = {-60, -30, -90}, s_hi[3] = {180, 180, 70};
    memcpy(s->limit_min_deg, s_lo, sizeof s_lo);
    memcpy(s->limit_max_deg, s_hi, sizeof s_hi);
    /* Elbow: neutral = rest (straight); flexion about the frame's -x brings
     * the forearm forward; right-handed axes; varus unlimited. */
    pose_joint_clinical *e = &a.clinical[ELBOW];
    e->flags = POSE_CLINICAL_DEFINED;
    e->neutral[3] = 1.0f;
    static const float elbow_axes[3][3] = {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}};
    memcpy(e->axes, elbow_axes, sizeof elbow_axes);
    e->names[1] = "varus";
    e->names[2] = "pronation";
    e->limit_flags = POSE_LIMIT_X | POSE_LIMIT_Z;
    e->limit_min_deg[0] = 0.0f;
    e->limit_max_deg[0] = 150.0f;
    e->limit_min_deg[2] = -80.0f;
    e->limit_max_deg[2] = 80.0f;

    /* The smallest mesh a rig may have: one tet on the spine. */
    static const float tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(a.tet_positions, tet, sizeof tet);
    for (int i = 0; i < 4; i++) {
        a.tets[i] = (uint32_t)i;
        a.weights[i] = 1.0f;
    }
    a.desc = (pose_rig_desc){
        .joint_count = JOINTS, .joints = a.joints,
        .tet_vertex_count = 4, .tet_positions = a.tet_positions,
        .tet_count = 1, .tets = a.tets, .tet_labels = a.labels,
        .influences = 1, .weight_joints = a.weight_joints, .weights = a.weights,
        .clinical = with_clinical ? a.clinical : NULL,
    };
    pose_rig *rig;
    if (pose_rig_create(&a.desc, NULL, &rig) != POSE_OK)
        fail_msg("%s", pose_last_error());
    return rig;
}

static void world_position(pose_state *st, int joint, double p[3])
{
    pose_transform w;
    assert_int_equal(pose_joint_world(st, joint, &w), POSE_OK);
    for (int i = 0; i < 3; i++)
        p[i] = w.translation[i];
}

/* Joint `joint` sits at `from` + `len` * `dir` after pose_apply. */
static void assert_segment(pose_state *st, int from, int joint, double len, double dir_x,
                           double dir_y, double dir_z)
{
    double a[3], b[3], d[3] = {dir_x, dir_y, dir_z};
    world_position(st, from, a);
    world_position(st, joint, b);
    for (int i = 0; i < 3; i++)
        if (fabs(b[i] - (a[i] + len * d[i])) > 1e-4)
            fail_msg("joint %d at (%.5f %.5f %.5f), expected (%.5f %.5f %.5f)", joint, b[0], b[1],
                     b[2], a[0] + len * d[0], a[1] + len * d[1], a[2] + len * d[2]);
}

static void set_clinical(pose_state *st, int joint, float f, float a, float r, pose_status want)
{
    const float deg[3] = {f, a, r};
    pose_status got = pose_set_joint_clinical(st, joint, deg);
    if (got != want)
        fail_msg("joint %d (%g, %g, %g): status %d, expected %d (%s)", joint, (double)f, (double)a,
                 (double)r, got, want, pose_last_error());
}

static void assert_angles(const float got[3], double f, double a, double r, double tol)
{
    if (fabs(got[0] - f) > tol || fabs(got[1] - a) > tol || fabs(got[2] - r) > tol)
        fail_msg("angles (%.5f %.5f %.5f), expected (%.5f %.5f %.5f)", (double)got[0],
                 (double)got[1], (double)got[2], f, a, r);
}

/* The postures of design §2b, measured from joint world positions. */
static void test_arm_postures(void **unused)
{
    (void)unused;
    pose_rig *rig = arm_rig(1);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    const double c150 = cos(150.0 * DEG), s150 = sin(150.0 * DEG);

    set_clinical(st, SHOULDER, 0, 0, 0, POSE_OK);
    set_clinical(st, ELBOW, 0, 0, 0, POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    assert_segment(st, SHOULDER, ELBOW, UPPER_ARM, 0, -1, 0); /* straight down */
    assert_segment(st, ELBOW, WRIST, FOREARM, 0, -1, 0);

    set_clinical(st, SHOULDER, 90, 0, 0, POSE_OK); /* forward, horizontal */
    pose_apply(st);
    assert_segment(st, SHOULDER, ELBOW, UPPER_ARM, 0, 0, 1);
    assert_segment(st, ELBOW, WRIST, FOREARM, 0, 0, 1);

    set_clinical(st, SHOULDER, 150, 0, 0, POSE_OK); /* the rest-frame limits would clamp this */
    pose_apply(st);
    assert_segment(st, SHOULDER, ELBOW, UPPER_ARM, 0, -c150, s150);
    double sh[3], el[3], wr[3];
    world_position(st, SHOULDER, sh);
    world_position(st, ELBOW, el);
    world_position(st, WRIST, wr);
    assert_true(el[1] > sh[1] + 0.25 && wr[1] > el[1]); /* elbow and wrist above the shoulder */

    set_clinical(st, SHOULDER, 0, 90, 0, POSE_OK); /* the T-pose the rig rests in */
    pose_apply(st);
    assert_segment(st, SHOULDER, ELBOW, UPPER_ARM, 1, 0, 0);
    float q[4];
    pose_get_joint(st, SHOULDER, q);
    double identity[4] = {0, 0, 0, 1};
    assert_true(dq_dist(identity, q) < 1e-6);

    set_clinical(st, SHOULDER, 0, 150, 0, POSE_OK);
    pose_apply(st);
    assert_segment(st, SHOULDER, ELBOW, UPPER_ARM, s150, -c150, 0);

    /* Elbow flexed 90: the forearm points forward; internal rotation of the
     * shoulder then swings it across the body (medially, -x). */
    set_clinical(st, SHOULDER, 0, 0, 0, POSE_OK);
    set_clinical(st, ELBOW, 90, 0, 0, POSE_OK);
    pose_apply(st);
    assert_segment(st, ELBOW, WRIST, FOREARM, 0, 0, 1);
    set_clinical(st, SHOULDER, 0, 0, 60, POSE_OK);
    pose_apply(st);
    assert_segment(st, SHOULDER, ELBOW, UPPER_ARM, 0, -1, 0);
    assert_segment(st, ELBOW, WRIST, FOREARM, -sin(60 * DEG), 0, cos(60 * DEG));
    pose_state_free(st);
    pose_rig_free(rig);
}

static double frand(unsigned *seed, double lo, double hi)
{
    *seed = *seed * 1103515245u + 12345u;
    return lo + (hi - lo) * (double)((*seed >> 8) & 0xFFFFFF) / (double)0x1000000;
}

/* The other triple of the same rotation, wrapped to (-180, 180]. */
static void other_triple(const double d[3], double o[3])
{
    const double raw[3] = {d[0] + 180.0, 180.0 - d[1], d[2] + 180.0};
    for (int i = 0; i < 3; i++)
        o[i] = raw[i] > 180.0 ? raw[i] - 360.0 : raw[i];
}

/* clinical -> local -> clinical for random triples inside the ranges, away
 * from gimbal lock: without a hint the triple inside the range comes back
 * (the other one never is for these ranges); a hint selects either; the
 * state reads a quaternion the same way. */
static void test_round_trip(void **unused)
{
    (void)unused;
    pose_rig *rig = arm_rig(1);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    unsigned seed = 12345u;
    const int joints[2] = {SHOULDER, ELBOW};
    int tested = 0, beyond_90 = 0;
    for (int n = 0; n < 2000; n++) {
        int j = joints[n % 2];
        pose_joint_clinical c;
        assert_int_equal(pose_rig_joint_clinical(rig, j, &c), POSE_OK);
        double d[3];
        for (int k = 0; k < 3; k++)
            d[k] = (c.limit_flags & (1u << k)) ? frand(&seed, c.limit_min_deg[k], c.limit_max_deg[k])
                                               : frand(&seed, -180.0, 180.0);
        if (fabs(fabs(d[1]) - 90.0) < 2.0)
            continue;
        tested++;
        beyond_90 += fabs(d[1]) > 90.0;
        const float df[3] = {(float)d[0], (float)d[1], (float)d[2]};
        float q[4], back[3];
        assert_int_equal(pose_clinical_to_local(rig, j, df, q), POSE_OK);
        assert_int_equal(pose_local_to_clinical(rig, j, q, NULL, back), POSE_OK);
        assert_angles(back, d[0], d[1], d[2], 2e-3);
        assert_int_equal(pose_local_to_clinical(rig, j, q, df, back), POSE_OK);
        assert_angles(back, d[0], d[1], d[2], 2e-3);
        double o[3];
        other_triple(d, o);
        const float of[3] = {(float)o[0], (float)o[1], (float)o[2]};
        assert_int_equal(pose_local_to_clinical(rig, j, q, of, back), POSE_OK);
        assert_angles(back, o[0], o[1], o[2], 2e-3);
        float qo[4];
        pose_clinical_to_local(rig, j, of, qo);
        double qd[4] = {q[0], q[1], q[2], q[3]};
        assert_true(dq_dist(qd, qo) < 2e-6); /* the same rotation */
        assert_int_equal(pose_set_joint(st, j, q), POSE_OK);
        assert_int_equal(pose_get_joint_clinical(st, j, back), POSE_OK);
        assert_angles(back, d[0], d[1], d[2], 2e-3);
    }
    assert_true(tested > 1800);
    assert_true(beyond_90 > 300); /* shoulder abduction past 90 takes the second triple */

    /* Neither triple inside the range: abduction in [-90, 90]. */
    const float outside[3] = {-100, 120, 0};
    float q[4], back[3];
    pose_clinical_to_local(rig, SHOULDER, outside, q);
    assert_int_equal(pose_local_to_clinical(rig, SHOULDER, q, NULL, back), POSE_OK);
    assert_near(back[0], 80.0, 2e-3);
    assert_near(back[1], 60.0, 2e-3);
    assert_near(fabs(back[2]), 180.0, 2e-3);
    pose_state_free(st);
    pose_rig_free(rig);
}

/* Abduction +-90: only flexion +- rotation is defined. */
static void test_gimbal_lock(void **unused)
{
    (void)unused;
    pose_rig *rig = arm_rig(1);
    float q[4], back[3], again[3], q2[4];
    const float locked[3] = {30, 90, 0}, locked_down[3] = {30, -90, 0}, hint[3] = {20, 90, 10};
    /* Right-handed elbow: (30, 90, 0) = (20, 90, 10). */
    pose_clinical_to_local(rig, ELBOW, locked, q);
    assert_int_equal(pose_local_to_clinical(rig, ELBOW, q, NULL, back), POSE_OK);
    assert_angles(back, 30, 90, 0, 1e-3);
    pose_local_to_clinical(rig, ELBOW, q, NULL, again);
    assert_memory_equal(back, again, sizeof back); /* deterministic */
    assert_int_equal(pose_local_to_clinical(rig, ELBOW, q, hint, back), POSE_OK);
    assert_angles(back, 20, 90, 10, 1e-3);
    pose_clinical_to_local(rig, ELBOW, locked_down, q);
    pose_local_to_clinical(rig, ELBOW, q, NULL, back);
    assert_angles(back, 30, -90, 0, 1e-3);
    const float hint_down[3] = {20, -90, 10};
    pose_local_to_clinical(rig, ELBOW, q, hint_down, back); /* at -90: flexion - rotation is fixed */
    assert_angles(back, 40, -90, 10, 1e-3);
    /* Left-handed shoulder: the rotation axis is mirrored, (30, 90, 0) = (40, 90, 10). */
    pose_clinical_to_local(rig, SHOULDER, locked, q);
    pose_local_to_clinical(rig, SHOULDER, q, NULL, back);
    assert_angles(back, 30, 90, 0, 1e-3);
    pose_local_to_clinical(rig, SHOULDER, q, hint, back);
    assert_angles(back, 40, 90, 10, 1e-3);
    pose_clinical_to_local(rig, SHOULDER, back, q2);
    double qd[4] = {q[0], q[1], q[2], q[3]};
    assert_true(dq_dist(qd, q2) < 2e-6);

    /* The rig rests at shoulder abduction 90; the state reads that as such,
     * and keeps whatever split of a locked pose was asked for. */
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_int_equal(pose_get_joint_clinical(st, SHOULDER, back), POSE_OK);
    assert_angles(back, 0, 90, 0, 1e-3);
    set_clinical(st, SHOULDER, 20, 90, 10, POSE_OK);
    pose_get_joint_clinical(st, SHOULDER, back);
    assert_angles(back, 20, 90, 10, 1e-4);
    const float identity[4] = {0, 0, 0, 1};
    assert_int_equal(pose_set_joint(st, SHOULDER, identity), POSE_OK);
    pose_get_joint_clinical(st, SHOULDER, back);
    assert_angles(back, 0, 90, 0, 1e-3);
    pose_state_free(st);
    pose_rig_free(rig);
}

static void assert_local_is(pose_state *st, int joint, float f, float a, float r)
{
    const float deg[3] = {f, a, r};
    float want[4], got[4], angles[3];
    assert_int_equal(pose_clinical_to_local(pose_state_rig(st), joint, deg, want), POSE_OK);
    assert_int_equal(pose_get_joint(st, joint, got), POSE_OK);
    double wd[4] = {want[0], want[1], want[2], want[3]};
    assert_true(dq_dist(wd, got) < 2e-6);
    assert_int_equal(pose_get_joint_clinical(st, joint, angles), POSE_OK);
    assert_angles(angles, f, a, r, 2e-3);
}

static void assert_message(const char *needle)
{
    if (!strstr(pose_last_error(), needle))
        fail_msg("message \"%s\" lacks \"%s\"", pose_last_error(), needle);
}

/* Every setter clamps a joint with clinical data in its clinical range. */
static void test_clamping(void **unused)
{
    (void)unused;
    pose_rig *rig = arm_rig(1);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);

    set_clinical(st, SHOULDER, 170, 0, 100, POSE_CLAMPED);
    assert_message("joint 1 'shoulder_l': internal_rotation 100.00 clamped to 70.00 by 30.00 "
                   "[-90.00, 70.00] degrees from neutral");
    assert_local_is(st, SHOULDER, 170, 0, 70);
    set_clinical(st, SHOULDER, -90, -45, 0, POSE_CLAMPED);
    assert_message("flexion -90.00 clamped to -60.00 by 30.00");
    assert_message("abduction -45.00 clamped to -30.00 by 15.00");
    assert_local_is(st, SHOULDER, -60, -30, 0);
    /* Angles are periodic: 350 is -10, inside; -170 is 190, past 180 by 10. */
    set_clinical(st, SHOULDER, 350, 0, 0, POSE_OK);
    assert_local_is(st, SHOULDER, -10, 0, 0);
    set_clinical(st, SHOULDER, -170, 0, 0, POSE_CLAMPED);
    assert_local_is(st, SHOULDER, 180, 0, 0);
    set_clinical(st, ELBOW, 160, 0, 0, POSE_CLAMPED);
    assert_message("joint 2 'elbow_l': flexion 160.00 clamped to 150.00 by 10.00");
    set_clinical(st, ELBOW, 45, 0, -95, POSE_CLAMPED);
    assert_message("pronation -95.00 clamped to -80.00");
    set_clinical(st, ELBOW, 45, 170, 0, POSE_OK); /* varus is not limited */

    /* A quaternion past the range: adduction 60 -> 30. */
    const float adducted[3] = {0, -60, 0};
    float q[4];
    pose_clinical_to_local(rig, SHOULDER, adducted, q);
    assert_int_equal(pose_set_joint(st, SHOULDER, q), POSE_CLAMPED);
    assert_message("abduction -60.00 clamped to -30.00 by 30.00");
    assert_local_is(st, SHOULDER, 0, -30, 0);
    /* The same rotation as rest-frame Euler angles: R_z(-60) * neutral = R_z(-150). */
    const float euler[3] = {0, 0, -150};
    assert_int_equal(pose_set_joint_euler(st, SHOULDER, euler, POSE_EULER_XYZ), POSE_CLAMPED);
    assert_message("abduction -60.00 clamped to -30.00");
    assert_local_is(st, SHOULDER, 0, -30, 0);
    /* Within the range nothing changes, whatever the rest-frame limits say. */
    const float raised[3] = {120, 40, -20};
    pose_clinical_to_local(rig, SHOULDER, raised, q);
    assert_int_equal(pose_set_joint(st, SHOULDER, q), POSE_OK);
    assert_string_equal(pose_last_error(), "");
    assert_local_is(st, SHOULDER, 120, 40, -20);

    /* A joint without clinical data keeps its rest-frame limits. */
    const float twist[3] = {0, 0, 50};
    assert_int_equal(pose_set_joint_euler(st, WRIST, twist, POSE_EULER_XYZ), POSE_CLAMPED);
    assert_message("joint 3 'wrist_l': z 50.00 clamped to 10.00");
    pose_state_free(st);
    pose_rig_free(rig);
}

static void assert_range(const pose_state *st, int joint, const float lo[3], const float hi[3],
                         uint32_t flags)
{
    float got_lo[3], got_hi[3];
    uint32_t got_flags = 0;
    assert_int_equal(pose_get_joint_range(st, joint, got_lo, got_hi, &got_flags), POSE_OK);
    for (int a = 0; a < 3; a++) {
        assert_true(got_lo[a] == lo[a]);
        assert_true(got_hi[a] == hi[a]);
    }
    assert_int_equal(got_flags, flags);
}

/* A frozen shoulder narrows one state's range: requests the rig's range
 * allows clamp there, from every setter, while another state of the same
 * rig is untouched; NULL gives the rig's range back. */
static void test_narrowed_range(void **unused)
{
    (void)unused;
    pose_rig *rig = arm_rig(1);
    pose_state *st, *other;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_int_equal(pose_state_create(rig, &other), POSE_OK);
    const float rig_lo[3] = {-60, -30, -90}, rig_hi[3] = {180, 180, 70};
    const uint32_t xyz = POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z;
    assert_range(st, SHOULDER, rig_lo, rig_hi, xyz);

    set_clinical(st, SHOULDER, 90, 0, 0, POSE_OK);
    const float lo[3] = {-10, -10, -20}, hi[3] = {40, 45, 20};
    assert_int_equal(pose_set_joint_range(st, SHOULDER, lo, hi), POSE_OK);
    assert_range(st, SHOULDER, lo, hi, xyz);
    float deg[3];
    pose_get_joint_clinical(st, SHOULDER, deg); /* kept until the joint is set again */
    assert_angles(deg, 90, 0, 0, 1e-4);

    set_clinical(st, SHOULDER, 90, 0, 0, POSE_CLAMPED);
    assert_message("joint 1 'shoulder_l': flexion 90.00 clamped to 40.00 by 50.00 [-10.00, 40.00]");
    assert_local_is(st, SHOULDER, 40, 0, 0);
    set_clinical(other, SHOULDER, 90, 0, 0, POSE_OK);
    /* A quaternion: abduction 150 stops at 45, where the arm then points. */
    const float raised[3] = {0, 150, 0};
    float q[4];
    pose_clinical_to_local(rig, SHOULDER, raised, q);
    assert_int_equal(pose_set_joint(st, SHOULDER, q), POSE_CLAMPED);
    assert_message("abduction 150.00 clamped to 45.00 by 105.00");
    assert_local_is(st, SHOULDER, 0, 45, 0);
    assert_int_equal(pose_apply(st), POSE_OK);
    assert_segment(st, SHOULDER, ELBOW, UPPER_ARM, S45, -S45, 0);
    assert_int_equal(pose_set_joint(other, SHOULDER, q), POSE_OK);

    /* pose_reset keeps the state's range; NULL restores the rig's. */
    assert_int_equal(pose_reset(st), POSE_OK);
    assert_range(st, SHOULDER, lo, hi, xyz);
    assert_int_equal(pose_set_joint_range(st, SHOULDER, NULL, NULL), POSE_OK);
    assert_range(st, SHOULDER, rig_lo, rig_hi, xyz);
    set_clinical(st, SHOULDER, 90, 0, 0, POSE_OK);
    assert_int_equal(pose_set_joint(st, SHOULDER, q), POSE_OK);
    pose_state_free(other);
    pose_state_free(st);
    pose_rig_free(rig);
}

/* A wider range lets through what the rig's clamps; an angle the rig leaves
 * free can be limited, and a whole turn frees it again; a contracture that
 * excludes 0 makes the neutral posture clamp. */
static void test_widened_range(void **unused)
{
    (void)unused;
    pose_rig *rig = arm_rig(1);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    const float rig_lo[3] = {0, -180, -80}, rig_hi[3] = {150, 180, 80};
    assert_range(st, ELBOW, rig_lo, rig_hi, POSE_LIMIT_X | POSE_LIMIT_Z);
    set_clinical(st, ELBOW, 160, 0, 0, POSE_CLAMPED);

    const float lo[3] = {-5, -5, -90}, hi[3] = {165, 5, 90};
    assert_int_equal(pose_set_joint_range(st, ELBOW, lo, hi), POSE_OK);
    assert_range(st, ELBOW, lo, hi, POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z);
    set_clinical(st, ELBOW, 160, 0, -85, POSE_OK);
    assert_local_is(st, ELBOW, 160, 0, -85);
    set_clinical(st, ELBOW, -3, 0, 0, POSE_OK); /* hyperextension */
    set_clinical(st, ELBOW, 45, 20, 0, POSE_CLAMPED); /* varus, free on the rig, now limited */
    assert_message("joint 2 'elbow_l': varus 20.00 clamped to 5.00 by 15.00 [-5.00, 5.00]");
    assert_local_is(st, ELBOW, 45, 5, 0);

    const float free_lo[3] = {-5, -180, -90}, free_hi[3] = {165, 180, 90};
    assert_int_equal(pose_set_joint_range(st, ELBOW, free_lo, free_hi), POSE_OK);
    assert_range(st, ELBOW, free_lo, free_hi, POSE_LIMIT_X | POSE_LIMIT_Z);
    set_clinical(st, ELBOW, 45, 20, 0, POSE_OK);

    const float contracture_lo[3] = {20, -180, -80}, contracture_hi[3] = {90, 180, 80};
    assert_int_equal(pose_set_joint_range(st, ELBOW, contracture_lo, contracture_hi), POSE_OK);
    assert_int_equal(pose_set_neutral(st), POSE_CLAMPED);
    assert_message("joint 2 'elbow_l': flexion 0.00 clamped to 20.00");
    float deg[3];
    pose_get_joint_clinical(st, ELBOW, deg);
    assert_angles(deg, 20, 0, 0, 1e-4);
    pose_state_free(st);
    pose_rig_free(rig);
}

static void test_range_arguments(void **unused)
{
    (void)unused;
    pose_rig *rig = arm_rig(1);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    const float lo[3] = {0, 0, 0}, hi[3] = {10, 10, 10}, bad_hi[3] = {10, -1, 10};
    const float nan3[3] = {0, NAN, 0}, inf3[3] = {10, 10, INFINITY};
    float out[3];
    uint32_t flags;
    assert_int_equal(pose_set_joint_range(NULL, SHOULDER, lo, hi), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint_range(st, -1, lo, hi), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint_range(st, JOINTS, lo, hi), POSE_ERR_INVALID_ARGUMENT);
    assert_message("joint 4 out of range (4 joints)");
    assert_int_equal(pose_set_joint_range(st, WRIST, lo, hi), POSE_ERR_UNSUPPORTED);
    assert_message("pose_set_joint_range: joint 3 'wrist_l' has no clinical data");
    assert_int_equal(pose_set_joint_range(st, WRIST, NULL, NULL), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_set_joint_range(st, SHOULDER, lo, NULL), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint_range(st, SHOULDER, NULL, hi), POSE_ERR_INVALID_ARGUMENT);
    assert_message("give both min_deg and max_deg");
    assert_int_equal(pose_set_joint_range(st, SHOULDER, lo, bad_hi), POSE_ERR_INVALID_ARGUMENT);
    assert_message("joint 1 'shoulder_l': abduction range [0, -1] is not finite with min <= max");
    assert_int_equal(pose_set_joint_range(st, SHOULDER, nan3, hi), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint_range(st, ELBOW, lo, inf3), POSE_ERR_INVALID_ARGUMENT);
    assert_message("pronation range [0, inf]");
    /* a refused range leaves the state's as it was */
    const float rig_lo[3] = {-60, -30, -90}, rig_hi[3] = {180, 180, 70};
    assert_range(st, SHOULDER, rig_lo, rig_hi, POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z);
    assert_int_equal(pose_get_joint_range(NULL, SHOULDER, out, out, &flags), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_get_joint_range(st, 9, out, out, &flags), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_get_joint_range(st, SPINE, out, out, &flags), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_get_joint_range(st, SHOULDER, NULL, NULL, NULL), POSE_OK);
    pose_state_free(st);
    pose_rig_free(rig);

    /* a rig without clinical data has no ranges to give */
    rig = arm_rig(0);
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_int_equal(pose_set_joint_range(st, SHOULDER, lo, hi), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_get_joint_range(st, SHOULDER, out, out, &flags), POSE_ERR_UNSUPPORTED);
    pose_state_free(st);
    pose_rig_free(rig);
}

static void test_set_neutral(void **unused)
{
    (void)unused;
    pose_rig *rig = arm_rig(1);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    set_clinical(st, SHOULDER, 90, 20, 30, POSE_OK);
    set_clinical(st, ELBOW, 60, 0, 10, POSE_OK);
    const float bend[3] = {5, 5, 5}, t[3] = {1, 2, 3};
    pose_set_joint_euler(st, WRIST, bend, POSE_EULER_XYZ);
    pose_set_joint_euler(st, SPINE, bend, POSE_EULER_XYZ);
    pose_set_root(st, t, NULL);
    assert_int_equal(pose_set_neutral(st), POSE_OK);
    float deg[3], q[4];
    pose_get_joint_clinical(st, SHOULDER, deg);
    assert_angles(deg, 0, 0, 0, 0);
    pose_get_joint_clinical(st, ELBOW, deg);
    assert_angles(deg, 0, 0, 0, 0);
    const double identity[4] = {0, 0, 0, 1};
    pose_get_joint(st, WRIST, q);
    assert_true(dq_dist(identity, q) == 0.0);
    pose_get_joint(st, SPINE, q);
    assert_true(dq_dist(identity, q) == 0.0);
    assert_int_equal(pose_apply(st), POSE_OK);
    double sh[3];
    world_position(st, SHOULDER, sh); /* root back to identity */
    for (int i = 0; i < 3; i++)
        assert_near(sh[i], k_shoulder[i], 1e-6);
    assert_segment(st, SHOULDER, ELBOW, UPPER_ARM, 0, -1, 0);
    assert_segment(st, ELBOW, WRIST, FOREARM, 0, -1, 0);
    /* pose_reset goes back to the T-pose, and reads it as abduction 90. */
    assert_int_equal(pose_reset(st), POSE_OK);
    pose_apply(st);
    assert_segment(st, SHOULDER, ELBOW, UPPER_ARM, 1, 0, 0);
    pose_get_joint_clinical(st, SHOULDER, deg);
    assert_angles(deg, 0, 90, 0, 1e-3);
    pose_state_free(st);
    pose_rig_free(rig);
}

static void test_without_clinical_data(void **unused)
{
    (void)unused;
    pose_rig *rig = arm_rig(0);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    pose_joint_clinical c;
    const float deg[3] = {30, 0, 0};
    float q[4], out[3];
    assert_int_equal(pose_rig_joint_clinical(rig, SHOULDER, &c), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_clinical_to_local(rig, SHOULDER, deg, q), POSE_ERR_UNSUPPORTED);
    assert_message("shoulder_l");
    const float id[4] = {0, 0, 0, 1};
    assert_int_equal(pose_local_to_clinical(rig, SHOULDER, id, NULL, out), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_set_joint_clinical(st, SHOULDER, deg), POSE_ERR_UNSUPPORTED);
    assert_int_equal(pose_get_joint_clinical(st, SHOULDER, out), POSE_ERR_UNSUPPORTED);
    /* Rest-frame limits apply again. */
    assert_int_equal(pose_set_joint_euler(st, SHOULDER, deg, POSE_EULER_XYZ), POSE_CLAMPED);
    assert_message("x 30.00 clamped to 10.00");
    pose_state_free(st);
    pose_rig_free(rig);
}

static void test_invalid_arguments(void **unused)
{
    (void)unused;
    pose_rig *rig = arm_rig(1);
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    const float deg[3] = {10, 0, 0}, nan3[3] = {NAN, 0, 0}, id[4] = {0, 0, 0, 1};
    const float zero[4] = {0, 0, 0, 0};
    float q[4], out[3];
    assert_int_equal(pose_clinical_to_local(NULL, SHOULDER, deg, q), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_clinical_to_local(rig, JOINTS, deg, q), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_clinical_to_local(rig, SHOULDER, nan3, q), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_clinical_to_local(rig, SHOULDER, deg, NULL), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_local_to_clinical(rig, SHOULDER, zero, NULL, out), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_local_to_clinical(rig, SHOULDER, id, nan3, out), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_local_to_clinical(rig, -1, id, NULL, out), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint_clinical(NULL, SHOULDER, deg), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint_clinical(st, SHOULDER, nan3), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint_clinical(st, 9, deg), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_joint_clinical(st, WRIST, deg), POSE_ERR_UNSUPPORTED);
    assert_message("joint 3 'wrist_l' has no clinical data");
    assert_int_equal(pose_get_joint_clinical(st, SHOULDER, NULL), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_set_neutral(NULL), POSE_ERR_INVALID_ARGUMENT);
    pose_state_free(st);
    pose_rig_free(rig);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_arm_postures),
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_gimbal_lock),
        cmocka_unit_test(test_clamping),
        cmocka_unit_test(test_narrowed_range),
        cmocka_unit_test(test_widened_range),
        cmocka_unit_test(test_range_arguments),
        cmocka_unit_test(test_set_neutral),
        cmocka_unit_test(test_without_clinical_data),
        cmocka_unit_test(test_invalid_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
