/* SPDX-License-Identifier: Apache-2.0
 * Simulated HID devices: recordings replayed through the live decoder give
 * the generator's angles back; faults (garbage, wrong IDs, short reports,
 * silence, unplug and return) move the source through its states while the
 * last good values hold. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "hid_hidraw.h"
#include "hid_mannequin.h"
#include "hid_open.h"
#include "pb_warn.h"

static void data_path(char *buf, size_t n, const char *file)
{
    const char *dir = getenv("POSE_DATA_DIR");
    assert_non_null(dir);
    snprintf(buf, n, "%s/hid/%s", dir, file);
}

static pb_source *open_replay(const char *file, const pb_hid_replay_options *opt)
{
    char path[1024];
    data_path(path, sizeof path, file);
    pb_source *src = NULL;
    pb_error err;
    if (pb_hid_open(path, opt, &src, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return src;
}

static void test_invalid(void **state)
{
    (void)state;
    pb_source *src = (pb_source *)1;
    pb_error err;
    assert_int_equal(pb_hid_open("", NULL, &src, &err), POSE_ERR_INVALID_ARGUMENT);
    assert_null(src);
    assert_int_equal(pb_hid_open("/nonexistent.hid", NULL, &src, &err), POSE_ERR_IO);
    assert_int_equal(pb_hid_open("hid:12345:1", NULL, &src, &err), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pb_hid_open("hid:1209", NULL, &src, &err), POSE_ERR_INVALID_ARGUMENT);
    /* No such live device here: enumeration finds nothing (or hidapi is not built in). */
    pose_status st = pb_hid_open("hid:ffff:fffe", NULL, &src, &err);
    assert_true(st == POSE_ERR_NOT_FOUND || st == POSE_ERR_UNSUPPORTED);
    assert_null(src);
    st = pb_hid_open("/dev/hidraw999", NULL, &src, &err);
    assert_true(st == POSE_ERR_NOT_FOUND || st == POSE_ERR_UNSUPPORTED);
    uint8_t desc[64];
    size_t len = 1;
    assert_int_equal(pb_hid_hidraw_descriptor("/dev/hidraw999", desc, sizeof desc, &len, &err), POSE_ERR_IO);
    assert_int_equal(len, 0);
    assert_non_null(strstr(err.message, "/dev/hidraw999"));
    char path[1024];
    data_path(path, sizeof path, "mannequin_arm_raise.hid");
    pb_hid_replay_options opt = {.device = 3};
    assert_int_equal(pb_hid_open(path, &opt, &src, &err), POSE_ERR_NOT_FOUND);
    assert_non_null(strstr(err.message, "no device 3"));
    /* A recording whose descriptor is broken fails with the parser's message. */
    pb_hid_recording *rec;
    const char text[] = "R: 2 a1 01\nE: 0.0 1 00\n";
    assert_int_equal(pb_hid_recording_parse(text, sizeof text - 1, "broken.hid", &rec, &err), POSE_OK);
    assert_int_equal(pb_hid_replay_create(rec, "broken.hid", NULL, &src, &err), POSE_ERR_FORMAT);
    assert_non_null(strstr(err.message, "broken.hid: report descriptor"));
    assert_null(src);
}

/* Every report of the recording decodes to the generator's angles, in order. */
static void test_decode_matches_generator(void **state)
{
    (void)state;
    const struct {
        const char *file;
        pb_mannequin_motion motion;
        double rate;
    } cases[] = {
        {"mannequin_sit_to_stand.hid", PB_MOTION_SIT_TO_STAND, 500},
        {"mannequin_arm_raise.hid", PB_MOTION_ARM_RAISE, 250},
        {"mannequin_reach_1khz.hid", PB_MOTION_REACH, 1000},
    };
    for (size_t k = 0; k < 3; k++) {
        pb_hid_replay_options opt = {.as_fast_as_possible = 1};
        pb_source *src = open_replay(cases[k].file, &opt);
        assert_int_equal(src->channel_count, 18);
        assert_int_equal(src->state, PB_SOURCE_WAITING);
        long n = 0;
        int64_t last_t = -1;
        double worst = 0;
        pb_update u;
        int r;
        while ((r = pb_source_read(src, &u, 100)) == 1) {
            assert_int_equal(u.count, 18);
            assert_true(u.t_ns > last_t);
            last_t = u.t_ns;
            assert_int_equal((long)u.values[17], n & 0xFFFF); /* counter: none dropped or reordered */
            double deg[16];
            int hold;
            pb_mannequin_pose(cases[k].motion, (double)n / cases[k].rate, deg, &hold);
            for (int i = 0; i < 16; i++) {
                double g, o;
                pb_mannequin_sensor(i, &g, &o);
                assert_int_equal(u.channels[i], i);
                double recovered = (u.values[i] - o) / g; /* ideal two-point calibration */
                double e = fabs(recovered - deg[i]);
                worst = e > worst ? e : worst;
            }
            assert_int_equal((int)u.values[16], hold);
            n++;
        }
        assert_int_equal(r, -1);
        assert_int_equal(src->state, PB_SOURCE_ENDED);
        assert_int_equal(n, (long)(pb_mannequin_motion_seconds(cases[k].motion) * cases[k].rate));
        /* Sensor noise is 0.12 deg RMS plus 0.05 deg quantisation: 6 sigma. */
        assert_true(worst < 0.8);
        assert_true(worst > 0.05); /* the noise is really there */
        pb_hid_source_stats st = pb_hid_source_get_stats(src);
        assert_int_equal(st.reports, (uint64_t)n);
        assert_int_equal(st.bad_reports + st.unknown_ids + st.disconnects, 0);
        pb_source_destroy(src);
    }
}

typedef struct transitions {
    pb_source_state states[64];
    char messages[64][128];
    int count;
} transitions;

static void on_status(pb_source *src, pb_source_state state, const char *message, void *user)
{
    (void)src;
    transitions *t = user;
    if (t->count < 64) {
        t->states[t->count] = state;
        snprintf(t->messages[t->count], sizeof t->messages[0], "%s", message);
        t->count++;
    }
}

static int find_state(const transitions *t, int from, pb_source_state s, const char *text)
{
    for (int i = from; i < t->count; i++)
        if (t->states[i] == s && (!text || strstr(t->messages[i], text)))
            return i;
    return -1;
}

static void test_faults(void **state)
{
    (void)state;
    /* 250 Hz played 4x faster: one report per millisecond. */
    const pb_hid_fault faults[] = {
        {100, PB_HID_FAULT_GARBAGE, 0},   {150, PB_HID_FAULT_WRONG_ID, 0}, {200, PB_HID_FAULT_SHORT, 0},
        {300, PB_HID_FAULT_SILENCE, 250}, {400, PB_HID_FAULT_DISCONNECT, 150},
    };
    pb_hid_replay_options opt = {
        .source = {.stale_ms = 80, .reopen_ms = 20},
        .speed = 4.0,
        .faults = faults,
        .fault_count = sizeof faults / sizeof faults[0],
    };
    pb_source *src = open_replay("mannequin_arm_raise.hid", &opt);
    transitions tr = {0};
    src->on_status = on_status;
    src->on_status_user = &tr;
    double held[18];
    int checked_hold = 0;
    long good = 0;
    for (int iter = 0; iter < 5000 && good < 600; iter++) {
        pb_update u;
        int r = pb_source_read(src, &u, 10);
        assert_true(r >= 0);
        const double *v = pb_hid_source_values(src);
        if (r == 1) {
            good++;
            memcpy(held, v, sizeof held);
        } else if (good > 0 && src->state != PB_SOURCE_OK) {
            /* Nothing new: the last good values stay, untouched by bad reports. */
            assert_memory_equal(v, held, sizeof held);
            checked_hold++;
        }
    }
    assert_true(good >= 600);
    assert_true(checked_hold > 0);
    int i = find_state(&tr, 0, PB_SOURCE_OK, NULL);
    assert_true(i >= 0);
    int garbage = find_state(&tr, i, PB_SOURCE_FAULT, NULL);
    assert_true(garbage > i);
    int wrong = find_state(&tr, garbage, PB_SOURCE_FAULT, "report ID 238");
    assert_true(wrong > garbage);
    assert_int_equal(tr.states[wrong - 1], PB_SOURCE_OK); /* recovered in between */
    int shrt = find_state(&tr, wrong, PB_SOURCE_FAULT, "shorter");
    assert_true(shrt > wrong);
    int stale = find_state(&tr, shrt, PB_SOURCE_STALE, "no report for 80 ms");
    assert_true(stale > shrt);
    int back = find_state(&tr, stale, PB_SOURCE_OK, NULL);
    assert_true(back > stale);
    int gone = find_state(&tr, back, PB_SOURCE_DISCONNECTED, "disconnected");
    assert_true(gone > back);
    int reopened = find_state(&tr, gone, PB_SOURCE_WAITING, "reopened");
    assert_true(reopened > gone);
    /* While unplugged, reopen attempts fail with the enumeration's message. */
    assert_true(find_state(&tr, gone, PB_SOURCE_DISCONNECTED, "not present") > gone);
    assert_true(find_state(&tr, reopened, PB_SOURCE_OK, NULL) > reopened);
    pb_hid_source_stats st = pb_hid_source_get_stats(src);
    assert_int_equal(st.disconnects, 1);
    assert_int_equal(st.reopens, 1);
    assert_true(st.unknown_ids >= 1);
    assert_true(st.bad_reports >= 1);
    assert_int_equal(st.bad_reports + st.unknown_ids, 3);
    assert_int_equal(src->state, PB_SOURCE_OK);
    pb_source_destroy(src);
}

/* A device that keeps sending reports with an undeclared ID is faulty, not
 * silent: one FAULT callback, no STALE, no value ever delivered. */
static void test_bad_stream_is_fault_not_stale(void **state)
{
    (void)state;
    pb_hid_recording *rec;
    pb_error err;
    assert_int_equal(pb_mannequin_recording(PB_MOTION_REACH, 1000, 0.3, 9, &rec, &err), POSE_OK);
    for (size_t i = 0; i < rec->event_count; i++)
        rec->data[rec->events[i].offset] = 0x07;
    pb_hid_replay_options opt = {.source = {.stale_ms = 40}};
    pb_source *src;
    assert_int_equal(pb_hid_replay_create(rec, "bad-ids", &opt, &src, &err), POSE_OK);
    transitions tr = {0};
    src->on_status = on_status;
    src->on_status_user = &tr;
    pb_update u;
    int r;
    while ((r = pb_source_read(src, &u, 20)) == 0) {
    }
    assert_int_equal(r, -1);
    assert_int_equal(tr.count, 2);
    assert_int_equal(tr.states[0], PB_SOURCE_FAULT);
    assert_non_null(strstr(tr.messages[0], "report ID 7 is not in the descriptor"));
    assert_int_equal(tr.states[1], PB_SOURCE_ENDED);
    assert_int_equal(pb_hid_source_get_stats(src).unknown_ids, 300);
    assert_true(isnan(pb_hid_source_values(src)[0])); /* never a good value */
    pb_source_destroy(src);
}

/* Started before the device is plugged in: channels from the expected
 * descriptor, DISCONNECTED until it appears; a device with another
 * descriptor is refused. */
static void test_expected_descriptor(void **state)
{
    (void)state;
    pb_hid_replay_options opt = {
        .source = {.reopen_ms = 20,
                   .expected_desc = pb_mannequin_descriptor,
                   .expected_desc_len = pb_mannequin_descriptor_len},
        .as_fast_as_possible = 1,
        .absent_ms = 100,
    };
    pb_source *src = open_replay("mannequin_reach_1khz.hid", &opt);
    assert_int_equal(src->state, PB_SOURCE_DISCONNECTED);
    assert_non_null(strstr(src->message, "not present"));
    assert_int_equal(src->channel_count, 18);
    assert_string_equal(src->channels[12].name, "Ordinal.13");
    pb_update u;
    assert_int_equal(pb_source_read(src, &u, 0), 0); /* still absent */
    int got = 0;
    for (int i = 0; i < 100 && !got; i++)
        got = pb_source_read(src, &u, 20) == 1;
    assert_true(got);
    assert_int_equal(src->state, PB_SOURCE_OK);
    assert_int_equal((long)u.values[17], 0); /* as fast as possible: nothing skipped */
    assert_int_equal(pb_hid_source_get_stats(src).reopens, 1);
    pb_source_destroy(src);

    /* The same device where a mouse was expected. */
    static const uint8_t mouse[] = {0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x09, 0x30, 0x15, 0x81, 0x25, 0x7F,
                                    0x75, 0x08, 0x95, 0x01, 0x81, 0x06, 0xC0};
    opt.source.expected_desc = mouse;
    opt.source.expected_desc_len = sizeof mouse;
    src = open_replay("mannequin_reach_1khz.hid", &opt);
    assert_int_equal(src->channel_count, 1);
    for (int i = 0; i < 20; i++)
        assert_int_equal(pb_source_read(src, &u, 20), 0);
    assert_int_equal(src->state, PB_SOURCE_FAULT);
    assert_non_null(strstr(src->message, "different report descriptor"));
    pb_source_destroy(src);

    /* Without an expected descriptor, an absent device is an error at once. */
    opt.source.expected_desc = NULL;
    opt.source.expected_desc_len = 0;
    char path[1024];
    data_path(path, sizeof path, "mannequin_reach_1khz.hid");
    pb_error err;
    assert_int_equal(pb_hid_open(path, &opt, &src, &err), POSE_ERR_NOT_FOUND);
    assert_null(src);
    assert_non_null(strstr(err.message, "not present"));
}

/* The mannequin's hold button freezes the angles: updates carry only the
 * button and the counter while it is pressed (3.2 to 3.8 s of the arm raise). */
static void test_hold_pose(void **state)
{
    (void)state;
    pb_hid_replay_options opt = {.as_fast_as_possible = 1, .source = {.hold_channel = "Button.1"}};
    pb_source *src = open_replay("mannequin_arm_raise.hid", &opt);
    pb_update u;
    int held = 0, free_running = 0;
    while (pb_source_read(src, &u, 100) == 1) {
        if (u.count == 2) {
            assert_int_equal(u.channels[0], 16);
            assert_true(u.values[0] == 1.0);
            assert_int_equal(u.channels[1], 17);
            long n = (long)u.values[1];
            assert_true(n >= 800 && n < 950); /* 3.2 s .. 3.8 s at 250 Hz */
            held++;
        } else {
            assert_int_equal(u.count, 18);
            free_running++;
        }
    }
    assert_int_equal(held, 150);
    assert_int_equal(free_running, 2500 - 150);
    pb_source_destroy(src);
    char path[1024];
    data_path(path, sizeof path, "mannequin_arm_raise.hid");
    opt.source.hold_channel = "Button.9";
    pb_error err;
    assert_int_equal(pb_hid_open(path, &opt, &src, &err), POSE_ERR_NOT_FOUND);
    assert_non_null(strstr(err.message, "Button.9"));
}

static void test_seek_and_loop(void **state)
{
    (void)state;
    pb_hid_replay_options opt = {.as_fast_as_possible = 1, .loop = 1};
    pb_source *src = open_replay("mannequin_reach_1khz.hid", &opt);
    pb_update u;
    int64_t last = -1;
    /* Two and a half passes: times keep increasing across the loop. */
    for (int i = 0; i < 10000; i++) {
        assert_int_equal(pb_source_read(src, &u, 100), 1);
        assert_true(u.t_ns > last);
        last = u.t_ns;
    }
    assert_true(last > 9990000000LL && last < 10010000000LL);
    /* Report 2500 was stamped within 40 us of 2.5 s (USB jitter). */
    assert_int_equal(pb_source_seek(src, 2499500000LL), 0);
    assert_int_equal(pb_source_read(src, &u, 100), 1);
    assert_true(u.t_ns >= 2499500000LL && u.t_ns < 2500500000LL);
    assert_int_equal((long)u.values[17], 2500);
    pb_source_destroy(src);
}

/* A report longer than its descriptor declares is decoded (devices pad) but
 * no longer in silence: one warning names the device and both lengths. */
static void test_long_report_warned(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/long_report.hid", getenv("POSE_TEST_TMP"));
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("R: 52 05 01 09 02 a1 01 09 01 a1 00 05 09 19 01 29 03 15 00 25 01 95 03 75 01 81 02 95 01 75 05 81 "
          "01 05 01 09 30 09 31 09 38 15 81 25 7f 75 08 95 03 81 06 c0 c0\n"
          "E: 000000.000100 4 05 fe 02 01\n"
          "E: 000000.000200 6 05 fe 02 01 00 00\n"
          "E: 000000.000300 6 05 fe 02 01 00 00\n",
          f);
    fclose(f);
    pb_warnings w;
    memset(&w, 0, sizeof w);
    pb_warnings *prev = pb_warnings_install(&w);
    pb_hid_replay_options opt = {.as_fast_as_possible = 1};
    pb_source *src = NULL;
    pb_error err;
    if (pb_hid_replay_open(path, &opt, &src, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_update u;
    for (int i = 0; i < 3; i++)
        assert_int_equal(pb_source_read(src, &u, 100), 1);
    pb_warnings_install(prev);
    assert_int_equal(src->state, PB_SOURCE_OK);
    assert_int_equal(w.count, 1);
    if (!strstr(w.text[0], "long_report.hid: report of 6 bytes, its descriptor declares 4"))
        fail_msg("%s", w.text[0]);
    pb_source_destroy(src);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_invalid),
        cmocka_unit_test(test_decode_matches_generator),
        cmocka_unit_test(test_faults),
        cmocka_unit_test(test_bad_stream_is_fault_not_stale),
        cmocka_unit_test(test_expected_descriptor),
        cmocka_unit_test(test_hold_pose),
        cmocka_unit_test(test_seek_and_loop),
        cmocka_unit_test(test_long_report_warned),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
