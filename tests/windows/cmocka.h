/* SPDX-License-Identifier: Apache-2.0 */
/* The part of cmocka's API the runtime tests use, for the Windows stage:
 * Debian ships no mingw-w64 cmocka. A failed assertion reports where and
 * jumps back to the runner, which goes on with the next test; the group's
 * result is the number of failed tests, as with cmocka (cmocka.c). */
#ifndef POSE_WINDOWS_CMOCKA_H
#define POSE_WINDOWS_CMOCKA_H

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

typedef void (*CMUnitTestFunction)(void **state);
typedef int (*CMFixtureFunction)(void **state);

struct CMUnitTest {
    const char *name;
    CMUnitTestFunction test_func;
};

#define cmocka_unit_test(f) {#f, f}

extern jmp_buf cm_jump; /* where a failed assertion returns to (cmocka.c) */

void print_message(const char *fmt, ...) __attribute__((format(gnu_printf, 1, 2)));
void print_error(const char *fmt, ...) __attribute__((format(gnu_printf, 1, 2)));
int cm_run_group(const char *group, const struct CMUnitTest *tests, size_t n,
                 CMFixtureFunction setup, CMFixtureFunction teardown);

#define cm_fail_here(...)                                                                  \
    do {                                                                                   \
        printf("%s:%d: error: ", __FILE__, __LINE__);                                      \
        printf(__VA_ARGS__);                                                               \
        printf("\n");                                                                      \
        longjmp(cm_jump, 1);                                                               \
    } while (0)

#define fail_msg(...) cm_fail_here(__VA_ARGS__)
#define fail() cm_fail_here("fail()")
#define skip() longjmp(cm_jump, 2)
#define assert_true(c)                                                                     \
    do {                                                                                   \
        if (!(c))                                                                          \
            cm_fail_here("%s is not true", #c);                                            \
    } while (0)
#define assert_false(c) assert_true(!(c))
#define assert_non_null(p) assert_true((p) != NULL)
#define assert_null(p) assert_true((p) == NULL)
#define assert_int_equal(a, b)                                                             \
    do {                                                                                   \
        intmax_t cm_a = (intmax_t)(a), cm_b = (intmax_t)(b);                               \
        if (cm_a != cm_b)                                                                  \
            cm_fail_here("%jd != %jd (%s, %s)", cm_a, cm_b, #a, #b);                       \
    } while (0)
#define assert_int_not_equal(a, b) assert_true((intmax_t)(a) != (intmax_t)(b))
#define assert_float_equal(a, b, eps)                                                      \
    do {                                                                                   \
        double cm_a = (double)(a), cm_b = (double)(b);                                     \
        if (!(fabs(cm_a - cm_b) <= (double)(eps)))                                         \
            cm_fail_here("%g != %g (%s, %s)", cm_a, cm_b, #a, #b);                         \
    } while (0)
#define assert_memory_equal(a, b, n) assert_true(memcmp((a), (b), (n)) == 0)
#define assert_string_equal(a, b)                                                          \
    do {                                                                                   \
        const char *cm_a = (a), *cm_b = (b);                                               \
        if (strcmp(cm_a, cm_b) != 0)                                                       \
            cm_fail_here("\"%s\" != \"%s\"", cm_a, cm_b);                                  \
    } while (0)
#define assert_string_not_equal(a, b) assert_true(strcmp((a), (b)) != 0)

#define cmocka_run_group_tests(tests, setup, teardown)                                     \
    cm_run_group(#tests, tests, sizeof(tests) / sizeof((tests)[0]), setup, teardown)

#endif /* POSE_WINDOWS_CMOCKA_H */
