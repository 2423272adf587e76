/* SPDX-License-Identifier: Apache-2.0 */
/* The runner of the Windows stage's cmocka subset (cmocka.h). */
#include <stddef.h>

#include "cmocka.h"

jmp_buf cm_jump;

void print_message(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
}

void print_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
}

int cm_run_group(const char *group, const struct CMUnitTest *tests, size_t n,
                 CMFixtureFunction setup, CMFixtureFunction teardown)
{
    void *state = NULL;
    if (setup && setup(&state) != 0) {
        printf("[  ERROR   ] %s: group setup failed\n", group);
        return 1;
    }
    int failed = 0;
    for (size_t i = 0; i < n; i++) {
        printf("[ RUN      ] %s\n", tests[i].name);
        fflush(stdout);
        void *test_state = state;
        switch (setjmp(cm_jump)) {
        case 0:
            tests[i].test_func(&test_state);
            printf("[       OK ] %s\n", tests[i].name);
            break;
        case 2:
            printf("[  SKIPPED ] %s\n", tests[i].name);
            break;
        default:
            printf("[  FAILED  ] %s\n", tests[i].name);
            failed++;
        }
        fflush(stdout);
    }
    if (teardown)
        teardown(&state);
    printf("[==========] %s: %zu test(s), %d failed\n", group, n, failed);
    return failed;
}
