/* SPDX-License-Identifier: Apache-2.0
 * The shared option parser (cli/pose_cli.h): options and arguments in
 * command-line order, both value spellings, "--" and each mistake's wording. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <unistd.h>

#include <cmocka.h>

#include "pose_cli.h"

enum { OPT_RIG = POSE_CLI_LONG_ONLY, OPT_JSON, OPT_FRAMES, OPT_FRAME_RATE };
static const struct option k_options[] = {
    {"rig", required_argument, NULL, OPT_RIG},       {"json", no_argument, NULL, OPT_JSON},
    {"frames", required_argument, NULL, OPT_FRAMES}, {"frame-rate", required_argument, NULL, OPT_FRAME_RATE},
    {"output", required_argument, NULL, 'o'},        {"help", no_argument, NULL, 'h'},
    {0}};

/* stderr of one parse, read back from a scratch file. */
static char g_stderr[1024];

/* Parse argv (NULL-terminated, without argv[0]) to the end or the first error;
 * "code:value" per step into `trace`, space-separated. Returns the last code. */
static int parse(char *trace, size_t size, ...)
{
    char *argv[32] = {"tool"};
    int argc = 1;
    va_list ap;
    va_start(ap, size);
    for (const char *a; (a = va_arg(ap, const char *)) != NULL;)
        argv[argc++] = (char *)a;
    va_end(ap);
    char path[512];
    const char *tmp = getenv("POSE_TEST_TMP");
    snprintf(path, sizeof path, "%s/stderr.txt", tmp ? tmp : ".");
    fflush(stderr);
    int saved = dup(STDERR_FILENO), fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    assert_true(saved >= 0 && fd >= 0);
    dup2(fd, STDERR_FILENO);
    close(fd);
    pose_cli cli;
    pose_cli_begin(&cli, "tool", argc, argv, k_options);
    trace[0] = '\0';
    int c;
    while ((c = pose_cli_next(&cli)) != POSE_CLI_END && c != POSE_CLI_ERROR) {
        size_t used = strlen(trace);
        snprintf(trace + used, size - used, "%s%d:%s", used ? " " : "", c, cli.value ? cli.value : "-");
    }
    fflush(stderr);
    dup2(saved, STDERR_FILENO);
    close(saved);
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(g_stderr, 1, sizeof g_stderr - 1, f) : 0;
    g_stderr[n] = '\0';
    if (f)
        fclose(f);
    return c;
}

static void test_order_and_values(void **state)
{
    (void)state;
    char t[512];
    assert_int_equal(parse(t, sizeof t, "a.rig", "--rig=r", "--json", "b", "-o", "out", "--frames", "-3", NULL),
                     POSE_CLI_END);
    /* Arguments keep their place; "-3" is a value, not an option. */
    assert_string_equal(t, "1:a.rig 256:r 257:- 1:b 111:out 258:-3");
    assert_string_equal(g_stderr, "");
    /* After "--" everything is an argument, options too. */
    assert_int_equal(parse(t, sizeof t, "--json", "--", "--rig", "-o", NULL), POSE_CLI_END);
    assert_string_equal(t, "257:- 1:--rig 1:-o");
}

static void test_mistakes(void **state)
{
    (void)state;
    char t[512];
    assert_int_equal(parse(t, sizeof t, "--nope", NULL), POSE_CLI_ERROR);
    assert_string_equal(g_stderr, "tool: unknown option '--nope' (see tool --help)\n");
    assert_int_equal(parse(t, sizeof t, "-x", NULL), POSE_CLI_ERROR);
    assert_string_equal(g_stderr, "tool: unknown option '-x' (see tool --help)\n");
    assert_int_equal(parse(t, sizeof t, "a.rig", "--rig", NULL), POSE_CLI_ERROR);
    assert_string_equal(t, "1:a.rig");
    assert_string_equal(g_stderr, "tool: --rig needs a value (see tool --help)\n");
    assert_int_equal(parse(t, sizeof t, "-o", NULL), POSE_CLI_ERROR);
    assert_string_equal(g_stderr, "tool: -o needs a value (see tool --help)\n");
    /* getopt_long alone would open a file named "--json". */
    assert_int_equal(parse(t, sizeof t, "--rig", "--json", NULL), POSE_CLI_ERROR);
    assert_string_equal(g_stderr, "tool: --rig needs a value (got the option --json) (see tool --help)\n");
    assert_int_equal(parse(t, sizeof t, "--json=yes", NULL), POSE_CLI_ERROR);
    assert_string_equal(g_stderr, "tool: --json takes no value (see tool --help)\n");
    /* Abbreviations are refused, unique or not. */
    assert_int_equal(parse(t, sizeof t, "--ri", "r", NULL), POSE_CLI_ERROR);
    assert_string_equal(g_stderr, "tool: unknown option '--ri' (did you mean --rig?) (see tool --help)\n");
    assert_int_equal(parse(t, sizeof t, "--fr=1", NULL), POSE_CLI_ERROR);
    assert_string_equal(g_stderr,
                        "tool: unknown option '--fr' (did you mean --frames or --frame-rate?) (see tool --help)\n");
}

static void test_numbers(void **state)
{
    (void)state;
    char *argv[] = {"tool", "--frames", "12", "--frame-rate", "2.5e1", "--frames", "1x", NULL};
    pose_cli cli;
    pose_cli_begin(&cli, "tool", 7, argv, k_options);
    long l = 0;
    double d = 0;
    assert_int_equal(pose_cli_next(&cli), OPT_FRAMES);
    assert_int_equal(pose_cli_long(&cli, 0, 100, &l), 0);
    assert_int_equal(l, 12);
    assert_int_equal(pose_cli_next(&cli), OPT_FRAME_RATE);
    assert_int_equal(pose_cli_double(&cli, 0, 100, &d), 0);
    assert_true(d == 25.0);
    assert_int_equal(pose_cli_double(&cli, 0, 10, &d), -1); /* out of range */
    assert_int_equal(pose_cli_next(&cli), OPT_FRAMES);
    assert_int_equal(pose_cli_long(&cli, 0, 100, &l), -1);
    assert_int_equal(l, 12);
    assert_string_equal(cli.name, "--frames");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_order_and_values),
        cmocka_unit_test(test_mistakes),
        cmocka_unit_test(test_numbers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
