/* SPDX-License-Identifier: Apache-2.0
 * hid-recorder files: malformed input first (errors name file and line),
 * both timestamp styles, wrapped descriptors, either hex case, several
 * devices, writer round trip, and the bundled mannequin recordings. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "hid_mannequin.h"
#include "hid_recorder.h"
#include "pb_warn.h"

static void bad_n(const char *text, size_t len, const char *what)
{
    pb_hid_recording *rec = (pb_hid_recording *)1;
    pb_error err = {{0}};
    pose_status st = pb_hid_recording_parse(text, len, "bad.hid", &rec, &err);
    if (st != POSE_ERR_FORMAT)
        fail_msg("accepted (%d) input that should fail with '%s'", st, what);
    assert_null(rec);
    if (!strstr(err.message, what))
        fail_msg("message '%s' lacks '%s'", err.message, what);
}

static void bad(const char *text, const char *what)
{
    bad_n(text, strlen(text), what);
}

static void test_invalid(void **state)
{
    (void)state;
    bad("", "no device");
    bad("# only a comment\n", "no device");
    bad("E: 0.000000 1 00\n", "before the device's R:");
    bad("R: 2 05 01\nE: 0.000000 2 00 zz\n", "bad.hid:2: E: bytes must be two-digit hex");
    bad("R: 2 05 01\nE: 0.000000 3 00 01\n", "fewer bytes");
    bad("R: 2 05 01\nE: 0.000000 1 00 01\n", "more bytes");
    bad("R: 2 05 01\nE: 1 1 00\n", "seconds.fraction");
    bad("R: 2 05 01\nE: 1.0000000000 1 00\n", "1 to 9 digits");
    bad("R: 2 05 01\nE: 0.000000\n", "report length");
    bad("R: 2 05 01\nE: 0.000000 99999 00\n", "report length");
    bad("D: 1\nR: 2 05 01\n", "in order");
    bad("D: 64\n", "above 63");
    bad("R: 2 05 01\nX: what\n", "bad.hid:2: unknown line type");
    bad("R: 2 05 01\nhello\n", "expected a line");
    bad("R: 4 05 01\nN: x\n", "descriptor shorter");
    bad("R: 4 05 01\n", "descriptor ends early");
    bad("R: 2 05 01 09\n", "more bytes than its length");
    bad("R: 2 05 01\nR: 2 05 01\n", "second R: line");
    bad("R: 0\n", "descriptor length");
    bad("R: 2 5 01\n", "two-digit hex");
    bad("R: 2 05 01\nI: 3 046d\n", "I: needs");
    bad("R: 2 05 01\nI: 3 046d c077 1\n", "more than three");
    bad("D: 0\nR: 2 05 01\nD: 1\nN: nothing\n", "device 1 has no R:");
    static const char nul[] = "R: 2 05 01\nE: 0.0 1 0\0\n";
    bad_n(nul, sizeof nul - 1, "bad.hid:2: NUL");
}

/* Older hid-recorder style: unpadded timestamps, upper-case hex, a wrapped
 * descriptor, CRLF line ends, blank lines and comments. */
static const char old_style[] = "# an old recording\r\n"
                                "R: 6 05 01 09\r\n"
                                "   02 A1\r\n"
                                "01\r\n"
                                "\r\n"
                                "N: Old Mouse\r\n"
                                "P: usb-0000:00:1d.0-1/input0\r\n"
                                "I: 3 046D C077\r\n"
                                "E: 0.000000 4 00 FF 01 00\r\n"
                                "E: 12.5 2 Ab cD\r\n";

static void test_old_style(void **state)
{
    (void)state;
    pb_hid_recording *rec;
    pb_error err;
    assert_int_equal(pb_hid_recording_parse(old_style, strlen(old_style), "old.hid", &rec, &err), POSE_OK);
    assert_int_equal(rec->device_count, 1);
    const pb_hid_rec_device *d = &rec->devices[0];
    const uint8_t desc[] = {0x05, 0x01, 0x09, 0x02, 0xA1, 0x01};
    assert_int_equal(d->desc_len, 6);
    assert_memory_equal(d->desc, desc, 6);
    assert_string_equal(d->name, "Old Mouse");
    assert_string_equal(d->phys, "usb-0000:00:1d.0-1/input0");
    assert_int_equal(d->bus, 3);
    assert_int_equal(d->vendor, 0x046D);
    assert_int_equal(d->product, 0xC077);
    assert_int_equal(rec->event_count, 2);
    assert_int_equal(rec->events[1].t_ns, 12500000000LL);
    assert_int_equal(rec->events[1].len, 2);
    assert_int_equal(rec->events[1].line, 10);
    assert_int_equal(rec->data[rec->events[1].offset], 0xAB);
    assert_int_equal(rec->data[rec->events[1].offset + 1], 0xCD);
    pb_hid_recording_free(rec);
}

/* Current hid-tools style with two devices and events switching between them. */
static const char two_devices[] = "D: 0\n"
                                  "R: 2 05 01\n"
                                  "N: first\n"
                                  "I: 3 0001 0002\n"
                                  "D: 1\n"
                                  "R: 3 05 09 c0\n"
                                  "N: second\n"
                                  "I: 5 0003 0004\n"
                                  "D: 0\n"
                                  "E: 000000.000100 1 01\n"
                                  "D: 1\n"
                                  "E: 000000.000200 2 02 03\n"
                                  "E: 000000.000300 0\n"
                                  "D: 0\n"
                                  "E: 000001.000000 1 04\n";

static void test_two_devices(void **state)
{
    (void)state;
    pb_hid_recording *rec;
    pb_error err;
    assert_int_equal(pb_hid_recording_parse(two_devices, strlen(two_devices), "two.hid", &rec, &err), POSE_OK);
    assert_int_equal(rec->device_count, 2);
    assert_string_equal(rec->devices[1].name, "second");
    assert_int_equal(rec->devices[1].bus, 5);
    assert_int_equal(rec->devices[1].desc_len, 3);
    assert_int_equal(rec->devices[0].event_count, 2);
    assert_int_equal(rec->devices[1].event_count, 2);
    const uint32_t dev[] = {0, 1, 1, 0};
    const int64_t t[] = {100000, 200000, 300000, 1000000000};
    for (int i = 0; i < 4; i++) {
        assert_int_equal(rec->events[i].device, dev[i]);
        assert_int_equal(rec->events[i].t_ns, t[i]);
    }
    assert_int_equal(rec->events[2].len, 0);
    pb_hid_recording_free(rec);
}

/* An empty first report (found by fuzzing: the data pool must exist even then). */
static void test_empty_report(void **state)
{
    (void)state;
    const char text[] = "R: 2 05 01\nE: 0.0 0\nE: 0.5 1 7f\n";
    pb_hid_recording *rec;
    pb_error err;
    assert_int_equal(pb_hid_recording_parse(text, sizeof text - 1, "empty.hid", &rec, &err), POSE_OK);
    assert_int_equal(rec->event_count, 2);
    assert_non_null(rec->data);
    assert_int_equal(rec->events[0].len, 0);
    assert_int_equal(rec->data[rec->events[1].offset], 0x7F);
    pb_hid_recording_free(rec);
}

static char *read_text(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)len + 1);
    assert_non_null(buf);
    assert_int_equal(fread(buf, 1, (size_t)len, f), (size_t)len);
    fclose(f);
    buf[len] = '\0';
    *n = (size_t)len;
    return buf;
}

static void test_write_round_trip(void **state)
{
    (void)state;
    pb_hid_recording *a, *b;
    pb_error err;
    assert_int_equal(pb_hid_recording_parse(two_devices, strlen(two_devices), "two.hid", &a, &err), POSE_OK);
    char path[512];
    snprintf(path, sizeof path, "%s/round_trip.hid", getenv("POSE_TEST_TMP") ? getenv("POSE_TEST_TMP") : "/tmp");
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    for (size_t i = 0; i < a->device_count; i++)
        assert_int_equal(pb_hid_recorder_write_device(f, (int)i, &a->devices[i]), 0);
    uint32_t current = UINT32_MAX;
    for (size_t i = 0; i < a->event_count; i++) {
        const pb_hid_rec_event *e = &a->events[i];
        if (e->device != current)
            fprintf(f, "D: %u\n", current = e->device);
        assert_int_equal(pb_hid_recorder_write_event(f, e->t_ns, a->data + e->offset, e->len), 0);
    }
    fclose(f);
    size_t n;
    char *text = read_text(path, &n);
    assert_non_null(strstr(text, "E: 000001.000000 1 04\n"));
    free(text);
    assert_int_equal(pb_hid_recording_load(path, &b, &err), POSE_OK);
    assert_int_equal(b->device_count, a->device_count);
    assert_int_equal(b->event_count, a->event_count);
    for (size_t i = 0; i < a->device_count; i++) {
        assert_string_equal(b->devices[i].name, a->devices[i].name);
        assert_int_equal(b->devices[i].vendor, a->devices[i].vendor);
        assert_int_equal(b->devices[i].desc_len, a->devices[i].desc_len);
        assert_memory_equal(b->devices[i].desc, a->devices[i].desc, a->devices[i].desc_len);
    }
    for (size_t i = 0; i < a->event_count; i++) {
        assert_int_equal(b->events[i].t_ns, a->events[i].t_ns);
        assert_int_equal(b->events[i].device, a->events[i].device);
        assert_int_equal(b->events[i].len, a->events[i].len);
        assert_memory_equal(b->data + b->events[i].offset, a->data + a->events[i].offset, a->events[i].len);
    }
    pb_hid_recording_free(a);
    pb_hid_recording_free(b);
    assert_int_equal(pb_hid_recording_load("/nonexistent/x.hid", &b, &err), POSE_ERR_IO);
    assert_non_null(strstr(err.message, "/nonexistent/x.hid"));
}

static void test_bundled_recordings(void **state)
{
    (void)state;
    const char *dir = getenv("POSE_DATA_DIR");
    assert_non_null(dir);
    const struct {
        const char *file;
        size_t events;
        double rate;
    } files[] = {
        {"mannequin_sit_to_stand.hid", 4000, 500},
        {"mannequin_arm_raise.hid", 2500, 250},
        {"mannequin_reach_1khz.hid", 4000, 1000},
    };
    for (size_t k = 0; k < 3; k++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/hid/%s", dir, files[k].file);
        pb_hid_recording *rec;
        pb_error err;
        if (pb_hid_recording_load(path, &rec, &err) != POSE_OK)
            fail_msg("%s", err.message);
        assert_int_equal(rec->device_count, 1);
        assert_int_equal(rec->devices[0].desc_len, pb_mannequin_descriptor_len);
        assert_memory_equal(rec->devices[0].desc, pb_mannequin_descriptor, pb_mannequin_descriptor_len);
        assert_int_equal(rec->devices[0].vendor, PB_MANNEQUIN_VENDOR);
        assert_int_equal(rec->event_count, files[k].events);
        double period_ns = 1e9 / files[k].rate;
        for (size_t i = 0; i < rec->event_count; i++) {
            const pb_hid_rec_event *e = &rec->events[i];
            assert_int_equal(e->len, PB_MANNEQUIN_REPORT_BYTES);
            const uint8_t *r = rec->data + e->offset;
            assert_int_equal(r[0], PB_MANNEQUIN_REPORT_ID);
            assert_int_equal(r[26] | r[27] << 8, i & 0xFFFF); /* counter: nothing dropped or reordered */
            double drift = (double)e->t_ns - (double)i * period_ns;
            assert_true(drift > -0.05 * period_ns && drift < 0.05 * period_ns); /* USB jitter only */
        }
        pb_hid_recording_free(rec);
    }
}

/* Time stamps that jump an hour ahead (a real-time replay stalled on it) or
 * go backwards (it was accepted without a word) are taken out with a
 * warning naming the line: the replay goes on one step after the report
 * before. A last E: line cut by a killed recorder is a warning, not an error
 * that loses the whole file. */
static void test_time_jumps_and_cut_line(void **state)
{
    (void)state;
    static const char text[] = "R: 2 05 01\n"
                               "E: 1.000000 1 00\n"
                               "E: 1.010000 1 01\n"
                               "E: 3601.010000 1 02\n" /* an hour ahead */
                               "E: 3601.020000 1 03\n"
                               "E: 3600.000000 1 04\n" /* back by 1.02 s */
                               "E: 3600.010000 1 05\n"
                               "E: 3600.020000 2 06"; /* cut: 2 bytes announced, no newline */
    pb_warnings w;
    memset(&w, 0, sizeof w);
    pb_warnings *prev = pb_warnings_install(&w);
    pb_hid_recording *rec = NULL;
    pb_error err = {{0}};
    const pose_status st = pb_hid_recording_parse(text, sizeof text - 1, "jumps.hid", &rec, &err);
    pb_warnings_install(prev);
    if (st != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(rec->event_count, 6);
    const double want[6] = {1.0, 1.01, 1.02, 1.03, 1.04, 1.05};
    for (int i = 0; i < 6; i++)
        if (llabs(rec->events[i].t_ns - (int64_t)(want[i] * 1e9 + 0.5)) > 1000)
            fail_msg("event %d at %lld ns, want %.3f s", i, (long long)rec->events[i].t_ns, want[i]);
    assert_int_equal(w.count, 3);
    if (!strstr(w.text[0], "jumps.hid:4: E: time stamp jumps ahead 3600.000 s"))
        fail_msg("%s", w.text[0]);
    if (!strstr(w.text[1], "jumps.hid:6: E: time stamp goes back 1.020 s"))
        fail_msg("%s", w.text[1]);
    if (!strstr(w.text[2], "jumps.hid:8: E: has fewer bytes than its length says; the last line is cut"))
        fail_msg("%s", w.text[2]);
    pb_hid_recording_free(rec);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_invalid),
        cmocka_unit_test(test_old_style),
        cmocka_unit_test(test_two_devices),
        cmocka_unit_test(test_empty_report),
        cmocka_unit_test(test_write_round_trip),
        cmocka_unit_test(test_bundled_recordings),
        cmocka_unit_test(test_time_jumps_and_cut_line),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
