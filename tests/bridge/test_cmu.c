/* SPDX-License-Identifier: Apache-2.0
 * The shared CMU clips: the cgspeed BVH and the Acclaim ASF/AMC of take
 * 01_01 must give the same joint positions (same length unit: both are the
 * database's unit, x 0.056444 for metres), BVH frame k+1 against AMC frame k
 * (the BVH's frame 0 is a synthetic T-pose). Plus ASF/AMC invalid input. */
#include "bridge_test.h"
#include "mocap.h"
#include "pb_math.h"

/* cgspeed BVH joint -> ASF bone (the BVH's own names for the same bones) */
static const char *PAIRS[][2] = {
    {"Hips", "root"},           {"LHipJoint", "lhipjoint"},   {"LeftUpLeg", "lfemur"},
    {"LeftLeg", "ltibia"},      {"LeftFoot", "lfoot"},        {"LeftToeBase", "ltoes"},
    {"LeftToeBase_end", "ltoes_end"}, {"RHipJoint", "rhipjoint"}, {"RightUpLeg", "rfemur"},
    {"RightLeg", "rtibia"},     {"RightFoot", "rfoot"},       {"RightToeBase", "rtoes"},
    {"LowerBack", "lowerback"}, {"Spine", "upperback"},       {"Spine1", "thorax"},
    {"Neck", "lowerneck"},      {"Neck1", "upperneck"},       {"Head", "head"},
    {"Head_end", "head_end"},   {"LeftShoulder", "lclavicle"}, {"LeftArm", "lhumerus"},
    {"LeftForeArm", "lradius"}, {"LeftHand", "lwrist"},       {"LeftFingerBase", "lhand"},
    {"LFingers", "lfingers"},   {"LFingers_end", "lfingers_end"}, {"LThumb", "lthumb"},
    {"RightShoulder", "rclavicle"}, {"RightArm", "rhumerus"}, {"RightForeArm", "rradius"},
    {"RightHand", "rwrist"},    {"RightFingerBase", "rhand"}, {"RFingers", "rfingers"},
    {"RThumb", "rthumb"},       {"RThumb_end", "rthumb_end"},
};
#define NPAIRS (sizeof PAIRS / sizeof PAIRS[0])

static pb_clip *load_amc(const char *asf, const char *amc)
{
    char a[1024], m[1024];
    pb_clip *c;
    pb_error err;
    if (pb_clip_load(BT_DATA(m, amc), BT_DATA(a, asf), &c, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return c;
}

static void test_bvh_matches_asf_amc(void **state)
{
    (void)state;
    char p[1024];
    pb_clip *bvh, *amc = load_amc("mocap/cmu-asf-amc/01.asf", "mocap/cmu-asf-amc/01_01.amc");
    pb_error err;
    if (pb_bvh_load(BT_DATA(p, "mocap/cmu-bvh/01_01.bvh"), &bvh, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(bvh->frame_count, amc->frame_count + 1);
    assert_near(bvh->frame_time, 1.0 / 120.0, 1e-6);
    int bj[NPAIRS], aj[NPAIRS];
    for (size_t i = 0; i < NPAIRS; i++) {
        bj[i] = pb_clip_find_joint(bvh, PAIRS[i][0]);
        aj[i] = pb_clip_find_joint(amc, PAIRS[i][1]);
        if (bj[i] < 0 || aj[i] < 0)
            fail_msg("joint pair %s / %s not found", PAIRS[i][0], PAIRS[i][1]);
    }
    size_t nb = (size_t)bvh->joint_count, na = (size_t)amc->joint_count;
    double *sb = malloc(nb * 14 * sizeof(double)), *sa = malloc(na * 14 * sizeof(double));
    double (*bq)[4] = (double (*)[4])(sb + 7 * nb), (*bp)[3] = (double (*)[3])(sb + 11 * nb);
    double (*aq)[4] = (double (*)[4])(sa + 7 * na), (*ap)[3] = (double (*)[3])(sa + 11 * na);
    /* Tolerance from the files' rounding: BVH values have 4 decimals (angle
     * error <= 5e-5 deg), AMC values 6 significant digits (<= 5e-4 deg for
     * angles up to 180). Each of a joint's three angles then turns the points
     * below it by <= ang rad; a joint's world rotation is off by at most
     * 3 * ang per rotating ancestor, a point at distance d below a joint moves
     * by <= d * 3 * ang. Positions: + 2 * 5e-5 * sqrt(3) for the root's.
     *
     * cgspeed's conversion collapses two bones to zero length: the thorax
     * (Neck and both shoulders sit at Spine1) and the wrist (FingerBase and
     * Thumb sit at Hand). So absolute positions are compared only up the
     * legs and the spine to Spine1; everywhere else the world rotations and
     * the segment vectors (BVH joint minus its parent, for non-zero BVH
     * offsets, against the same ASF bone) are compared. */
    const double ang = (5e-5 + 5e-4) * PB_DEG2RAD;
    double worst_p = 0.0, worst_v = 0.0, worst_r = 0.0, worst_ratio = 0.0;
    size_t checks = 0;
    for (size_t f = 0; f < amc->frame_count; f++) {
        pb_clip_fk(bvh, pb_clip_frame(bvh, f + 1), sb, bq, bp);
        pb_clip_fk(amc, pb_clip_frame(amc, f), sa, aq, ap);
        for (size_t i = 0; i < NPAIRS; i++) {
            int b = bj[i], a = aj[i], depth = 0;
            for (int k = amc->joints[a].parent; k >= 0; k = amc->joints[k].parent)
                depth++;
            /* world rotations (end sites carry their parent's) */
            double d = fabs(pb_quat_dot(bq[b], aq[a]));
            double rot = 2.0 * acos(d > 1.0 ? 1.0 : d), rtol = (depth + 1) * 3 * ang + 1e-7;
            if (rot > rtol)
                fail_msg("frame %zu %s: world rotations differ by %g rad (tolerance %g)", f, PAIRS[i][0], rot, rtol);
            worst_r = rot > worst_r ? rot : worst_r;
            checks++;
            const double *x = bp[b], *y = ap[a];
            double e, tol;
            if (i < 15) { /* Hips .. Spine1: same absolute positions */
                double v[3] = {x[0] - y[0], x[1] - y[1], x[2] - y[2]};
                e = pb_vec_len(v);
                tol = 2 * 5e-5 * sqrt(3.0);
                for (int k = amc->joints[a].parent; k >= 0; k = amc->joints[k].parent) {
                    double dd[3] = {y[0] - ap[k][0], y[1] - ap[k][1], y[2] - ap[k][2]};
                    tol += 3 * ang * pb_vec_len(dd);
                }
                worst_p = e > worst_p ? e : worst_p;
            } else {
                int pb = bvh->joints[b].parent;
                if (pb_vec_len(bvh->joints[b].offset) < 1e-9)
                    continue;
                /* the ASF bone of that BVH offset ends at joint a and starts at its parent's start */
                int pa = amc->joints[a].parent;
                double vb[3] = {x[0] - bp[pb][0], x[1] - bp[pb][1], x[2] - bp[pb][2]};
                double va[3] = {y[0] - ap[pa][0], y[1] - ap[pa][1], y[2] - ap[pa][2]};
                double v[3] = {vb[0] - va[0], vb[1] - va[1], vb[2] - va[2]};
                e = pb_vec_len(v);
                tol = 1e-5 + pb_vec_len(va) * (depth + 1) * 3 * ang;
                worst_v = e > worst_v ? e : worst_v;
            }
            if (e > tol)
                fail_msg("frame %zu joint %s: BVH and AMC differ by %g (tolerance %g)", f, PAIRS[i][0], e, tol);
            if (e / tol > worst_ratio)
                worst_ratio = e / tol;
            checks++;
        }
    }
    print_message("01_01: %zu frames, %zu checks; worst position %.3g units (%.3g mm), segment %.3g units, "
                  "rotation %.3g deg; worst %.0f%% of its bound\n",
                  amc->frame_count, checks, worst_p, worst_p * 56.444, worst_v, worst_r * PB_RAD2DEG,
                  100 * worst_ratio);
    free(sb);
    free(sa);
    pb_clip_free(bvh);
    pb_clip_free(amc);
}

static void test_asf_fields(void **state)
{
    (void)state;
    pb_clip *c = load_amc("mocap/cmu-asf-amc/11.asf", "mocap/cmu-asf-amc/11_01.amc");
    assert_string_equal(c->format, "asf-amc");
    assert_near(c->length_unit, 0.45, 0);
    int f = pb_clip_find_joint(c, "lfemur");
    assert_true(f > 0);
    const pb_clip_joint *J = &c->joints[f];
    assert_int_equal(J->chan_count, 3);
    assert_int_equal(J->chan[0], PB_CH_XROT);
    assert_int_equal(J->chan[2], PB_CH_ZROT);
    assert_true(J->has_limits);
    assert_near(J->limit_min[0], -160.0, 0);
    assert_near(J->limit_max[2], 70.0, 0);
    /* axis 0 0 20 XYZ: C = Rz(20) */
    assert_near(J->axis_q[2], sin(10 * PB_DEG2RAD), 1e-12);
    assert_near(J->axis_q[3], cos(10 * PB_DEG2RAD), 1e-12);
    /* root channels follow :root order TX TY TZ RX RY RZ */
    assert_int_equal(c->joints[0].chan_count, 6);
    assert_int_equal(c->joints[0].chan[3], PB_CH_XROT);
    assert_true(c->frame_count > 100);
    pb_clip_free(c);
}

static const char *ASF_OK =
    ":units\n  length 1\n  angle rad\n:root\n  order TX TY TZ RZ RY RX\n  axis XYZ\n  position 0 0 0\n"
    "  orientation 0 0 0\n:bonedata\n  begin\n    id 1\n    name up\n    direction 0 1 0\n    length 2\n"
    "    axis 0 0 0 XYZ\n    dof rx rz\n    limits (-1.0 1.0)\n      (-inf inf)\n  end\n"
    ":hierarchy\n  begin\n    root up\n  end\n";

static void expect_asf_error(const char *text, const char *fragment)
{
    pb_clip *c = (pb_clip *)1;
    pb_error err;
    assert_int_equal(pb_asf_parse(text, strlen(text), "t.asf", &c, &err), POSE_ERR_FORMAT);
    assert_null(c);
    if (!strstr(err.message, fragment))
        fail_msg("message '%s' lacks '%s'", err.message, fragment);
}

static void expect_amc_error(pb_clip *skel, const char *text, const char *fragment)
{
    pb_error err;
    assert_int_equal(pb_amc_parse(skel, text, strlen(text), "t.amc", &err), POSE_ERR_FORMAT);
    if (!strstr(err.message, fragment))
        fail_msg("message '%s' lacks '%s'", err.message, fragment);
}

static void test_asf_amc_invalid(void **state)
{
    (void)state;
    expect_asf_error(":root\n  order TX TY TZ RX RY RZ\n:bonedata\n", "missing section :hierarchy");
    expect_asf_error(":root\n:bonedata\n begin\n name a\n direction 0 1 0\n length 1\n end\n:hierarchy\n begin\n"
                     " root b\n end\n",
                     "t.asf:10: expected a bone defined in :bonedata (child), found 'b'");
    expect_asf_error(":root\n:bonedata\n begin\n name a\n direction 0 1 0\n end\n", "bone block lacks a length");
    expect_asf_error(":root\n:bonedata\n begin\n name a\n direction 0 nan 0\n", "t.asf:5: a direction component is not finite");
    expect_asf_error(":root\n:bonedata\n begin\n name a\n direction 0 1 0\n length 1\n dof rx\n limits -1 1\n end\n",
                     "t.asf:8: expected '(' opening limit 1 of 1 for bone a");
    expect_asf_error(":root\n:bonedata\n begin\n name a\n direction 0 1 0\n length 1\n end\n:hierarchy\n begin\n"
                     " root\n end\n",
                     "bone a is not attached in :hierarchy");

    pb_clip *c;
    pb_error err;
    if (pb_asf_parse(ASF_OK, strlen(ASF_OK), "t.asf", &c, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(c->channel_count, 8);
    assert_near(c->joints[1].limit_min[0], -PB_RAD2DEG, 1e-9); /* radians converted */
    assert_true(isinf(c->joints[1].limit_max[1]));
    expect_amc_error(c, "1\nroot 0 0 0 0 0 0\n", "last frame 1 lacks bone up");
    expect_amc_error(c, "1\nroot 0 0 0 0 0 0\nup 1\n", "bone up: expected 2 values, found fewer");
    expect_amc_error(c, "1\nroot 0 0 0 0 0 0\nup 1 2 3\n", "t.amc:3: bone up: more than 2 values");
    expect_amc_error(c, "1\nroot 0 0 0 0 0 0\nup 1 inf\n", "expected 2 finite values");
    expect_amc_error(c, "1\nroot 0 0 0 0 0 0\nup 1 2\nknee 1\n", "t.amc:4: expected a bone of the skeleton, found 'knee'");
    expect_amc_error(c, "1\nroot 0 0 0 0 0 0\nup 1 2\n3\n", "expected frame number 2, found 3");
    expect_amc_error(c, "root 0 0 0 0 0 0\n", "expected a frame number before 'root'");
    expect_amc_error(c, ":DEGREES\n", "no frames");
    /* a good one: :RADIANS converts, frame 2 counts */
    const char *amc = ":FULLY-SPECIFIED\n:RADIANS\n1\nroot 1 2 3 0 0 0\nup 0.5 0\n2\nup 0 0\nroot 0 0 0 0 0 1\n";
    if (pb_amc_parse(c, amc, strlen(amc), "t.amc", &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(c->frame_count, 2);
    assert_near(pb_clip_frame(c, 0)[6], 0.5 * PB_RAD2DEG, 1e-9);
    assert_near(pb_clip_frame(c, 1)[5], PB_RAD2DEG, 1e-9);
    /* up (dir 0 1 0, length 2): its end site sits 2 above root; rx 0.5 rad turns it about x */
    double s[3 * 7], wq[3][4], wp[3][3];
    pb_clip_fk(c, pb_clip_frame(c, 0), s, wq, wp);
    assert_near(wp[2][0], 1.0, 1e-12);
    assert_near(wp[2][1], 2.0 + 2.0 * cos(0.5), 1e-12);
    assert_near(wp[2][2], 3.0 + 2.0 * sin(0.5), 1e-12);
    pb_clip_free(c);
    assert_int_equal(pb_asf_load("/nonexistent.asf", &c, &err), POSE_ERR_IO);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_asf_amc_invalid),
        cmocka_unit_test(test_asf_fields),
        cmocka_unit_test(test_bvh_matches_asf_amc),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
