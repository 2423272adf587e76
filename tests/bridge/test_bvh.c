/* SPDX-License-Identifier: Apache-2.0
 * BVH reader: invalid input first, then a small hand-written file with
 * several rotation orders whose FK was computed by hand. */
#include "bridge_test.h"
#include "mocap.h"
#include "pb_math.h"
#include "pb_text.h"
#include "pb_warn.h"

static const char *HIER =
    "HIERARCHY\n"
    "ROOT root\n"
    "{\n"
    "  OFFSET 1 2 3\n"
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    "  JOINT a\n"
    "  {\n"
    "    OFFSET 0 2 0\n"
    "    CHANNELS 3 Xrotation Yrotation Zrotation\n"
    "    JOINT b\n"
    "    {\n"
    "      OFFSET 0 0 3\n"
    "      CHANNELS 3 Yrotation Zrotation Xrotation\n"
    "      End Site\n"
    "      {\n"
    "        OFFSET 1 0 0\n"
    "      }\n"
    "    }\n"
    "  }\n"
    "  JOINT c\n"
    "  {\n"
    "    OFFSET 1 0 0\n"
    "    CHANNELS 1 Zrotation\n"
    "    End Site\n"
    "    {\n"
    "      OFFSET 2 0 0\n"
    "    }\n"
    "  }\n"
    "}\n";

static const char *MOTION =
    "MOTION\n"
    "Frames: 3\n"
    "Frame Time: 0.1\n"
    "0 0 0 0 0 0 0 0 0 0 0 0 0\n"
    "10 0 0 90 0 0 0 0 90 90 0 0 -90\n"
    "0 0 0 90 90 0 90 90 0 0 90 0 0\n";

static char *join(const char *a, const char *b)
{
    size_t n = strlen(a) + strlen(b) + 1;
    char *s = malloc(n);
    assert_non_null(s);
    snprintf(s, n, "%s%s", a, b);
    return s;
}

static pose_status parse_text(const char *text, pb_clip **clip, pb_error *err)
{
    return pb_bvh_parse(text, strlen(text), "hand.bvh", clip, err);
}

static void expect_error(const char *text, pose_status want, const char *fragment)
{
    pb_clip *clip = (pb_clip *)1;
    pb_error err = {{0}};
    pose_status s = parse_text(text, &clip, &err);
    assert_int_equal(s, want);
    assert_null(clip);
    if (!strstr(err.message, fragment))
        fail_msg("message '%s' lacks '%s'", err.message, fragment);
}

static void test_truncated_hierarchy(void **state)
{
    (void)state;
    char *t = strdup(HIER);
    t[strlen(t) / 2] = '\0'; /* cut inside joint b */
    expect_error(t, POSE_ERR_FORMAT, "hand.bvh:");
    expect_error(t, POSE_ERR_FORMAT, "found end of file");
    free(t);
    expect_error("", POSE_ERR_FORMAT, "expected HIERARCHY");
    expect_error("HIERARCHY\nROOT r\n{\nOFFSET 0 0\n}\n", POSE_ERR_FORMAT, "hand.bvh:5: expected an OFFSET coordinate, found '}'");
}

static void test_channel_count_mismatch(void **state)
{
    (void)state;
    char *t = join(HIER, "MOTION\nFrames: 2\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0 0 0 0 0\n0 0 0 0 0 0 0 0 0 0 0 0\n");
    expect_error(t, POSE_ERR_FORMAT, "hand.bvh:34: frame 1 has 12 values, expected 13");
    free(t);
    t = join(HIER, "MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0 0 0 0 0 7\n");
    expect_error(t, POSE_ERR_FORMAT, "frame 0 has more than 13 values");
    free(t);
    t = join(HIER, "MOTION\nFrames: 2\nFrame Time: 0.1\n0.0000 0.0000 0.0000 0.0000 0.0000 0.0000 0.0000 "
                   "0.0000 0.0000 0.0000 0.0000 0.0000 0.0000\n");
    expect_error(t, POSE_ERR_FORMAT, "hand.bvh:34: frame 1 has 0 values, expected 13 (one per channel); file ends early");
    free(t);
    expect_error("HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 7 Xrotation\n}\n", POSE_ERR_FORMAT,
                 "expected a channel count from 0 to 6, found '7'");
    expect_error("HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 1 Wrotation\n}\n", POSE_ERR_FORMAT,
                 "hand.bvh:5: expected a channel name");
}

static void test_non_finite_values(void **state)
{
    (void)state;
    char *t = join(HIER, "MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 nan 0 0 0 0 0 0 0 0\n");
    expect_error(t, POSE_ERR_FORMAT, "hand.bvh:33: frame 0 value 4: expected a finite number, found 'nan'");
    free(t);
    t = join(HIER, "MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0 0 0 0 -inf\n");
    expect_error(t, POSE_ERR_FORMAT, "expected a finite number, found '-inf'");
    free(t);
    expect_error("HIERARCHY\nROOT r\n{\nOFFSET 0 1e999 0\n}\n", POSE_ERR_FORMAT, "not finite");
    t = join(HIER, "MOTION\nFrames: 1\nFrame Time: 0\n");
    expect_error(t, POSE_ERR_FORMAT, "frame time 0 s is not in (0, 3600]");
    free(t);
}

static void test_absurd_frame_count(void **state)
{
    (void)state;
    char *t = join(HIER, "MOTION\nFrames: 999999999\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0 0 0 0 0\n");
    expect_error(t, POSE_ERR_FORMAT, "'Frames: 999999999' with 13 channels needs more data");
    free(t);
    t = join(HIER, "MOTION\nFrames: 99999999999999999999\nFrame Time: 0.1\n");
    expect_error(t, POSE_ERR_FORMAT, "expected a frame count");
    free(t);
    t = join(HIER, "MOTION\nFrames: -1\nFrame Time: 0.1\n");
    expect_error(t, POSE_ERR_FORMAT, "expected a frame count, found '-1'");
    free(t);
}

static void test_structure_errors(void **state)
{
    (void)state;
    expect_error("HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nEnd Site\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\n}\n",
                 POSE_ERR_FORMAT, "hand.bvh:8: expected '}' closing the End Site, found 'CHANNELS'");
    char *t = join(HIER, "ROOT other\n");
    expect_error(t, POSE_ERR_UNSUPPORTED, "more than one ROOT");
    free(t);
    t = join(HIER, "MOTION\nFrames: 0\nFrame Time: 0.1\nextra\n");
    expect_error(t, POSE_ERR_FORMAT, "data after the 0 frames");
    free(t);
    /* deep nesting is bounded, not a stack overflow */
    size_t cap = 400 * 40 + 64;
    char *deep = malloc(cap);
    size_t n = (size_t)snprintf(deep, cap, "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\n");
    for (int i = 0; i < 400; i++)
        n += (size_t)snprintf(deep + n, cap - n, "JOINT j%d\n{\nOFFSET 0 0 0\n", i);
    expect_error(deep, POSE_ERR_FORMAT, "hierarchy deeper than 256");
    free(deep);
}

static void test_missing_file(void **state)
{
    (void)state;
    pb_clip *clip = (pb_clip *)1;
    pb_error err;
    assert_int_equal(pb_bvh_load("/nonexistent/dir/x.bvh", &clip, &err), POSE_ERR_IO);
    assert_null(clip);
    assert_non_null(strstr(err.message, "/nonexistent/dir/x.bvh: cannot open"));
    assert_int_equal(pb_clip_load("/nonexistent.amc", NULL, &clip, &err), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err.message, "needs its ASF skeleton"));
    /* the CMU sibling skeleton is found by name */
    char amc[1024];
    if (pb_clip_load(BT_DATA(amc, "mocap/cmu-asf-amc/11_01.amc"), NULL, &clip, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_string_equal(clip->format, "asf-amc");
    assert_true(clip->frame_count > 0);
    pb_clip_free(clip);
}

static void fk(const pb_clip *c, size_t f, double (*wp)[3])
{
    double scratch[6 * 7], wq[6][4];
    pb_clip_fk(c, pb_clip_frame(c, f), scratch, wq, wp);
}

static void expect_pos(const double p[3], double x, double y, double z)
{
    assert_near(p[0], x, 1e-9);
    assert_near(p[1], y, 1e-9);
    assert_near(p[2], z, 1e-9);
}

static void check_hand_clip(const pb_clip *c)
{
    assert_int_equal(c->joint_count, 6);
    assert_int_equal(c->channel_count, 13);
    assert_int_equal(c->frame_count, 3);
    assert_near(c->frame_time, 0.1, 0);
    assert_string_equal(c->joints[3].name, "b_end");
    assert_int_equal(c->joints[3].parent, 2);
    assert_int_equal(c->joints[4].parent, 0);
    double wp[6][3];
    /* frame 0: offsets only */
    fk(c, 0, wp);
    expect_pos(wp[0], 1, 2, 3);
    expect_pos(wp[1], 1, 4, 3);
    expect_pos(wp[2], 1, 4, 6);
    expect_pos(wp[3], 2, 4, 6);
    expect_pos(wp[5], 4, 2, 3);
    /* frame 1 (by hand): root at (11,2,3) turned Rz90; a = Rz90 Rz90 = Rz180;
     * b = Rz180 Ry90: its end site (1,0,0) -> Ry90 (0,0,-1) -> (0,0,-1). */
    fk(c, 1, wp);
    expect_pos(wp[0], 11, 2, 3);
    expect_pos(wp[1], 9, 2, 3);
    expect_pos(wp[2], 9, 2, 6);
    expect_pos(wp[3], 9, 2, 5);
    expect_pos(wp[4], 11, 3, 3);
    expect_pos(wp[5], 13, 3, 3);
    /* frame 2: root ZXY (Rz90 Rx90), a XYZ (Rx90 Ry90), b YZX (Rz90); the
     * other compositions would put a at (-1,2,3)... and b elsewhere. */
    fk(c, 2, wp);
    expect_pos(wp[1], 1, 2, 5);
    expect_pos(wp[2], 1, 5, 5);
    expect_pos(wp[3], 2, 5, 5);
    expect_pos(wp[4], 1, 3, 3);
    expect_pos(wp[5], 1, 5, 3);
}

/* A skeleton without channels (CHANNELS 0 everywhere) has frames but no
 * values: the clip has no frame storage, and taking frame f must not do
 * pointer arithmetic on NULL (undefined; UBSan aborts on it). */
static void test_no_channels(void **state)
{
    (void)state;
    pb_clip *c = NULL;
    pb_error err = {{0}};
    const char *text = "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 0\nEnd Site\n{\nOFFSET 0 1 0\n}\n}\n"
                       "MOTION\nFrames: 2\nFrame Time: 0.1\n\n\n";
    assert_int_equal(parse_text(text, &c, &err), POSE_OK);
    assert_int_equal(c->channel_count, 0);
    assert_int_equal(c->frame_count, 2);
    double scratch[2 * 7], wq[2][4], wp[2][3];
    pb_clip_fk(c, pb_clip_frame(c, 1), scratch, wq, wp);
    expect_pos(wp[1], 0, 1, 0);
    pb_clip_free(c);
}

/* Values no joint or capture volume can have (1e30 in a BVH, 1e300 in an
 * AMC) are kept but warned about, naming the line, the first value and the
 * count; so is a frame time beyond a minute (a replay would stall that
 * long per frame); a radians value too large for degrees is refused (it was
 * inf). */
static void test_absurd_values_warned(void **state)
{
    (void)state;
    pb_warnings w;
    memset(&w, 0, sizeof w);
    pb_warnings *prev = pb_warnings_install(&w);
    char *t = join(HIER, "MOTION\nFrames: 2\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0 0 0 0 0\n0 0 0 1e30 0 0 0 0 0 0 0 0 -2e7\n");
    pb_clip *c = NULL;
    pb_error err = {{0}};
    assert_int_equal(parse_text(t, &c, &err), POSE_OK);
    free(t);
    pb_clip_free(c);
    t = join(HIER, "MOTION\nFrames: 1\nFrame Time: 3600\n0 0 0 0 0 0 0 0 0 0 0 0 0\n");
    assert_int_equal(parse_text(t, &c, &err), POSE_OK);
    free(t);
    pb_clip_free(c);
    assert_int_equal(w.count, 2);
    if (!strstr(w.text[1], "hand.bvh:32: frame time 3600 s: a real-time replay waits that long"))
        fail_msg("%s", w.text[1]);
    if (!strstr(w.text[0], "hand.bvh:34: frame 1 value 3 is 1e+30, beyond +-1e+06") ||
        !strstr(w.text[0], "2 such values"))
        fail_msg("%s", w.text[0]);

    static const char asf[] = ":version 1.10\n:name t\n:units\n  angle deg\n:root\n  order TX TY TZ RX RY RZ\n"
                              "  axis XYZ\n  position 0 0 0\n  orientation 0 0 0\n:bonedata\n  begin\n    id 1\n"
                              "    name a\n    direction 0 1 0\n    length 1\n    axis 0 0 0 XYZ\n    dof rx\n"
                              "  end\n:hierarchy\n  begin\n    root a\n  end\n";
    assert_int_equal(pb_asf_parse(asf, strlen(asf), "t.asf", &c, &err), POSE_OK);
    static const char amc[] = ":DEGREES\n1\nroot 0 0 0 0 0 0\na 5\n2\nroot 0 0 0 0 0 0\na 1e300\n";
    if (pb_amc_parse(c, amc, strlen(amc), "t.amc", &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(w.count, 3);
    if (!strstr(w.text[2], "t.amc:7: bone a value 1e+300 is beyond +-1e+06"))
        fail_msg("%s", w.text[2]);
    static const char rad[] = ":RADIANS\n1\nroot 0 0 0 0 0 0\na 1e307\n";
    assert_int_equal(pb_amc_parse(c, rad, strlen(rad), "r.amc", &err), POSE_ERR_FORMAT);
    if (!strstr(err.message, "r.amc:4: bone a: value 0 is not finite in degrees"))
        fail_msg("%s", err.message);
    pb_clip_free(c);
    pb_warnings_install(prev);
}

static void test_hand_computed_fk(void **state)
{
    (void)state;
    char *t = join(HIER, MOTION);
    pb_clip *c;
    pb_error err;
    assert_int_equal(parse_text(t, &c, &err), POSE_OK);
    check_hand_clip(c);
    pb_clip_free(c);
    free(t);
}

static void test_crlf_and_trailing_blanks(void **state)
{
    (void)state;
    char *t = join(HIER, MOTION);
    size_t n = strlen(t);
    char *w = malloc(n * 4 + 1);
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        if (t[i] == '\n') {
            w[k++] = ' ';
            w[k++] = '\t';
            w[k++] = '\r';
        }
        w[k++] = t[i] == ' ' ? '\t' : t[i];
    }
    w[k] = '\0';
    pb_clip *c;
    pb_error err;
    if (parse_text(w, &c, &err) != POSE_OK)
        fail_msg("%s", err.message);
    check_hand_clip(c);
    pb_clip_free(c);
    free(w);
    free(t);
}

static void test_euler_round_trip(void **state)
{
    (void)state;
    const double angles[4][3] = {{10, 20, 30}, {-70, 45, 120}, {179, -30, 5}, {0, 0, -90}};
    for (int o = 0; o < 6; o++)
        for (int a = 0; a < 4; a++) {
            double q[4], back[4], d[3];
            pb_quat_from_euler(angles[a], (pose_euler_order)o, q);
            pb_quat_to_euler(q, (pose_euler_order)o, d);
            pb_quat_from_euler(d, (pose_euler_order)o, back);
            assert_near(fabs(pb_quat_dot(q, back)), 1.0, 1e-12);
        }
}

/* the reader's fast decimal path must round exactly like strtod */
static void test_number_parsing_matches_strtod(void **state)
{
    (void)state;
    unsigned x = 12345;
    char buf[64];
    for (int i = 0; i < 200000; i++) {
        x = x * 1103515245u + 12345u;
        int digits = 1 + (int)(x % 15), point = (int)((x >> 8) % (unsigned)(digits + 1));
        size_t n = 0;
        if (x & 0x10000)
            buf[n++] = '-';
        for (int d = 0; d < digits; d++) {
            if (d == point && d > 0)
                buf[n++] = '.';
            x = x * 1103515245u + 12345u;
            buf[n++] = (char)('0' + (x >> 16) % 10);
        }
        buf[n] = '\0';
        pb_token tk = {buf, n, 1};
        double v;
        assert_int_equal(pb_token_double(tk, &v), 0);
        if (v != strtod(buf, NULL))
            fail_msg("'%s' parsed as %.17g, strtod gives %.17g", buf, v, strtod(buf, NULL));
    }
    const char *bad[] = {".", "-", "1.2.3", "1e", "0x", "--1", "1,5"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        pb_token tk = {bad[i], strlen(bad[i]), 1};
        double v;
        assert_int_equal(pb_token_double(tk, &v), -1);
    }
    const char *odd[] = {"1e3", "-2.5E-2", "0x10", "+7", "1."};
    const double want[] = {1000, -0.025, 16, 7, 1};
    for (size_t i = 0; i < sizeof odd / sizeof odd[0]; i++) {
        pb_token tk = {odd[i], strlen(odd[i]), 1};
        double v;
        assert_int_equal(pb_token_double(tk, &v), 0);
        assert_near(v, want[i], 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_truncated_hierarchy),
        cmocka_unit_test(test_channel_count_mismatch),
        cmocka_unit_test(test_non_finite_values),
        cmocka_unit_test(test_absurd_frame_count),
        cmocka_unit_test(test_structure_errors),
        cmocka_unit_test(test_no_channels),
        cmocka_unit_test(test_absurd_values_warned),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_hand_computed_fk),
        cmocka_unit_test(test_crlf_and_trailing_blanks),
        cmocka_unit_test(test_euler_round_trip),
        cmocka_unit_test(test_number_parsing_matches_strtod),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
