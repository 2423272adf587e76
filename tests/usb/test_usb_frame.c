/* SPDX-License-Identifier: Apache-2.0
 * The vendor-class frame layout (usb_frame.h) and the usbmon text reader
 * (usbmon.h): fields of every size, endianness and sign, packed bit fields,
 * checksums against their published check values, the sequence counter's
 * exact accounting of lost, late and repeated frames (across its wrap), the
 * layout's errors naming the key, and usbmon lines from the kernel's
 * documentation, old "t" lines, truncated data and malformed lines whose
 * errors name the file, line and byte. */
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "usb_frame.h"
#include "usb_gonio.h"
#include "usbmon.h"

static pb_usb_layout *layout_from(const char *json, pose_status want, const char *msg)
{
    static pb_usb_layout l;
    pb_error err = {{0}};
    pose_status s = pb_usb_layout_parse(json, strlen(json), "t.json", &l, &err);
    if (s != want)
        fail_msg("status %d, wanted %d: %s", s, want, err.message);
    if (msg && !strstr(err.message, msg))
        fail_msg("message '%s' lacks '%s'", err.message, msg);
    return &l;
}

static void test_fields(void **state)
{
    (void)state;
    const uint8_t f[8] = {0x34, 0x12, 0xFF, 0xFE, 0x80, 0x00, 0x00, 0x01};
    pb_usb_field le16 = {0, 2, 0, 0, 0, 16}, be16 = {0, 2, 1, 0, 0, 16}, s16 = {2, 2, 0, 1, 0, 16};
    assert_int_equal(pb_usb_field_get(&le16, f), 0x1234);
    assert_int_equal(pb_usb_field_get(&be16, f), 0x3412);
    assert_int_equal(pb_usb_field_get(&s16, f), -257); /* 0xFEFF */
    pb_usb_field s8 = {4, 1, 0, 1, 0, 8}, u8 = {4, 1, 0, 0, 0, 8}, be32 = {4, 4, 1, 0, 0, 32};
    assert_int_equal(pb_usb_field_get(&s8, f), -128);
    assert_int_equal(pb_usb_field_get(&u8, f), 128);
    assert_int_equal(pb_usb_field_get(&be32, f), 0x80000001);
    pb_usb_field s64 = {0, 8, 0, 1, 0, 64};
    assert_true(pb_usb_field_get(&s64, f) == (int64_t)0x01000080FEFF1234LL);
    /* 12-bit signed at bit 4 of byte 1: bytes 1-2 LE = 0xFF12 >> 4 = 0xFF1 -> -15 */
    pb_usb_field p12 = {1, 2, 0, 1, 4, 12};
    assert_int_equal(pb_usb_field_get(&p12, f), -15);
    /* put then get, leaving the neighbouring bits alone */
    uint8_t g[4] = {0xAA, 0xAA, 0xAA, 0xAA};
    pb_usb_field a = {0, 2, 0, 1, 0, 12}, b = {1, 2, 0, 1, 4, 12};
    pb_usb_field_put(&a, g, -1000);
    pb_usb_field_put(&b, g, 1234);
    assert_int_equal(pb_usb_field_get(&a, g), -1000);
    assert_int_equal(pb_usb_field_get(&b, g), 1234);
    assert_int_equal(g[3], 0xAA);
}

static void test_checksums(void **state)
{
    (void)state;
    const uint8_t check[] = "123456789";
    assert_int_equal(pb_usb_checksum(PB_USB_CHECKSUM_CRC16_CCITT, check, 9), 0x29B1); /* CRC-16/CCITT-FALSE */
    assert_int_equal(pb_usb_checksum(PB_USB_CHECKSUM_SUM8, check, 9), 0xDD);          /* 477 & 0xFF */
    assert_int_equal(pb_usb_checksum(PB_USB_CHECKSUM_XOR8, check, 9), 0x31);
}

static const char *const SEQ_MAP =
    "{\"usb\": {\"frame_bytes\": 4, \"sequence\": {\"byte\": 0, \"size\": 1},"
    " \"checksum\": {\"kind\": \"xor8\", \"byte\": 3, \"from\": 0, \"to\": 3},"
    " \"channels\": [{\"name\": \"a\", \"byte\": 1, \"size\": 2, \"endian\": \"big\", \"signed\": true,"
    " \"scale\": 0.5, \"offset\": 10, \"unit\": \"deg\"}]}}";

static pb_usb_decode_result feed(pb_usb_decoder *d, unsigned seq, int value)
{
    uint8_t fr[4] = {(uint8_t)seq, 0, 0, 0};
    pb_usb_field_put(&d->layout->channels[0].field, fr, value);
    pb_usb_checksum_store(d->layout, fr);
    return pb_usb_decode(d, fr, sizeof fr, NULL);
}

static void test_sequence_accounting(void **state)
{
    (void)state;
    pb_usb_layout *l = layout_from(SEQ_MAP, POSE_OK, NULL);
    pb_usb_decoder d;
    pb_error err;
    assert_int_equal(pb_usb_decoder_init(&d, l, &err), POSE_OK);
    assert_true(isnan(d.values[0]));
    assert_int_equal(feed(&d, 250, -4), PB_USB_DECODE_OK);
    assert_true(d.values[0] == 8.0); /* -4 * 0.5 + 10 */
    assert_int_equal(feed(&d, 251, 0), PB_USB_DECODE_OK);
    assert_int_equal(feed(&d, 254, 0), PB_USB_DECODE_OK); /* 252, 253 lost */
    assert_int_equal(d.stats.lost, 2);
    assert_int_equal(feed(&d, 252, 7), PB_USB_DECODE_REORDERED); /* late: one of them */
    assert_true(d.values[0] == 10.0);                             /* not decoded */
    assert_int_equal(d.stats.lost, 1);
    assert_int_equal(feed(&d, 252, 7), PB_USB_DECODE_REORDERED); /* the same again: repeated */
    assert_int_equal(d.stats.lost, 1);
    assert_int_equal(feed(&d, 254, 0), PB_USB_DECODE_REORDERED); /* repeated newest */
    assert_int_equal(feed(&d, 255, 0), PB_USB_DECODE_OK);
    assert_int_equal(feed(&d, 1, 0), PB_USB_DECODE_OK); /* wraps: 0 lost */
    assert_int_equal(d.stats.lost, 2);
    assert_int_equal(d.stats.reordered, 3);
    assert_int_equal(d.stats.frames, 5);
    /* malformed frames change nothing and are counted by kind */
    uint8_t fr[4] = {2, 0, 0, 0};
    assert_int_equal(pb_usb_decode(&d, fr, 3, NULL), PB_USB_DECODE_SHORT);
    assert_int_equal(pb_usb_decode(&d, fr, 4, NULL), PB_USB_DECODE_CHECKSUM); /* xor is 2, stored 0 */
    uint8_t big[5] = {0};
    assert_int_equal(pb_usb_decode(&d, big, 5, NULL), PB_USB_DECODE_LONG);
    assert_int_equal(d.stats.short_frames + d.stats.bad_checksums + d.stats.long_frames, 3);
    /* a device that left starts its counter anew: no loss counted across the gap */
    pb_usb_decoder_count_status(&d, PB_USB_XFER_NO_DEVICE);
    pb_usb_decoder_count_status(&d, PB_USB_XFER_NO_DEVICE); /* the resubmission's ENODEV: the same unplug */
    assert_int_equal(feed(&d, 0, 0), PB_USB_DECODE_OK);
    assert_int_equal(d.stats.lost, 2);
    assert_int_equal(d.stats.disconnects, 1);
    pb_usb_decoder_free(&d);
}

static void test_layout_errors(void **state)
{
    (void)state;
    layout_from("{\"channels\": []}", POSE_ERR_FORMAT, "no \"usb\" object");
    layout_from("{\"usb\": {\"channels\": [{\"name\": \"a\", \"byte\": 0}]}}", POSE_ERR_FORMAT,
                "\"frame_bytes\" is missing");
    layout_from("{\"usb\": {\"frame_bytes\": 4, \"channels\": [{\"name\": \"a\", \"byte\": 3, \"size\": 2}]}}",
                POSE_ERR_FORMAT, "usb.channels[0] (a): bytes 3..4 lie past the frame's 4 bytes");
    layout_from("{\"usb\": {\"frame_bytes\": 4, \"channels\": [{\"name\": \"a\", \"byte\": 0, \"size\": 3}]}}",
                POSE_ERR_FORMAT, "size 3 is not 1, 2, 4 or 8");
    layout_from("{\"usb\": {\"frame_bytes\": 4, \"channels\": [{\"name\": \"a\", \"byte\": 0, \"size\": 1, \"shift\": 4, "
                "\"bits\": 6}]}}",
                POSE_ERR_FORMAT, "shift 4 + bits 6 do not fit in 1 bytes");
    layout_from("{\"usb\": {\"frame_bytes\": 4, \"endpoint\": \"0x01\", \"channels\": [{\"name\": \"a\", \"byte\": 0}]}}",
                POSE_ERR_FORMAT, "not an IN endpoint");
    layout_from("{\"usb\": {\"frame_bytes\": 4, \"checksum\": {\"kind\": \"crc16-ccitt\", \"byte\": 3}, \"channels\": "
                "[{\"name\": \"a\", \"byte\": 0}]}}",
                POSE_ERR_FORMAT, "usb.checksum: stored at byte 3 (2 bytes)");
    layout_from("{\"usb\": {\"frame_bytes\": 4, \"checksum\": {\"kind\": \"md5\", \"byte\": 3}, \"channels\": "
                "[{\"name\": \"a\", \"byte\": 0}]}}",
                POSE_ERR_FORMAT, "kind \"md5\"");
    layout_from("{\"usb\": {\"frame_bytes\": 4, \"channels\": [{\"name\": \"a\", \"byte\": 0}, {\"name\": \"a\", "
                "\"byte\": 1}]}}",
                POSE_ERR_FORMAT, "usb.channels[1] (a): the name is given twice");
    layout_from("{\"usb\": {\"frame_bytes\": 4, \"channels\": [{\"name\": \"a\", \"byte\": 0, \"scale\": 0}]}}",
                POSE_ERR_FORMAT, "scale must be finite and not 0");
    layout_from("{\"usb\": ", POSE_ERR_FORMAT, "t.json: offset");
}

/* The shipped map's "usb" object is the box's layout, field for field. */
static void test_shipped_map_is_the_box(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/../bridge/maps/usb_gonio_full_body.json", getenv("POSE_DATA_DIR"));
    static pb_usb_layout file, box;
    pb_error err;
    assert_int_equal(pb_usb_layout_load(path, &file, &err), POSE_OK);
    pb_gonio_layout(&box);
    assert_int_equal(file.vid, box.vid);
    assert_int_equal(file.pid, box.pid);
    assert_int_equal(file.endpoint, box.endpoint);
    assert_int_equal(file.frame_bytes, box.frame_bytes);
    assert_int_equal(file.checksum, box.checksum);
    assert_int_equal(file.checksum_byte, box.checksum_byte);
    assert_int_equal(file.checksum_to, box.checksum_to);
    assert_string_equal(file.hold_channel, box.hold_channel);
    assert_int_equal(file.channel_count, box.channel_count);
    assert_memory_equal(&file.sequence, &box.sequence, sizeof file.sequence);
    for (size_t i = 0; i < box.channel_count; i++) {
        assert_string_equal(file.channels[i].name, box.channels[i].name);
        assert_memory_equal(&file.channels[i].field, &box.channels[i].field, sizeof box.channels[i].field);
        assert_true(file.channels[i].scale == box.channels[i].scale);
    }
    /* a packed frame decodes back to the sensor's reading, to the 0.1-degree step */
    double deg[PB_MANNEQUIN_AXES];
    int hold;
    pb_mannequin_pose(PB_MOTION_ARM_RAISE, 2.5, deg, &hold);
    uint8_t fr[PB_GONIO_FRAME_BYTES];
    pb_gonio_pack(&box, deg, 1, 65535, NULL, fr);
    pb_usb_decoder d;
    assert_int_equal(pb_usb_decoder_init(&d, &file, &err), POSE_OK);
    uint64_t seq;
    assert_int_equal(pb_usb_decode(&d, fr, sizeof fr, &seq), PB_USB_DECODE_OK);
    assert_int_equal(seq, 65535);
    for (int i = 0; i < PB_MANNEQUIN_AXES; i++) {
        double g, o;
        pb_mannequin_sensor(i, &g, &o);
        if (fabs(d.values[i] - (g * deg[i] + o)) > 0.05 + 1e-9)
            fail_msg("axis %d: %.3f, sensor reads %.3f", i, d.values[i], g * deg[i] + o);
    }
    assert_true(d.values[PB_MANNEQUIN_AXES] == 1.0);
    pb_usb_decoder_free(&d);
}

static pb_usbmon_capture *parse(const char *text, pose_status want, const char *msg)
{
    pb_usbmon_capture *c = NULL;
    pb_error err = {{0}};
    pose_status s = pb_usbmon_parse(text, strlen(text), "cap.txt", &c, &err);
    if (s != want)
        fail_msg("status %d, wanted %d: %s", s, want, err.message);
    if (msg && !strstr(err.message, msg))
        fail_msg("message '%s' lacks '%s'", err.message, msg);
    return c;
}

static void test_usbmon_kernel_examples(void **state)
{
    (void)state;
    /* Documentation/usb/usbmon.rst's examples: a control transfer getting a port status, a bulk OUT */
    pb_usbmon_capture *c = parse("d5ea89a0 3575914555 S Ci:1:001:0 s a3 00 0000 0003 0004 4 <\n"
                                 "d5ea89a0 3575914560 C Ci:1:001:0 0 4 = 01050000\n"
                                 "dd65f0e8 4128379752 S Bo:1:005:2 -115 31 = 55534243 ad000000 00800000 80010a28 "
                                 "20000000 20000040 00000000 000000\n"
                                 "dd65f0e8 4128379808 C Bo:1:005:2 0 31 >\n",
                                 POSE_OK, NULL);
    assert_int_equal(c->count, 4);
    const pb_usbmon_event *e = &c->events[1];
    assert_int_equal(e->t_us, 3575914560LL);
    assert_int_equal(e->event, 'C');
    assert_int_equal(e->xfer, 'C');
    assert_int_equal(e->in, 1);
    assert_int_equal(e->bus, 1);
    assert_int_equal(e->dev, 1);
    assert_int_equal(e->ep, 0);
    assert_int_equal(e->length, 4);
    assert_int_equal(e->captured, 4);
    assert_memory_equal(c->data + e->offset, "\x01\x05\x00\x00", 4);
    e = &c->events[2];
    assert_int_equal(e->status, -115);
    assert_int_equal(e->captured, 31);
    assert_int_equal(c->data[e->offset + 30], 0x00);
    assert_int_equal(c->data[e->offset + 3], 0x43);
    assert_int_equal(c->events[3].captured, 0);
    pb_usbmon_capture_free(c);
    /* an interrupt completion with its interval, a "t" line without a bus, a cut capture, a submission error */
    c = parse("ffff9960828e9540 4014796128 C Ii:1:001:1 0:2048 2 = 1000\n"
              "# a comment\n\n"
              "c5753280 41352977 S Ii:001:1 -115:2048 4 <\n"
              "ffff8881 100 C Ii:3:007:1 0:1 40 = 00112233 44556677 8899aabb ccddeeff 00112233 44556677 8899aabb "
              "ccddeeff\n"
              "ffff8881 200 E Ii:3:007:1 -19:1 0\n",
              POSE_OK, NULL);
    assert_int_equal(c->count, 4);
    assert_int_equal(c->comment_lines, 1);
    assert_int_equal(c->events[0].interval, 2048);
    assert_int_equal(c->events[1].bus, 0);
    assert_int_equal(c->events[1].dev, 1);
    assert_int_equal(c->events[1].line, 4);
    assert_int_equal(c->events[2].length, 40);
    assert_int_equal(c->events[2].captured, 32);
    assert_int_equal(c->events[3].event, 'E');
    assert_int_equal(c->events[3].status, -ENODEV);
    pb_usbmon_capture_free(c);
}

static void test_usbmon_errors(void **state)
{
    (void)state;
    parse("a b C Ii:1:001:1 0 4 <\n", POSE_ERR_FORMAT, "cap.txt:1: byte 2: expected the time stamp");
    parse("# x\na 1 X Ii:1:001:1 0 4 <\n", POSE_ERR_FORMAT, "cap.txt:2: byte 4: expected the event type");
    parse("a 1 C Qi:1:001:1 0 4 <\n", POSE_ERR_FORMAT, "byte 6: expected an address");
    parse("a 1 C Ii:1:200:1 0 4 <\n", POSE_ERR_FORMAT, "device above 127 or endpoint above 15");
    parse("a 1 C Ii:1:001:1 0:x 4 <\n", POSE_ERR_FORMAT, "the interval is not a decimal number");
    parse("a 1 C Bi:1:001:1 0:1 4 <\n", POSE_ERR_FORMAT, "only interrupt and isochronous transfers have one");
    parse("a 1 C Ii:1:001:1 0 4 = 0011223\n", POSE_ERR_FORMAT, "cap.txt:1: byte 23: data word '0011223'");
    parse("a 1 C Ii:1:001:1 0 2 = 001122\n", POSE_ERR_FORMAT, "3 data bytes on a line whose data length is 2");
    parse("a 1 C Ii:1:001:1 0\n", POSE_ERR_FORMAT, "the line ends before the data length");
    parse("a 1 C Ii:1:001:1 0 4 < 00\n", POSE_ERR_FORMAT, "text after the data tag");
    parse("a 1 S Ci:1:001:0 s a3 00 0000\n", POSE_ERR_FORMAT, "setup packet word 4");
    parse("a 1 C Ii:1:001:1 s 4 <\n", POSE_ERR_FORMAT, "setup tag 's' on an event that is not a control submission");
    pb_usbmon_capture *c = parse("", POSE_OK, NULL);
    assert_int_equal(c->count, 0);
    pb_usbmon_capture_free(c);
}

/* What pb_usbmon_write writes reads back the same. */
static void test_usbmon_round_trip(void **state)
{
    (void)state;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    const uint8_t data[5] = {1, 2, 3, 4, 5};
    pb_usbmon_event a = {.t_us = 123456789, .event = 'C', .xfer = 'B', .in = 1, .bus = 2, .dev = 9, .ep = 3,
                         .status = 0, .interval = -1, .length = 5, .captured = 5};
    pb_usbmon_event b = {.t_us = 123456999, .event = 'C', .xfer = 'I', .in = 1, .bus = 2, .dev = 9, .ep = 1,
                         .status = -EPIPE, .interval = 8, .length = 0};
    assert_int_equal(pb_usbmon_write(f, 0xffff1234, &a, data), 0);
    assert_int_equal(pb_usbmon_write(f, 0xffff1235, &b, NULL), 0);
    fclose(f);
    assert_non_null(strstr(buf, " C Bi:2:009:3 0 5 = 01020304 05\n"));
    assert_non_null(strstr(buf, " C Ii:2:009:1 -32:8 0 <\n"));
    pb_usbmon_capture *c = parse(buf, POSE_OK, NULL);
    assert_int_equal(c->count, 2);
    assert_int_equal(c->events[0].t_us, 123456789);
    assert_memory_equal(c->data + c->events[0].offset, data, 5);
    assert_int_equal(c->events[1].status, -EPIPE);
    assert_int_equal(c->events[1].interval, 8);
    pb_usbmon_capture_free(c);
    free(buf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fields),
        cmocka_unit_test(test_checksums),
        cmocka_unit_test(test_sequence_accounting),
        cmocka_unit_test(test_layout_errors),
        cmocka_unit_test(test_shipped_map_is_the_box),
        cmocka_unit_test(test_usbmon_kernel_examples),
        cmocka_unit_test(test_usbmon_errors),
        cmocka_unit_test(test_usbmon_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
