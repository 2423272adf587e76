/* SPDX-License-Identifier: Apache-2.0
 * Report-descriptor parser and report decoder: hand-built descriptors that
 * cover every item kind, invalid ones first, then the mannequin's. */
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
#include "hid_report.h"
#include "pb_warn.h"

#define PARSE_ERR(bytes, text) parse_err(bytes, sizeof bytes, text)

static void parse_err(const uint8_t *b, size_t n, const char *text)
{
    pb_hid_desc *d = (pb_hid_desc *)1;
    pb_error err = {{0}};
    if (pb_hid_desc_parse(b, n, "t.bin", &d, &err) != POSE_ERR_FORMAT)
        fail_msg("expected a format error mentioning '%s'", text);
    assert_null(d);
    if (!strstr(err.message, text))
        fail_msg("message '%s' lacks '%s'", err.message, text);
    assert_non_null(strstr(err.message, "t.bin: report descriptor byte"));
}

static pb_hid_desc *parse_ok(const uint8_t *b, size_t n)
{
    pb_hid_desc *d = NULL;
    pb_error err = {{0}};
    if (pb_hid_desc_parse(b, n, "t.bin", &d, &err) != POSE_OK)
        fail_msg("parse failed: %s", err.message);
    return d;
}

static void test_invalid(void **state)
{
    (void)state;
    pb_hid_desc *d = (pb_hid_desc *)1;
    pb_error err;
    assert_int_equal(pb_hid_desc_parse((const uint8_t *)"", 0, NULL, &d, &err), POSE_ERR_FORMAT);
    assert_null(d);
    static const uint8_t truncated[] = {0x05, 0x01, 0x26, 0xFF};
    PARSE_ERR(truncated, "needs 2 data bytes");
    static const uint8_t truncated_at[] = {0x05, 0x01, 0x27, 0xFF};
    parse_err(truncated_at, sizeof truncated_at, "byte 2:");
    /* Long items: the kernel's fetch_item reads them, hid_open_report refuses them. */
    static const uint8_t long_item[] = {0xFE, 0x02, 0x10, 0xAA, 0xBB};
    PARSE_ERR(long_item, "long item (prefix 0xfe): the Linux kernel refuses long items");
    static const uint8_t long_short[] = {0x05, 0x01, 0xFE, 0x05};
    PARSE_ERR(long_short, "byte 2: long item");
    static const uint8_t long_f0[] = {0xF0};
    PARSE_ERR(long_f0, "long item (prefix 0xf0)");
    /* Reserved global tags: hid_parser_global fails ("unknown global tag"). */
    static const uint8_t global_reserved[] = {0x05, 0x01, 0xC4, 0x01};
    PARSE_ERR(global_reserved, "byte 2: reserved global item tag 0xc");
    /* Report Count above HID_MAX_USAGES (12288). */
    static const uint8_t count_big[] = {0x96, 0x01, 0x30};
    PARSE_ERR(count_big, "report count 12289 too large");
    /* hid_add_field: logical maximum below the minimum, even for padding. */
    static const uint8_t range_bad[] = {0x15, 0x05, 0x25, 0x01, 0x75, 0x08, 0x95, 0x01, 0x81, 0x03};
    PARSE_ERR(range_bad, "byte 8: logical maximum 1 below logical minimum 5");
    static const uint8_t range_bad_signed[] = {0x15, 0xFE, 0x25, 0xFD, 0x75, 0x08, 0x95, 0x01, 0x81, 0x02};
    PARSE_ERR(range_bad_signed, "logical maximum -3 below logical minimum -2");
    static const uint8_t end_without[] = {0xC0};
    PARSE_ERR(end_without, "End Collection without");
    static const uint8_t unclosed[] = {0x05, 0x01, 0x09, 0x02, 0xA1, 0x01};
    PARSE_ERR(unclosed, "not closed");
    static const uint8_t pop[] = {0xB4};
    PARSE_ERR(pop, "Pop without");
    static const uint8_t id0[] = {0x85, 0x00};
    PARSE_ERR(id0, "report ID 0");
    static const uint8_t usage_max[] = {0x29, 0x05};
    PARSE_ERR(usage_max, "Usage Maximum without");
    static const uint8_t backwards[] = {0x19, 0x05, 0x29, 0x01};
    PARSE_ERR(backwards, "below Usage Minimum");
    static const uint8_t too_big[] = {0x75, 0x08, 0x96, 0x00, 0x10, 0x81, 0x02, 0x81, 0x02};
    PARSE_ERR(too_big, "grows beyond");
    static const uint8_t late_id[] = {0x75, 0x08, 0x95, 0x01, 0x81, 0x02, 0x85, 0x01};
    PARSE_ERR(late_id, "after fields without");
    static const uint8_t size_big[] = {0x76, 0x01, 0x01};
    PARSE_ERR(size_big, "report size");
    static const uint8_t delim[] = {0xA9, 0x00};
    PARSE_ERR(delim, "delimiter close");
    static const uint8_t delim_open[] = {0xA9, 0x01};
    PARSE_ERR(delim_open, "delimiter not closed");
    uint8_t pushes[2 * PB_HID_MAX_DEPTH + 2];
    for (size_t i = 0; i < sizeof pushes; i++)
        pushes[i] = 0xA4;
    PARSE_ERR(pushes, "Push deeper");
}

/* The HID 1.11 appendix boot mouse, with a wheel. */
static const uint8_t mouse[] = {
    0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x09, 0x01, 0xA1, 0x00, 0x05, 0x09, 0x19, 0x01, 0x29, 0x03,
    0x15, 0x00, 0x25, 0x01, 0x95, 0x03, 0x75, 0x01, 0x81, 0x02, 0x95, 0x01, 0x75, 0x05, 0x81, 0x01,
    0x05, 0x01, 0x09, 0x30, 0x09, 0x31, 0x09, 0x38, 0x15, 0x81, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x03,
    0x81, 0x06, 0xC0, 0xC0,
};

static void test_mouse(void **state)
{
    (void)state;
    pb_hid_desc *d = parse_ok(mouse, sizeof mouse);
    assert_false(d->uses_report_ids);
    assert_int_equal(d->field_count, 7); /* 3 buttons, padding, X, Y, wheel */
    assert_int_equal(d->channel_count, 6);
    assert_int_equal(d->input_bytes[0], 4);
    assert_int_equal(pb_hid_desc_input_length(d, 0), 4);
    assert_int_equal(pb_hid_desc_input_length(d, 1), 0);
    const char *names[] = {"Button.1", "Button.2", "Button.3", "GenericDesktop.X", "GenericDesktop.Y",
                           "GenericDesktop.Wheel"};
    const uint32_t bits[] = {0, 1, 2, 8, 16, 24};
    for (int c = 0; c < 6; c++) {
        assert_string_equal(d->channels[c].name, names[c]);
        assert_int_equal(d->fields[d->channel_field[c]].bit_offset, bits[c]);
    }
    const pb_hid_field *x = &d->fields[d->channel_field[3]];
    assert_true(x->is_signed);
    assert_int_equal(x->logical_min, -127);
    assert_int_equal(x->logical_max, 127);
    assert_true(x->flags & PB_HID_RELATIVE);
    assert_int_equal(x->usage, 0x00010030);
    assert_false(pb_hid_field_has_physical(x));
    assert_int_equal(d->fields[3].flags & PB_HID_CONSTANT, PB_HID_CONSTANT);
    assert_int_equal(d->fields[3].bit_size, 5);
    /* Collections: Application(Mouse) > Physical(Pointer). */
    assert_int_equal(d->collection_count, 2);
    assert_int_equal(d->collections[0].usage, 0x00010002);
    assert_int_equal(d->collections[0].type, 1);
    assert_int_equal(d->collections[1].parent, 0);
    assert_int_equal(x->collection, 1);

    int32_t lg[6];
    double v[6];
    uint8_t ok[6];
    uint32_t first, count;
    const uint8_t rep[] = {0x05, 0xFF, 0x01, 0x80};
    assert_int_equal(pb_hid_report_decode(d, rep, sizeof rep, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(first, 0);
    assert_int_equal(count, 6);
    assert_int_equal(lg[0], 1);
    assert_int_equal(lg[1], 0);
    assert_int_equal(lg[2], 1);
    assert_int_equal(lg[3], -1);
    assert_int_equal(lg[4], 1);
    assert_int_equal(lg[5], -128);
    assert_true(v[3] == -1.0);
    assert_int_equal(pb_hid_report_decode(d, rep, 3, lg, v, ok, &first, &count), PB_HID_DECODE_SHORT);
    assert_int_equal(pb_hid_report_decode(d, rep, 0, lg, v, ok, &first, &count), PB_HID_DECODE_EMPTY);
    pb_hid_desc_free(d);
}

static void test_sign_and_sizes(void **state)
{
    (void)state;
    static const uint8_t b[] = {
        0x05, 0x01,                         /* Generic Desktop */
        0x15, 0x00, 0x25, 0xFF,             /* 0..255: max unsigned since min >= 0 */
        0x75, 0x08, 0x95, 0x01, 0x09, 0x30, 0x81, 0x02,
        0x16, 0x01, 0x80, 0x26, 0xFF, 0x7F, /* -32767..32767 */
        0x75, 0x10, 0x09, 0x31, 0x81, 0x02,
        0x17, 0x00, 0x00, 0x00, 0x80,       /* INT32_MIN.. */
        0x27, 0xFF, 0xFF, 0xFF, 0x7F,       /* ..INT32_MAX */
        0x75, 0x20, 0x09, 0x32, 0x81, 0x02,
        0x15, 0xF8, 0x25, 0x07,             /* -8..7 in 4 bits */
        0x75, 0x04, 0x95, 0x02, 0x09, 0x33, 0x81, 0x02,
    };
    pb_hid_desc *d = parse_ok(b, sizeof b);
    assert_int_equal(d->channel_count, 5);
    const pb_hid_field *f0 = &d->fields[d->channel_field[0]];
    assert_false(f0->is_signed);
    assert_int_equal(f0->logical_max, 255);
    const pb_hid_field *f1 = &d->fields[d->channel_field[1]];
    assert_int_equal(f1->logical_min, -32767);
    assert_int_equal(f1->logical_max, 32767);
    const pb_hid_field *f2 = &d->fields[d->channel_field[2]];
    assert_int_equal(f2->logical_min, INT32_MIN);
    assert_int_equal(f2->logical_max, INT32_MAX);
    assert_int_equal(f2->bit_offset, 24);
    /* Report count 2 with one usage: the last usage repeats. */
    assert_string_equal(d->channels[3].name, "GenericDesktop.Rx");
    assert_string_equal(d->channels[4].name, "GenericDesktop.Rx#1");
    assert_int_equal(d->input_bytes[0], 8);
    const uint8_t rep[] = {0xFE, 0x01, 0x80, 0xFF, 0xFF, 0xFF, 0xFF, 0x8F};
    int32_t lg[5];
    double v[5];
    uint8_t ok[5];
    uint32_t first, count;
    assert_int_equal(pb_hid_report_decode(d, rep, sizeof rep, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(lg[0], 254);
    assert_int_equal(lg[1], -32767);
    assert_int_equal(lg[2], -1);
    assert_int_equal(lg[3], -1); /* 0xF */
    assert_int_equal(lg[4], -8); /* 0x8 */
    pb_hid_desc_free(d);
}

static void test_report_ids_and_extended_usages(void **state)
{
    (void)state;
    static const uint8_t b[] = {
        0x05, 0x09,                   /* Button page: the extended usages below ignore it */
        0x85, 0x01, 0x0B, 0x30, 0x00, 0x01, 0x00, 0x0B, 0x31, 0x00, 0x01, 0x00, /* GD.X, GD.Y */
        0x15, 0x00, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x02, 0x81, 0x02,
        0x85, 0x02, 0x09, 0x05, 0x75, 0x08, 0x95, 0x01, 0x81, 0x02, /* Button 5 */
        0x85, 0x03, 0x09, 0x06, 0x91, 0x02,                         /* output only */
        0x85, 0x01, 0x09, 0x07, 0x81, 0x02,                         /* report 1 continues */
        0x0C,                                                       /* reserved type: skipped */
    };
    pb_hid_desc *d = parse_ok(b, sizeof b);
    assert_true(d->uses_report_ids);
    assert_int_equal(pb_hid_desc_input_length(d, 1), 4);
    assert_int_equal(pb_hid_desc_input_length(d, 2), 2);
    assert_int_equal(pb_hid_desc_input_length(d, 3), 0);
    assert_int_equal(d->output_bytes[3], 1);
    assert_int_equal(d->report_count[1], 3);
    assert_int_equal(d->report_count[2], 1);
    assert_string_equal(d->channels[d->report_first[1]].name, "GenericDesktop.X");
    assert_string_equal(d->channels[d->report_first[1] + 1].name, "GenericDesktop.Y");
    assert_string_equal(d->channels[d->report_first[1] + 2].name, "Button.7");
    assert_int_equal(d->fields[d->channel_field[d->report_first[1] + 2]].bit_offset, 16);
    assert_string_equal(d->channels[d->report_first[2]].name, "Button.5");
    int32_t lg[4];
    double v[4];
    uint8_t ok[4];
    uint32_t first, count;
    const uint8_t r2[] = {0x02, 0x2A};
    assert_int_equal(pb_hid_report_decode(d, r2, 2, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(first, d->report_first[2]);
    assert_int_equal(count, 1);
    assert_int_equal(lg[first], 42);
    const uint8_t r1[] = {0x01, 0x05, 0x06, 0x07};
    assert_int_equal(pb_hid_report_decode(d, r1, 4, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(lg[first + 2], 7);
    const uint8_t r3[] = {0x03, 0x00};
    assert_int_equal(pb_hid_report_decode(d, r3, 2, lg, v, ok, &first, &count), PB_HID_DECODE_UNKNOWN_ID);
    assert_int_equal(pb_hid_report_decode(d, r1, 3, lg, v, ok, &first, &count), PB_HID_DECODE_SHORT);
    pb_hid_desc_free(d);
}

static void test_arrays(void **state)
{
    (void)state;
    /* Keyboard-style array: six slots selecting usages 0..0x65. */
    static const uint8_t b[] = {
        0x05, 0x07, 0x19, 0x00, 0x29, 0x65, 0x15, 0x00, 0x25, 0x65,
        0x75, 0x08, 0x95, 0x06, 0x81, 0x00,
        /* An array over two usage lists: Button 1..2 then Button 9. */
        0x05, 0x09, 0x19, 0x01, 0x29, 0x02, 0x09, 0x09, 0x15, 0x01, 0x25, 0x03,
        0x75, 0x08, 0x95, 0x01, 0x81, 0x00,
    };
    pb_hid_desc *d = parse_ok(b, sizeof b);
    assert_int_equal(d->channel_count, 7);
    assert_string_equal(d->channels[0].name, "Keyboard.array");
    assert_string_equal(d->channels[5].name, "Keyboard.array#5");
    assert_string_equal(d->channels[6].name, "Button.array");
    const pb_hid_field *f = &d->fields[d->channel_field[1]];
    assert_false(f->flags & PB_HID_VARIABLE);
    assert_int_equal(f->array_index, 1);
    assert_int_equal(f->usage, 0x00070000);
    assert_int_equal(f->usage_last, 0x00070065);
    int32_t lg[7];
    double v[7];
    uint8_t ok[7];
    uint32_t first, count;
    const uint8_t rep[] = {0x04, 0x29, 0x00, 0x00, 0x00, 0x7F, 0x03};
    assert_int_equal(pb_hid_report_decode(d, rep, sizeof rep, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_true(v[0] == 4.0);    /* 'a' */
    assert_true(v[1] == 0x29);   /* Escape */
    assert_true(v[2] == 0.0);    /* no key */
    assert_true(v[5] == 0.0);    /* 0x7F is out of the logical range: nothing */
    assert_true(v[6] == 9.0);    /* index 2 of [1..2, 9] */
    pb_hid_desc_free(d);
}

static void test_units_push_pop(void **state)
{
    (void)state;
    static const uint8_t b[] = {
        0x05, 0x01, 0x15, 0x00, 0x26, 0xFF, 0x0F, 0x75, 0x10, 0x95, 0x01,
        /* degrees, 0..4095 -> 0..360.00 (exponent -2 as a nibble) */
        0x35, 0x00, 0x47, 0xA0, 0x8C, 0x00, 0x00, 0x65, 0x14, 0x55, 0x0E, 0xA4,
        0x09, 0x30, 0x81, 0x02,
        /* radians via SI rotation, exponent -2 as a signed byte, inside a Push */
        0x66, 0x12, 0x00, 0x55, 0xFE, 0x36, 0x00, 0x00, 0x46, 0x3B, 0x01, 0x09, 0x31, 0x81, 0x02,
        0xB4, /* Pop: back to degrees 0..360 */
        0x09, 0x32, 0x81, 0x02,
        /* centimetres, seconds, an exotic unit, no unit */
        0x65, 0x11, 0x55, 0x00, 0x35, 0x00, 0x46, 0xFF, 0x0F, 0x09, 0x33, 0x81, 0x02,
        0x66, 0x01, 0x10, 0x09, 0x34, 0x81, 0x02,
        0x67, 0x11, 0xE1, 0x00, 0x00, 0x09, 0x35, 0x81, 0x02,
        0x65, 0x00, 0x35, 0x00, 0x45, 0x00, 0x09, 0x36, 0x81, 0x02,
    };
    pb_hid_desc *d = parse_ok(b, sizeof b);
    assert_int_equal(d->channel_count, 7);
    const pb_hid_field *deg = &d->fields[d->channel_field[0]];
    assert_string_equal(deg->unit_name, "deg");
    assert_int_equal(deg->unit_exponent, -2);
    assert_int_equal(deg->physical_max, 36000);
    assert_float_equal(4095 * deg->scale + deg->offset, 360.0, 1e-9);
    assert_string_equal(d->channels[0].unit, "deg");
    assert_float_equal(d->channels[0].max, 360.0, 1e-9);
    const pb_hid_field *rad = &d->fields[d->channel_field[1]];
    assert_string_equal(rad->unit_name, "rad");
    assert_int_equal(rad->unit_exponent, -2);
    assert_float_equal(4095 * rad->scale + rad->offset, 3.15, 1e-9);
    const pb_hid_field *popped = &d->fields[d->channel_field[2]];
    assert_string_equal(popped->unit_name, "deg");
    assert_float_equal(popped->scale, deg->scale, 1e-12);
    assert_string_equal(d->fields[d->channel_field[3]].unit_name, "cm");
    assert_float_equal(d->fields[d->channel_field[3]].scale, 1.0, 1e-12);
    assert_string_equal(d->fields[d->channel_field[4]].unit_name, "s");
    assert_string_equal(d->fields[d->channel_field[5]].unit_name, "0xe111");
    assert_string_equal(d->fields[d->channel_field[6]].unit_name, "");
    assert_false(pb_hid_field_has_physical(&d->fields[d->channel_field[6]]));
    int32_t lg[7];
    double v[7];
    uint8_t ok[7];
    uint32_t first, count;
    uint8_t rep[14] = {0};
    rep[0] = 0x00;
    rep[1] = 0x08; /* 2048 */
    assert_int_equal(pb_hid_report_decode(d, rep, sizeof rep, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_float_equal(v[0], 2048.0 * 360.0 / 4095.0, 1e-9);
    pb_hid_desc_free(d);
}

static void test_collections_delimiters_null(void **state)
{
    (void)state;
    static const uint8_t b[] = {
        0x05, 0x01, 0x09, 0x04, 0xA1, 0x01,             /* Application (Joystick) */
        0x09, 0x01, 0xA1, 0x00,                         /*  Physical (Pointer) */
        0xA1, 0x02,                                     /*   Logical */
        0xA9, 0x01, 0x09, 0x30, 0x09, 0x31, 0xA9, 0x00, /*   Delimited set: X preferred over Y */
        0x15, 0x00, 0x25, 0x64, 0x75, 0x08, 0x95, 0x01, 0x81, 0x02,
        0xC0, 0xC0,
        0x09, 0x39, 0x15, 0x01, 0x25, 0x08, 0x75, 0x04, 0x95, 0x01, 0x81, 0x42, /* hat: Null state */
        0x75, 0x04, 0x81, 0x03,
        0xC0,
    };
    pb_hid_desc *d = parse_ok(b, sizeof b);
    assert_int_equal(d->collection_count, 3);
    assert_int_equal(d->collections[2].type, 2);
    assert_int_equal(d->collections[2].parent, 1);
    assert_int_equal(d->collections[1].parent, 0);
    assert_int_equal(d->collections[0].parent, -1);
    assert_int_equal(d->channel_count, 2);
    assert_string_equal(d->channels[0].name, "GenericDesktop.X");
    assert_int_equal(d->fields[d->channel_field[0]].collection, 2);
    assert_string_equal(d->channels[1].name, "GenericDesktop.HatSwitch");
    assert_int_equal(d->fields[d->channel_field[1]].collection, 0);
    int32_t lg[2];
    double v[2];
    uint8_t ok[2];
    uint32_t first, count;
    const uint8_t centred[] = {0x32, 0x00};
    assert_int_equal(pb_hid_report_decode(d, centred, 2, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(lg[0], 50);
    assert_int_equal(ok[0], 1);
    assert_int_equal(ok[1], 0); /* 0 is outside 1..8: the hat reports no direction */
    const uint8_t east[] = {0x32, 0x03};
    assert_int_equal(pb_hid_report_decode(d, east, 2, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(ok[1], 1);
    assert_int_equal(lg[1], 3);
    pb_hid_desc_free(d);
}

static void test_unaligned_32bit(void **state)
{
    (void)state;
    static const uint8_t b[] = {
        0x75, 0x04, 0x95, 0x01, 0x81, 0x03,                   /* 4 bits padding */
        0x06, 0x00, 0xFF, 0x09, 0x01, 0x17, 0x00, 0x00, 0x00, 0x80, 0x27, 0xFF, 0xFF, 0xFF, 0x7F,
        0x75, 0x20, 0x81, 0x02,                               /* signed 32 bits at bit 4 */
        0x75, 0x04, 0x81, 0x03,
    };
    pb_hid_desc *d = parse_ok(b, sizeof b);
    assert_string_equal(d->channels[0].name, "Vendor0xFF00.0x01");
    const pb_hid_field *f = &d->fields[d->channel_field[0]];
    assert_int_equal(f->bit_offset, 4);
    const uint32_t value = 0x89ABCDEFu;
    uint8_t rep[5] = {0};
    uint64_t shifted = (uint64_t)value << 4;
    for (int i = 0; i < 5; i++)
        rep[i] = (uint8_t)(shifted >> (8 * i));
    assert_int_equal(pb_hid_field_extract(f, rep), (int32_t)value);
    pb_hid_desc_free(d);
}

static void test_mannequin(void **state)
{
    (void)state;
    pb_hid_desc *d = parse_ok(pb_mannequin_descriptor, pb_mannequin_descriptor_len);
    assert_true(d->uses_report_ids);
    assert_int_equal(pb_hid_desc_input_length(d, 1), PB_MANNEQUIN_REPORT_BYTES);
    assert_int_equal(d->channel_count, 18);
    for (int i = 0; i < 16; i++) {
        char name[16];
        snprintf(name, sizeof name, "Ordinal.%d", i + 1);
        assert_string_equal(d->channels[i].name, name);
        assert_string_equal(d->channels[i].unit, "deg");
        assert_float_equal(d->channels[i].min, -180.0, 1e-9);
        assert_float_equal(d->channels[i].max, 180.0, 1e-9);
        const pb_hid_field *f = &d->fields[d->channel_field[i]];
        assert_int_equal(f->bit_offset, 12 * i);
        assert_int_equal(f->bit_size, 12);
        assert_true(f->is_signed);
        assert_float_equal(f->scale, 0.1, 1e-12);
    }
    assert_string_equal(d->channels[16].name, "Button.1");
    assert_string_equal(d->channels[16].unit, ""); /* the Pop dropped the degrees */
    assert_string_equal(d->channels[17].name, "Vendor0xFF00.0x01");
    assert_int_equal(d->fields[d->channel_field[17]].logical_max, 65535);
    assert_false(d->fields[d->channel_field[17]].is_signed);
    /* Pack known angles and decode them back. */
    double deg[16];
    for (int i = 0; i < 16; i++)
        deg[i] = -150.0 + 20.0 * i;
    uint8_t rep[PB_MANNEQUIN_REPORT_BYTES];
    pb_mannequin_pack(deg, 1, 54321, NULL, rep);
    int32_t lg[18];
    double v[18];
    uint8_t ok[18];
    uint32_t first, count;
    assert_int_equal(pb_hid_report_decode(d, rep, sizeof rep, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    for (int i = 0; i < 16; i++) {
        double g, o;
        pb_mannequin_sensor(i, &g, &o);
        double expect = g * deg[i] + o;
        expect = expect > 180 ? 180 : expect < -180 ? -180 : expect;
        assert_float_equal(v[i], expect, 0.051); /* 0.1-degree quantisation */
    }
    assert_int_equal(lg[16], 1);
    assert_int_equal(lg[17], 54321);
    pb_hid_desc_free(d);
}

/* What the Linux kernel accepts with a warning (drivers/hid/hid-core.c): a
 * main item with a reserved tag, such as a 0x00 byte after the last End
 * Collection (hid_parser_main: "unknown main item tag", locals reset), an item
 * of the reserved type 3 (hid_parser_reserved) and a local item with a
 * reserved tag (hid_parser_local). The fields are those of the descriptor
 * without the odd items, and reports decode the same. */
static void test_kernel_tolerated_items(void **state)
{
    (void)state;
    pb_warnings w = {0};
    pb_warnings *prev = pb_warnings_install(&w);

    /* The boot mouse with one trailing 0x00 (byte 52). */
    uint8_t trailing[sizeof mouse + 1];
    memcpy(trailing, mouse, sizeof mouse);
    trailing[sizeof mouse] = 0x00;
    pb_hid_desc *d = parse_ok(trailing, sizeof trailing);
    assert_int_equal(w.count, 1);
    assert_string_equal(w.text[0], "t.bin: report descriptor byte 52: 1 trailing 0x00 byte after the last item skipped, "
                                   "as the Linux kernel does");
    assert_int_equal(d->field_count, 7);
    assert_int_equal(d->channel_count, 6);
    assert_int_equal(pb_hid_desc_input_length(d, 0), 4);
    int32_t lg[6];
    double v[6];
    uint8_t ok[6];
    uint32_t first, count;
    const uint8_t rep[] = {0x05, 0xFE, 0x02, 0x01}; /* buttons 1 and 3, X -2, Y 2, wheel 1 */
    assert_int_equal(pb_hid_report_decode(d, rep, sizeof rep, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(count, 6);
    const int32_t expect[6] = {1, 0, 1, -2, 2, 1};
    for (int c = 0; c < 6; c++)
        assert_int_equal(lg[c], expect[c]);
    pb_hid_desc_free(d);

    /* Several zero bytes: one warning naming where they start. */
    w.count = 0;
    uint8_t zeros[sizeof mouse + 3] = {0};
    memcpy(zeros, mouse, sizeof mouse);
    d = parse_ok(zeros, sizeof zeros);
    assert_int_equal(w.count, 1);
    assert_non_null(strstr(w.text[0], "byte 52: 3 trailing 0x00 bytes"));
    assert_int_equal(d->field_count, 7);
    pb_hid_desc_free(d);

    /* Reserved items inside: a main item with tag 0 between Usage (X) and Usage (Y)
     * clears the pending usages as every main item does, so the two values get
     * Y and then Y again (the last usage repeats); a reserved-type item (0x0D, one
     * data byte) and reserved local tags (0x68, 0xB9 with one byte) are skipped. */
    static const uint8_t odd[] = {
        0x05, 0x01, 0x09, 0x02, 0xA1, 0x01,       /* 0: Application (Mouse) */
        0x09, 0x30, 0x00, 0x09, 0x31,             /* 6: X, reserved main tag 0 at byte 8, Y */
        0x0D, 0x7F,                               /* 11: reserved type 3, tag 0 */
        0x68,                                     /* 13: local tag 6 (reserved) */
        0xB9, 0x01,                               /* 14: local tag 0xB (reserved) */
        0x15, 0x81, 0x25, 0x7F, 0x75, 0x08, 0x95, 0x02, 0x81, 0x06,
        0xD0,                                     /* 26: main tag 0xD (reserved) */
        0xC0,
    };
    w.count = 0;
    d = parse_ok(odd, sizeof odd);
    assert_int_equal(w.count, 5);
    assert_string_equal(w.text[0], "t.bin: report descriptor byte 8: main item with reserved tag 0x0 (prefix 0x00) "
                                   "skipped, as the Linux kernel does");
    assert_string_equal(w.text[1], "t.bin: report descriptor byte 11: item of reserved type 3 (prefix 0x0d) skipped, "
                                   "as the Linux kernel does");
    assert_non_null(strstr(w.text[2], "byte 13: local item with reserved tag 0x6 (prefix 0x68) skipped"));
    assert_non_null(strstr(w.text[3], "byte 14: local item with reserved tag 0xb (prefix 0xb9) skipped"));
    assert_non_null(strstr(w.text[4], "byte 26: main item with reserved tag 0xd (prefix 0xd0) skipped"));
    assert_int_equal(d->field_count, 2);
    assert_string_equal(d->channels[0].name, "GenericDesktop.Y");
    assert_string_equal(d->channels[1].name, "GenericDesktop.Y#1");
    assert_int_equal(d->fields[1].bit_offset, 8);
    pb_hid_desc_free(d);

    /* Accepted by the kernel, kept here with a warning: an exponent no double can
     * carry (taken as 0) and a 32-bit unsigned maximum (clamped to INT32_MAX). */
    static const uint8_t wide[] = {
        0x05, 0x01, 0x15, 0x00, 0x27, 0xFF, 0xFF, 0xFF, 0xFF, /* 0..4294967295 */
        0x55, 0x7F, 0x65, 0x11,                               /* 10^127 cm */
        0x75, 0x20, 0x95, 0x01, 0x09, 0x30, 0x81, 0x02,
    };
    w.count = 0;
    d = parse_ok(wide, sizeof wide);
    assert_int_equal(w.count, 2);
    assert_string_equal(w.text[0], "t.bin: report descriptor byte 9: unit exponent 127 out of -38..38 taken as 0 "
                                   "(the Linux kernel accepts it)");
    assert_non_null(strstr(w.text[1], "byte 19: logical maximum 4294967295 does not fit 32-bit signed values"));
    const pb_hid_field *wf = &d->fields[0];
    assert_int_equal(wf->logical_min, 0);
    assert_int_equal(wf->logical_max, INT32_MAX);
    assert_int_equal(wf->unit_exponent, 0);
    const uint8_t r32[4] = {0x10, 0x00, 0x00, 0x00};
    assert_int_equal(pb_hid_report_decode(d, r32, 4, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(lg[0], 16);
    assert_float_equal(v[0], 16.0, 1e-9);
    pb_hid_desc_free(d);

    /* More warnings than the sink keeps are counted; without a sink they are dropped. */
    uint8_t many[40];
    memset(many, 0x0C, sizeof many);
    w.count = 0;
    d = parse_ok(many, sizeof many);
    assert_int_equal(w.count, PB_WARN_MAX);
    assert_int_equal(w.dropped, sizeof many - PB_WARN_MAX);
    pb_hid_desc_free(d);
    pb_warnings_install(NULL);
    d = parse_ok(trailing, sizeof trailing);
    assert_int_equal(d->field_count, 7);
    pb_hid_desc_free(d);
    pb_warnings_install(prev);
}

/* A real device with the trailing 0x00: the Apple Wireless Keyboard over
 * Bluetooth (05ac:0256), data/hid/real/apple_wireless_keyboard_bt.hid
 * (provenance in data/hid/real/README.md). Its 225-byte descriptor ends
 * "... b1 01 c0 00": the 0x00 at byte 224 is a main item with tag 0, which
 * hid-core.c's hid_parser_main answers with hid_warn("unknown main item tag
 * 0x0") and return 0, so hid_open_report finishes the descriptor normally.
 * The expected values below were worked out by hand from hid-core.c
 * (hid_parser_global/_local/_main, hid_add_field, hid_concatenate_last_usage_page)
 * walked over the bytes; the kernel's own selftest for this keyboard
 * (tools/testing/selftests/hid/tests/test_apple_keyboard.py) carries bytes
 * 0-223, and its test_single_fn_function_key drives the 0xff0003 bit used below. */
static void test_real_trailing_zero(void **state)
{
    (void)state;
    const char *dir = getenv("POSE_DATA_DIR");
    assert_non_null(dir);
    char path[1024];
    snprintf(path, sizeof path, "%s/hid/real/apple_wireless_keyboard_bt.hid", dir);
    pb_hid_recording *rec = NULL;
    pb_error err = {{0}};
    if (pb_hid_recording_load(path, &rec, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(rec->device_count, 1);
    const pb_hid_rec_device *dev = &rec->devices[0];
    assert_string_equal(dev->name, "Apple Wireless Keyboard");
    assert_int_equal(dev->bus, 5); /* BUS_BLUETOOTH */
    assert_int_equal(dev->vendor, 0x05ac);
    assert_int_equal(dev->product, 0x0256);
    assert_int_equal(dev->desc_len, 225);
    assert_int_equal(dev->desc[223], 0xC0); /* the last End Collection */
    assert_int_equal(dev->desc[224], 0x00);

    pb_warnings w = {0};
    pb_warnings *prev = pb_warnings_install(&w);
    pb_hid_desc *d = NULL;
    if (pb_hid_desc_parse(dev->desc, dev->desc_len, "apple_wireless_keyboard_bt.hid", &d, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(w.count, 1); /* the kernel warns once, for byte 224 */
    assert_string_equal(w.text[0], "apple_wireless_keyboard_bt.hid: report descriptor byte 224: 1 trailing 0x00 byte "
                                   "after the last item skipped, as the Linux kernel does");

    /* Collections (the kernel's device->collection[], 4 of them): Application
     * Keyboard; Application Consumer Control holding a Logical Keyboard (usage
     * 0x00010006: Usage Page 0x01 is current at byte 77); Application Consumer Control. */
    assert_int_equal(d->collection_count, 4);
    const uint32_t col_usage[4] = {0x00010006, 0x000C0001, 0x00010006, 0x000C0001};
    const uint8_t col_type[4] = {1, 1, 2, 1};
    const int32_t col_parent[4] = {-1, -1, 1, -1};
    for (int i = 0; i < 4; i++) {
        assert_int_equal(d->collections[i].usage, col_usage[i]);
        assert_int_equal(d->collections[i].type, col_type[i]);
        assert_int_equal(d->collections[i].parent, col_parent[i]);
    }

    /* Report sizes (the kernel's report->size, bits, without the ID byte):
     * input 1 = 8 x 1 modifiers + 8 constant + 6 x 8 keys = 64; output 1 = 5 LEDs
     * + 3 constant = 8; inputs 17, 18, 19 and 71 = 8 each; feature 9 = 8 + 16 = 24. */
    assert_true(d->uses_report_ids);
    assert_int_equal(d->input_bytes[1], 8);
    assert_int_equal(pb_hid_desc_input_length(d, 1), 9);
    assert_int_equal(d->output_bytes[1], 1);
    assert_int_equal(d->input_bytes[17], 1);
    assert_int_equal(d->input_bytes[18], 1);
    assert_int_equal(d->input_bytes[19], 1);
    assert_int_equal(d->input_bytes[71], 1);
    assert_int_equal(d->feature_bytes[9], 3);
    assert_int_equal(d->input_bytes[9], 0);

    /* The kernel makes 14 fields (hid_add_field skips the 9 constant items, which
     * only advance report->size): input 1: modifiers (report_count 8, usages
     * 0x700e0-0x700e7) and keys (array, report_count 6, 256 usages 0x70000-0x700ff,
     * logical 0..255); output 1: LEDs (5 usages 0x80001-0x80005); input 71: Battery
     * Strength 0x60020; input 17: Eject 0xc00b8 at bit 3, 0xff0003 at bit 4 (Usage
     * Page 0x00ff); input 18: 0xc00cd, 0xc00b3, 0xc00b4, 0xc00b5, 0xc00b6 at bits
     * 0-4; input 19: 0xff01000a, 0xff01000c (Input 0x22: NoPref); feature 9: 0xff01000b.
     * Here one pb_hid_field is one value (report_count of them per kernel field) and
     * the constant items are kept as padding: 30 values + 9 padding = 39; the 24
     * input values are the channels. */
    assert_int_equal(d->field_count, 39);
    assert_int_equal(d->channel_count, 24);
    for (int c = 0; c < 8; c++) {
        const pb_hid_field *f = &d->fields[d->channel_field[c]];
        assert_int_equal(f->report_id, 1);
        assert_int_equal(f->usage, 0x000700E0u + (uint32_t)c);
        assert_int_equal(f->bit_offset, (uint32_t)c);
        assert_int_equal(f->bit_size, 1);
    }
    for (int c = 8; c < 14; c++) {
        const pb_hid_field *f = &d->fields[d->channel_field[c]];
        assert_false(f->flags & PB_HID_VARIABLE);
        assert_int_equal(f->usage, 0x00070000);
        assert_int_equal(f->usage_last, 0x000700FF);
        assert_int_equal(f->array_index, (uint32_t)(c - 8));
        assert_int_equal(f->bit_offset, 16 + 8 * (uint32_t)(c - 8));
        assert_int_equal(f->logical_min, 0);
        assert_int_equal(f->logical_max, 255);
    }
    static const struct { uint8_t id; uint32_t usage, bit; uint16_t flags; } rest[] = {
        {17, 0x000C00B8, 3, 0x02}, {17, 0x00FF0003, 4, 0x02}, {18, 0x000C00CD, 0, 0x02},
        {18, 0x000C00B3, 1, 0x02}, {18, 0x000C00B4, 2, 0x02}, {18, 0x000C00B5, 3, 0x02},
        {18, 0x000C00B6, 4, 0x02}, {19, 0xFF01000A, 0, 0x02}, {19, 0xFF01000C, 1, 0x22},
        {71, 0x00060020, 0, 0x02},
    };
    for (int i = 0; i < 10; i++) {
        const pb_hid_field *f = &d->fields[d->channel_field[14 + i]];
        assert_int_equal(f->kind, PB_HID_INPUT);
        assert_int_equal(f->report_id, rest[i].id);
        assert_int_equal(f->usage, rest[i].usage);
        assert_int_equal(f->bit_offset, rest[i].bit);
        assert_int_equal(f->flags, rest[i].flags);
    }
    assert_int_equal(d->fields[d->channel_field[23]].logical_max, 255); /* battery 0..255 */
    assert_int_equal(d->fields[d->channel_field[23]].collection, 2);   /* inside the Logical one */
    int leds = 0, feature = 0;
    for (size_t i = 0; i < d->field_count; i++) {
        const pb_hid_field *f = &d->fields[i];
        if (f->kind == PB_HID_OUTPUT && !(f->flags & PB_HID_CONSTANT)) {
            assert_int_equal(f->usage, 0x00080001u + (uint32_t)leds);
            leds++;
        } else if (f->kind == PB_HID_FEATURE && !(f->flags & PB_HID_CONSTANT)) {
            assert_int_equal(f->report_id, 9);
            assert_int_equal(f->usage, 0xFF01000B);
            feature++;
        }
    }
    assert_int_equal(leds, 5);
    assert_int_equal(feature, 1);

    /* Reports laid out by that descriptor (authored here): Left Shift with 'a'
     * and 's' held, then the fn key (report 17 bit 4, as the kernel selftest's
     * send_fn_state sets it), then a battery level. */
    int32_t lg[24];
    double v[24];
    uint8_t ok[24];
    uint32_t first, count;
    const uint8_t keys[9] = {0x01, 0x02, 0x00, 0x04, 0x16, 0x00, 0x00, 0x00, 0x00};
    assert_int_equal(pb_hid_report_decode(d, keys, sizeof keys, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(first, 0);
    assert_int_equal(count, 14);
    for (int c = 0; c < 8; c++)
        assert_int_equal(lg[c], c == 1); /* 0xE1 Left Shift */
    assert_int_equal(lg[8], 0x04);
    assert_int_equal(lg[9], 0x16);
    for (int c = 10; c < 14; c++)
        assert_int_equal(lg[c], 0);
    const uint8_t fn[2] = {0x11, 0x10};
    assert_int_equal(pb_hid_report_decode(d, fn, sizeof fn, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(first, 14);
    assert_int_equal(count, 2);
    assert_int_equal(lg[14], 0);
    assert_int_equal(lg[15], 1);
    const uint8_t battery[2] = {0x47, 0x64};
    assert_int_equal(pb_hid_report_decode(d, battery, sizeof battery, lg, v, ok, &first, &count), PB_HID_DECODE_OK);
    assert_int_equal(first, 23);
    assert_int_equal(count, 1);
    assert_int_equal(lg[23], 100);
    const uint8_t feature_id[4] = {0x09, 0x00, 0x00, 0x00};
    assert_int_equal(pb_hid_report_decode(d, feature_id, sizeof feature_id, lg, v, ok, &first, &count),
                     PB_HID_DECODE_UNKNOWN_ID);

    /* Without byte 224 (the kernel selftest's 224 bytes): no warning, the same fields. */
    w.count = 0;
    pb_hid_desc *d224 = parse_ok(dev->desc, 224);
    assert_int_equal(w.count, 0);
    assert_int_equal(d224->field_count, d->field_count);
    assert_int_equal(d224->channel_count, d->channel_count);
    for (size_t i = 0; i < d->field_count; i++) {
        const pb_hid_field *a = &d->fields[i], *b = &d224->fields[i];
        assert_int_equal(a->kind, b->kind);
        assert_int_equal(a->report_id, b->report_id);
        assert_int_equal(a->flags, b->flags);
        assert_int_equal(a->bit_offset, b->bit_offset);
        assert_int_equal(a->bit_size, b->bit_size);
        assert_int_equal(a->usage, b->usage);
        assert_int_equal(a->usage_last, b->usage_last);
    }
    pb_hid_desc_free(d224);
    pb_hid_desc_free(d);
    pb_hid_recording_free(rec);
    pb_warnings_install(prev);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_invalid),
        cmocka_unit_test(test_mouse),
        cmocka_unit_test(test_sign_and_sizes),
        cmocka_unit_test(test_report_ids_and_extended_usages),
        cmocka_unit_test(test_arrays),
        cmocka_unit_test(test_units_push_pop),
        cmocka_unit_test(test_collections_delimiters_null),
        cmocka_unit_test(test_unaligned_32bit),
        cmocka_unit_test(test_mannequin),
        cmocka_unit_test(test_kernel_tolerated_items),
        cmocka_unit_test(test_real_trailing_zero),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
