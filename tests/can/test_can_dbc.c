/* SPDX-License-Identifier: Apache-2.0
 * DBC parser and signal decoder: malformed files first, then hand-checked
 * frames (Intel, Motorola, signed, float, multiplexed), then the real DBC
 * files bundled in data/can. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "dbc_decode.h"
#include "dbc_parse.h"
#include "pb_warn.h"

static pb_dbc *parse_ok(const char *text)
{
    pb_dbc *d = NULL;
    pb_dbc_error e;
    int rc = pb_dbc_parse(text, strlen(text), "inline.dbc", &d, &e);
    if (rc != 0)
        fail_msg("unexpected parse error: %s", e.message);
    return d;
}

/* Parse must fail at `line` with a message containing `what`. */
static void parse_fails(const char *text, size_t line, const char *what)
{
    pb_dbc *d = NULL;
    pb_dbc_error e;
    assert_int_equal(pb_dbc_parse(text, strlen(text), "bad.dbc", &d, &e), -1);
    assert_null(d);
    assert_int_equal(e.line, line);
    char prefix[32];
    snprintf(prefix, sizeof prefix, "bad.dbc:%zu: ", line);
    if (strncmp(e.message, prefix, strlen(prefix)) != 0 || !strstr(e.message, what))
        fail_msg("message '%s' lacks '%s' or '%s'", e.message, prefix, what);
}

static void test_malformed(void **state)
{
    (void)state;
    parse_fails(" SG_ a : 0|8@1+ (1,0) [0|0] \"\" N\n", 1, "outside a message");
    parse_fails("BO_ 1 M: 8 N\n SG_ a : 0|0@1+ (1,0) [0|0] \"\" N\n", 2, "length 0");
    parse_fails("BO_ 1 M: 8 N\n SG_ a : 600|8@1+ (1,0) [0|0] \"\" N\n", 2, "start bit");
    parse_fails("BO_ 1 M: 8 N\n SG_ a : 510|8@1+ (1,0) [0|0] \"\" N\n", 2, "past 64 bytes");
    parse_fails("BO_ 1 M: 8 N\n SG_ a : 0|8@2+ (1,0) [0|0] \"\" N\n", 2, "byte order");
    parse_fails("BO_ 1 M: 8 N\n SG_ a : 0|8@1* (1,0) [0|0] \"\" N\n", 2, "'+' or '-'");
    parse_fails("BO_ 1 M: 8 N\n SG_ a : 0|8@1+ (1,0) [0|0] \"deg N\n", 2, "not closed");
    parse_fails("BO_ x M: 8 N\n", 1, "message identifier");
    parse_fails("BO_ 1 M: 65 N\n", 1, "size");
    parse_fails("BO_ 1 M: 8 N\n SG_ a : 0|16@1+ (1,0) [0|0] \"\" N\n\nSIG_VALTYPE_ 1 a : 1;\n", 4,
                "32 bits");
    parse_fails("BO_ 1 M: 8 N\n SG_ a m5 : 0|8@1+ (1,0) [0|0] \"\" N\n", 2, "no multiplexor");
    parse_fails("BO_ 1 M: 8 N\n SG_ a x5 : 0|8@1+ (1,0) [0|0] \"\" N\n", 2, "multiplexer indicator");
    parse_fails("BO_ 1 M: 8 N\n SG_ a : 0|8@1+ (1,0) [0|0] \"\" N\n SG_ a : 8|8@1+ (1,0) [0|0] \"\" N\n",
                3, "twice");
    parse_fails("BO_ 1 M: 8 N\n SG_ a : 0|8@1+ (1e999,0) [0|0] \"\" N\n", 2, "bad number");
    parse_fails("BO_ 1 M: 8 N\n SG_ a m1M : 0|4@1+ (1,0) [0|0] \"\" N\n SG_ b m1M : 4|4@1+ (1,0) [0|0] \"\" N\n"
                "SG_MUL_VAL_ 1 a b 1-1;\nSG_MUL_VAL_ 1 b a 1-1;\n",
                2, "loop");
    parse_fails("BO_ 1 M: 8 N\n SG_ a M : 0|4@1+ (1,0) [0|0] \"\" N\n SG_ b : 4|4@1+ (1,0) [0|0] \"\" N\n"
                "SG_MUL_VAL_ 1 a b 3-1;\n",
                4, "empty");
    parse_fails("12 BO_\n", 1, "expected a keyword");
    /* Statements we skip may hold anything, even ';' and newlines in strings. */
    pb_dbc *d = parse_ok("CM_ \"a; b\n c\";\nBA_DEF_ BO_ \"x\" INT 0 1;\nBO_ 5 M: 1 N\n");
    assert_int_equal(d->message_count, 1);
    assert_int_equal(d->messages[0].id, 5);
    pb_dbc_free(d);
    /* A byte order mark, CRLF line ends and an unindented NS_ list are fine. */
    d = parse_ok("\xEF\xBB\xBFVERSION \"\"\r\nNS_ :\r\nSIG_VALTYPE_\r\nVAL_\r\nBA_\r\n\r\nBS_:\r\n"
                 "BU_: N\r\nBO_ 5 M: 1 N\r\n SG_ a : 0|8@1+ (1,0) [0|0] \"\" N\r\n");
    assert_int_equal(d->message_count, 1);
    assert_int_equal(d->messages[0].signal_count, 1);
    assert_int_equal(d->messages[0].signals[0].line, 10);
    pb_dbc_free(d);
        /* A VAL_ for a signal that does not exist is a warning, not an error. */
    d = parse_ok("BO_ 5 M: 1 N\nVAL_ 5 nope 1 \"one\" ;\n");
    assert_int_equal(d->warning_count, 1);
    assert_non_null(strstr(d->warning, "inline.dbc:2:"));
    pb_dbc_free(d);
    assert_int_equal(pb_dbc_load("/nonexistent/x.dbc", &d, NULL), -1);
}

static const char *const HAND_DBC =
    "VERSION \"\"\n"
    "BU_: N\n"
    "BO_ 256 M: 8 N\n"
    " SG_ a : 0|16@1- (0.01,0) [-180|180] \"deg\" N\n"
    " SG_ b : 12|8@1+ (1,0) [0|255] \"\" N\n"
    " SG_ c : 7|16@0+ (1,0) [0|0] \"\" N\n"
    " SG_ d : 19|12@0+ (1,0) [0|0] \"\" N\n"
    " SG_ e : 15|8@0- (0.5,10) [0|0] \"\" N\n"
    " SG_ f : 32|32@1- (1,0) [0|0] \"\" N\n"
    "BO_ 2147484159 X: 8 N\n"          /* 0x800001FF: extended id 0x1FF */
    " SG_ g : 0|64@1- (1,0) [0|0] \"\" N\n"
    "SIG_VALTYPE_ 256 f : 1;\n"
    "SIG_VALTYPE_ 2147484159 g : 2;\n"
    "VAL_ 256 b 79 \"seventy-nine\" 0 \"zero\" ;\n";

static void test_hand_checked(void **state)
{
    (void)state;
    pb_dbc *d = parse_ok(HAND_DBC);
    const pb_dbc_message *m = pb_dbc_find(d, 256, 0);
    assert_non_null(m);
    assert_null(pb_dbc_find(d, 256, 1));
    assert_int_equal(m->signal_count, 6);
    /* 18 FC 34 12 | 00 00 C0 3F */
    const uint8_t data[8] = {0x18, 0xFC, 0x34, 0x12, 0x00, 0x00, 0xC0, 0x3F};
    double v[6];
    uint64_t raw[6];
    uint8_t pr[6];
    assert_int_equal(pb_dbc_decode(m, data, 8, v, raw, pr), 6);
    /* a, Intel signed 16 at bit 0: 0xFC18 = 64536 -> -1000 -> x0.01 = -10.00 */
    assert_true(fabs(v[0] - -10.0) < 1e-12);
    /* b, Intel 8 at bit 12: byte1 high nibble 0xF (low bits), byte2 low nibble 0x4 (high bits) = 0x4F = 79 */
    assert_true(v[1] == 79.0);
    assert_string_equal(pb_dbc_choice_text(&m->signals[1], (int64_t)raw[1]), "seventy-nine");
    assert_null(pb_dbc_choice_text(&m->signals[1], 80));
    /* c, Motorola 16, MSB at bit 7 of byte 0: bytes 0,1 big-endian = 0x18FC = 6396 */
    assert_true(v[2] == 6396.0);
    /* d, Motorola 12, MSB at bit 19 (byte 2, bit 3): byte2 bits 3..0 = 0x4, then byte 3 = 0x12 -> 0x412 = 1042 */
    assert_true(v[3] == 1042.0);
    /* e, Motorola signed 8 at bit 15 = byte 1 = 0xFC = -4 -> -4 * 0.5 + 10 = 8 */
    assert_true(v[4] == 8.0);
    /* f, float32 little-endian in bytes 4..7: 0x3FC00000 = 1.5 */
    assert_true(v[5] == 1.5);

    /* Short frame: only signals that fit decode; the rest are marked. */
    assert_int_equal(pb_dbc_decode(m, data, 2, v, NULL, pr), 3); /* a, c, e */
    assert_int_equal(pr[0], PB_DBC_PRESENT);
    assert_int_equal(pr[1], PB_DBC_SHORT);
    assert_int_equal(pr[3], PB_DBC_SHORT);

    /* double, 64-bit signal of an extended message: 2.5 = 0x4004000000000000 */
    const pb_dbc_message *x = pb_dbc_find(d, 0x1FF, 1);
    assert_non_null(x);
    assert_true(x->extended);
    const uint8_t dd[8] = {0, 0, 0, 0, 0, 0, 0x04, 0x40};
    assert_int_equal(pb_dbc_decode(x, dd, 8, v, NULL, pr), 1);
    assert_true(v[0] == 2.5);
    pb_dbc_free(d);
}

static pb_dbc *load_data(const char *rel)
{
    const char *dir = getenv("POSE_DATA_DIR");
    assert_non_null(dir);
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    pb_dbc *d = NULL;
    pb_dbc_error e;
    if (pb_dbc_load(path, &d, &e) != 0)
        fail_msg("%s", e.message);
    return d;
}

static void test_cantools_files(void **state)
{
    (void)state;
    /* padding_bit_order.dbc: 64-bit Motorola and Intel over 01..08 */
    pb_dbc *d = load_data("can/cantools-dbc/padding_bit_order.dbc");
    const uint8_t seq[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    uint64_t raw;
    const pb_dbc_message *m3 = pb_dbc_find(d, 4, 0), *m4 = pb_dbc_find(d, 5, 0), *m0 = pb_dbc_find(d, 1, 0);
    assert_true(pb_dbc_extract_raw(&m3->signals[0], seq, 8, &raw));
    assert_true(raw == 0x0102030405060708ull);
    assert_true(pb_dbc_extract_raw(&m4->signals[0], seq, 8, &raw));
    assert_true(raw == 0x0807060504030201ull);
    /* MSG0 A: 6|15@0+ -> MSB byte0 bit6: byte0 bits 6..0 (0x01 & 0x7f = 1) then byte1 (0x02): 1<<8 | 2 = 258 */
    assert_true(pb_dbc_extract_raw(&m0->signals[0], seq, 8, &raw));
    assert_int_equal(raw, 258);
    /* B: 7|1@0+ -> byte0 bit 7 of 0x01 = 0 */
    assert_true(pb_dbc_extract_raw(&m0->signals[1], seq, 8, &raw));
    assert_int_equal(raw, 0);
    pb_dbc_free(d);

    /* signed.dbc: all-ones frames are -1 for every signed width, 64-bit included. */
    d = load_data("can/cantools-dbc/signed.dbc");
    const uint8_t ones[8] = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
    for (size_t i = 0; i < d->message_count; i++) {
        const pb_dbc_message *m = &d->messages[i];
        double v[16];
        uint8_t pr[16];
        assert_int_equal(pb_dbc_decode(m, ones, 8, v, NULL, pr), m->signal_count);
        for (size_t j = 0; j < m->signal_count; j++)
            if (v[j] != -1.0)
                fail_msg("%s.%s = %g, expected -1", m->name, m->signals[j].name, v[j]);
    }
    /* Message378910 s7big 62|7@0-: byte 7 bits 6..0; 0x40 there is the sign bit -> -64 */
    const pb_dbc_message *m = pb_dbc_find(d, 10, 0);
    int si = pb_dbc_find_signal(d, "Message378910", "s7big", NULL);
    assert_true(si >= 0);
    const uint8_t s7[8] = {0, 0, 0, 0, 0, 0, 0, 0x40};
    assert_true(pb_dbc_extract_raw(&m->signals[si], s7, 8, &raw));
    assert_true(pb_dbc_physical(&m->signals[si], raw) == -64.0);
    pb_dbc_free(d);

    /* motohawk.dbc: Temperature 0|12@0- (0.01,250): MSB byte0 bit0, then byte1, then byte2 bits 7..5.
     * bytes C0 06 E0: bit0 of 0xC0 = 0, 0x06, top 3 bits of 0xE0 = 7 -> 0 000 0011 0111 = 0x037 = 55 -> 250.55 */
    d = load_data("can/cantools-dbc/motohawk.dbc");
    m = pb_dbc_find(d, 496, 0);
    const uint8_t mh[8] = {0xC0, 0x06, 0xE0, 0, 0, 0, 0, 0};
    double v[3];
    uint8_t pr[3];
    assert_int_equal(pb_dbc_decode(m, mh, 8, v, NULL, pr), 3);
    assert_true(fabs(v[0] - 250.55) < 1e-9);
    /* AverageRadius 6|6@0+ (0.1): byte0 bits 6..1 of 0xC0 = 0b100000 = 32 -> 3.2; Enable 7|1 = 1 */
    assert_true(fabs(v[1] - 3.2) < 1e-9);
    assert_true(v[2] == 1.0);
    assert_string_equal(pb_dbc_choice_text(&m->signals[2], 1), "Enabled");
    pb_dbc_free(d);

    /* choices.dbc: a negative VAL_ entry and non-ASCII text load. */
    d = load_data("can/cantools-dbc/choices.dbc");
    assert_string_equal(pb_dbc_choice_text(&d->messages[0].signals[0], -5), "A negative value");
    pb_dbc_free(d);
}

static void test_multiplexing(void **state)
{
    (void)state;
    pb_dbc *d = load_data("can/cantools-dbc/multiplex.dbc");
    const pb_dbc_message *m = pb_dbc_find(d, 0x123456, 1);
    assert_non_null(m);
    int mux = pb_dbc_find_signal(d, "Message1", "Multiplexor", NULL);
    int bit_j = pb_dbc_find_signal(d, "Message1", "BIT_J", NULL);
    int bit_a = pb_dbc_find_signal(d, "Message1", "BIT_A", NULL);
    int bit_l = pb_dbc_find_signal(d, "Message1", "BIT_L", NULL);
    assert_true(mux >= 0 && bit_j >= 0 && bit_a >= 0 && bit_l >= 0);
    double v[12];
    uint8_t pr[12];
    /* Multiplexor 2|6 = 8 -> byte0 = 8 << 2 = 0x20; BIT_J at bit 18 = byte2 bit2 */
    uint8_t f[8] = {0x20, 0, 0x04, 0, 0, 0, 0, 0};
    pb_dbc_decode(m, f, 8, v, NULL, pr);
    assert_true(v[mux] == 8.0);
    assert_int_equal(pr[bit_j], PB_DBC_PRESENT);
    assert_true(v[bit_j] == 1.0);
    assert_int_equal(pr[bit_a], PB_DBC_MUX_OFF); /* m24 */
    assert_int_equal(pr[bit_l], PB_DBC_PRESENT); /* SG_MUL_VAL_ 8-8, 16-16, 24-24 */
    /* Multiplexor 24 -> byte0 = 0x60: BIT_A (m24) and the SG_MUL_VAL_ signals present */
    f[0] = 0x60;
    f[3] = 0x04; /* BIT_A at bit 26 = byte3 bit2 */
    pb_dbc_decode(m, f, 8, v, NULL, pr);
    assert_int_equal(pr[bit_a], PB_DBC_PRESENT);
    assert_true(v[bit_a] == 1.0);
    assert_int_equal(pr[bit_l], PB_DBC_PRESENT);
    /* 9 selects nothing multiplexed */
    f[0] = 9 << 2;
    assert_int_equal(pb_dbc_decode(m, f, 8, v, NULL, pr), 1);
    pb_dbc_free(d);

    /* Nested extended multiplexing: c is selected by b = 2, which is selected by a = 1. */
    d = parse_ok("BO_ 7 M: 8 N\n"
                 " SG_ a M : 0|4@1+ (1,0) [0|0] \"\" N\n"
                 " SG_ b m1M : 4|4@1+ (1,0) [0|0] \"\" N\n"
                 " SG_ c m2 : 8|8@1+ (1,0) [0|0] \"\" N\n"
                 "SG_MUL_VAL_ 7 b a 1-1;\nSG_MUL_VAL_ 7 c b 2-3;\n");
    m = &d->messages[0];
    const uint8_t on[8] = {0x21, 0x55}, off[8] = {0x22, 0x55}, out_of[8] = {0x41, 0x55};
    assert_int_equal(pb_dbc_decode(m, on, 8, v, NULL, pr), 3);
    assert_true(v[2] == 0x55);
    assert_int_equal(pb_dbc_decode(m, off, 8, v, NULL, pr), 1); /* a = 2: b and c off */
    assert_int_equal(pb_dbc_decode(m, out_of, 8, v, NULL, pr), 2); /* b = 4: c off */
    pb_dbc_free(d);
}

static void test_rig_dbc(void **state)
{
    (void)state;
    pb_dbc *d = load_data("can-rig/goniometer_rig.dbc");
    assert_int_equal(d->message_count, 13);
    assert_int_equal(d->warning_count, 0);
    const pb_dbc_message *knee_r = pb_dbc_find(d, 0x10C, 0);
    assert_int_equal(knee_r->cycle_ms, 5);
    /* KNEE_R flex 5|14@0- (0.02): -1 raw = all ones: byte0 bits 5..0 and byte1 bits 7..0 */
    const uint8_t ones[8] = {0x3F, 0xFF, 0, 0, 0, 0, 0, 0};
    double v[4];
    uint8_t pr[4];
    pb_dbc_decode(knee_r, ones, 8, v, NULL, pr);
    assert_true(fabs(v[0] - -0.02) < 1e-12);
    /* KNEE_L flex 4|14@1- (0.02): raw 4500 = 0x1194 -> bits 4..17: 0x11940 -> 40 19 01 -> 90.00 deg */
    const uint8_t k[8] = {0x40, 0x19, 0x01, 0, 0, 0, 0, 0};
    pb_dbc_decode(pb_dbc_find(d, 0x10B, 0), k, 8, v, NULL, pr);
    assert_true(fabs(v[0] - 90.0) < 1e-9);
    /* RIG_STATUS: page 1 (extended multiplexing) shows node_errors and uptime, not supply */
    const pb_dbc_message *st = pb_dbc_find(d, 0xF0, 0);
    const uint8_t p1[8] = {0x01, 0x00, 0x04, 0xE8, 0x03, 0, 0};
    double sv[5];
    uint8_t sp[5];
    assert_int_equal(pb_dbc_decode(st, p1, 8, sv, NULL, sp), 3);
    assert_int_equal(sp[1], PB_DBC_MUX_OFF);
    assert_true(sv[3] == 0x400);
    assert_true(fabs(sv[4] - 1.0) < 1e-12); /* 0x3E8 = 1000 ms */
    pb_dbc_free(d);
}

/* VECTOR__INDEPENDENT_SIG_MSG, CANdb++'s holder of signals that belong to no
 * message: cantools drops it by name before building messages
 * (formats/dbc.py, _load_messages), so nothing in it is checked beyond the
 * grammar; repeated signal names there load. Here: dropped too, each repeat
 * a warning naming file and line; references to its identifier are quiet. */
static void test_pseudo_message(void **state)
{
    (void)state;
    pb_warnings w = {0};
    pb_warnings *prev = pb_warnings_install(&w);

    /* The real file of cantools issue 62 (a J1939 export): only the pseudo-message,
     * 18 signals, no repeats. cantools loads it with no message at all. */
    pb_dbc *d = load_data("can/cantools-dbc/issue_62.dbc");
    assert_int_equal(d->message_count, 0);
    assert_int_equal(d->warning_count, 0);
    assert_int_equal(w.count, 0);
    assert_null(pb_dbc_find(d, 0x40000000, 1));
    assert_null(pb_dbc_find(d, 0, 1));
    pb_dbc_free(d);

    /* Repeated names, as CANdb++ writes them when messages holding same-named
     * signals are deleted, around a real message. */
    static const char text[] =
        "VERSION \"\"\n"                                                            /* 1 */
        "BU_: ECU\n"                                                                 /* 2 */
        "BO_ 3221225472 VECTOR__INDEPENDENT_SIG_MSG: 0 Vector__XXX\n"                /* 3 */
        " SG_ Checksum : 0|8@1+ (1,0) [0|0] \"\" Vector__XXX\n"                     /* 4 */
        " SG_ Counter : 0|4@1+ (1,0) [0|15] \"\" Vector__XXX\n"                     /* 5 */
        " SG_ Checksum : 0|8@0+ (1,0) [0|255] \"\" Vector__XXX\n"                   /* 6 */
        " SG_ Counter : 0|4@1+ (1,0) [0|15] \"\" Vector__XXX\n"                     /* 7 */
        " SG_ Spare : 0|32@1- (1,0) [0|0] \"\" Vector__XXX\n"                       /* 8 */
        "\n"                                                                         /* 9 */
        "BO_ 291 Status: 2 ECU\n"                                                    /* 10 */
        " SG_ Counter : 0|4@1+ (1,0) [0|15] \"\" Vector__XXX\n"                     /* 11 */
        " SG_ Checksum : 8|8@1+ (1,0) [0|255] \"\" Vector__XXX\n"                   /* 12 */
        "CM_ BO_ 3221225472 \"This is a message for not used signals, created by Vector CANdb++ DBC OLE DB "
        "Provider.\";\n"                                                            /* 13 */
        "VAL_ 3221225472 Counter 0 \"zero\" ;\n"                                     /* 14 */
        "SIG_VALTYPE_ 3221225472 Spare : 2;\n"                                       /* 15: 32 bits as double */
        "BA_ \"GenMsgCycleTime\" BO_ 3221225472 100;\n"                               /* 16 */
        "VAL_ 291 Counter 15 \"max\" ;\n";                                           /* 17 */
    d = parse_ok(text);
    assert_int_equal(d->message_count, 1);
    const pb_dbc_message *m = pb_dbc_find(d, 291, 0);
    assert_non_null(m);
    assert_string_equal(m->name, "Status");
    assert_int_equal(m->signal_count, 2);
    assert_string_equal(m->signals[1].name, "Checksum");
    assert_int_equal(m->signals[1].start, 8);
    assert_int_equal(m->signals[0].choice_count, 1);
    assert_int_equal(d->warning_count, 2);
    assert_string_equal(d->warning, "inline.dbc:6: signal Checksum repeats in VECTOR__INDEPENDENT_SIG_MSG (first at "
                                    "line 4); that pseudo-message of signals in no message is skipped, as cantools "
                                    "skips it");
    assert_int_equal(w.count, 2);
    assert_string_equal(w.text[0], d->warning);
    assert_non_null(strstr(w.text[1], "inline.dbc:7: signal Counter repeats in VECTOR__INDEPENDENT_SIG_MSG (first at "
                                      "line 5)"));
    const uint8_t f[2] = {0x0A, 0x5C};
    double v[2];
    uint8_t pr[2];
    assert_int_equal(pb_dbc_decode(m, f, 2, v, NULL, pr), 2);
    assert_true(v[0] == 10.0 && v[1] == 0x5C);
    pb_dbc_free(d);

    /* Its SG_ lines must still be well formed (cantools' grammar parses them). */
    parse_fails("BO_ 3221225472 VECTOR__INDEPENDENT_SIG_MSG: 0 Vector__XXX\n"
                " SG_ a : 0|8@1* (1,0) [0|0] \"\" Vector__XXX\n",
                2, "'+' or '-'");
    /* Any other identifier beyond 29 bits is refused, as cantools' Message refuses it. */
    parse_fails("BO_ 3221225473 Other: 8 N\n", 1, "exceeds 29 bits");
    parse_fails("BO_ 1073741824 Other: 8 N\n", 1, "exceeds 29 bits");
    /* Repeats in a real message stay an error. */
    parse_fails("BO_ 1 M: 8 N\n SG_ a : 0|8@1+ (1,0) [0|0] \"\" N\n SG_ a : 8|8@1+ (1,0) [0|0] \"\" N\n", 3,
                "defined twice");
    pb_warnings_install(prev);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_malformed),
        cmocka_unit_test(test_hand_checked),
        cmocka_unit_test(test_cantools_files),
        cmocka_unit_test(test_multiplexing),
        cmocka_unit_test(test_rig_dbc),
        cmocka_unit_test(test_pseudo_message),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
