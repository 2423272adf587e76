/* SPDX-License-Identifier: Apache-2.0
 * DBC input that tools accept but that is almost surely wrong, accepted here
 * with a warning naming the file and line (pb_warn): signals sharing bits,
 * a factor of 0, bytes that are not text in a node list. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "dbc_parse.h"
#include "pb_warn.h"

/* Parses text, which must load, and returns its warnings. */
static void parse_warned(const char *text, size_t len, pb_warnings *w)
{
    memset(w, 0, sizeof *w);
    pb_warnings *prev = pb_warnings_install(w);
    pb_dbc *d = NULL;
    pb_dbc_error err;
    const int rc = pb_dbc_parse(text, len, "w.dbc", &d, &err);
    pb_warnings_install(prev);
    if (rc != 0)
        fail_msg("%s", err.message);
    pb_dbc_free(d);
}

static void expect_warning(const pb_warnings *w, const char *fragment)
{
    for (size_t i = 0; i < w->count; i++)
        if (strstr(w->text[i], fragment))
            return;
    fail_msg("no warning with '%s' (%zu warnings%s%s)", fragment, (size_t)w->count, w->count ? ", first: " : "",
             w->count ? w->text[0] : "");
}

static void test_overlapping_signals(void **state)
{
    (void)state;
    static const char dbc[] = "BO_ 256 M: 8 N\n"
                              " SG_ A : 0|12@1+ (1,0) [0|0] \"\" N\n"
                              " SG_ B : 8|8@1+ (1,0) [0|0] \"\" N\n"   /* bits 8..11 are A's */
                              " SG_ C : 16|8@1+ (1,0) [0|0] \"\" N\n"  /* clear */
                              " SG_ D : 31|4@0+ (1,0) [0|0] \"\" N\n"  /* Motorola bits 28..31: clear */
                              " SG_ E : 30|2@1+ (1,0) [0|0] \"\" N\n"  /* Intel bits 30..31: D's */
                              "BO_ 257 X: 8 N\n"
                              " SG_ S M : 0|8@1+ (1,0) [0|0] \"\" N\n"
                              " SG_ P m1 : 8|8@1+ (1,0) [0|0] \"\" N\n"
                              " SG_ Q m2 : 8|8@1+ (1,0) [0|0] \"\" N\n" /* other mux value: fine */
                              " SG_ R m1 : 12|8@1+ (1,0) [0|0] \"\" N\n"; /* same value as P */
    pb_warnings w;
    parse_warned(dbc, sizeof dbc - 1, &w);
    assert_int_equal(w.count, 3);
    expect_warning(&w, "w.dbc:3: signal B overlaps signal A (line 2) in message M");
    expect_warning(&w, "w.dbc:6: signal E overlaps signal D (line 5) in message M");
    expect_warning(&w, "w.dbc:11: signal R overlaps signal P (line 9) in message X");
}

static void test_factor_zero(void **state)
{
    (void)state;
    static const char dbc[] = "BO_ 256 M: 8 N\n SG_ A : 0|8@1+ (0,5) [0|0] \"\" N\n";
    pb_warnings w;
    parse_warned(dbc, sizeof dbc - 1, &w);
    assert_int_equal(w.count, 1);
    expect_warning(&w, "w.dbc:2: signal A has factor 0: it always reads its offset 5");
}

static void test_node_list_bytes(void **state)
{
    (void)state;
    static const char dbc[] = "BU_: N \0 \xFF M\nBO_ 256 M: 8 N\n SG_ A : 0|8@1+ (1,0) [0|0] \"\" N \xFF\n";
    pb_warnings w;
    parse_warned(dbc, sizeof dbc - 1, &w);
    assert_int_equal(w.count, 2);
    expect_warning(&w, "w.dbc:1: byte 0x00 at column 8 is not text");
    expect_warning(&w, "w.dbc:3: byte 0xFF at column");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_overlapping_signals),
        cmocka_unit_test(test_factor_zero),
        cmocka_unit_test(test_node_list_bytes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
