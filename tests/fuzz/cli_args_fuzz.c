/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for the tools' option parser (cli/pose_cli.c over
 * getopt_long): the input is a command line, arguments separated by NUL
 * bytes, parsed against an option table with every kind of option. Every
 * value handed out must be one of the command line's words (or the part of
 * one after '='), numbers go through the range checks, and parsing ends. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pose_cli.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

enum { MAX_ARGS = 64 };

/* libFuzzer only: the parser's messages to a sink. The FILE is replaced, not
 * descriptor 2, so sanitizer and libFuzzer reports still reach the log. */
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    FILE *null = fopen("/dev/null", "w");
    if (null)
        stderr = null;
    return 0;
}

static int from_line(const char *v, char *const *words, int n)
{
    for (int i = 0; i < n; i++)
        if (v >= words[i] && v <= words[i] + strlen(words[i]))
            return 1;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const struct option opts[] = {
        {"map", required_argument, NULL, 'm'},      {"output", required_argument, NULL, 'o'},
        {"json", no_argument, NULL, 'j'},           {"help", no_argument, NULL, 'h'},
        {"frames", required_argument, NULL, 256},   {"speed", required_argument, NULL, 257},
        {"level", optional_argument, NULL, 258},    {"frame-rate", required_argument, NULL, 259},
        {0, 0, 0, 0}};
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    char *argv[MAX_ARGS + 2], *words[MAX_ARGS + 1];
    int argc = 0;
    argv[argc++] = "fuzz";
    for (char *p = text; p <= text + size && argc <= MAX_ARGS; p += strlen(p) + 1)
        argv[argc++] = p;
    argv[argc] = NULL;
    memcpy(words, argv, sizeof *argv * (size_t)argc); /* getopt_long permutes argv */
    pose_cli cli;
    pose_cli_begin(&cli, "fuzz", argc, argv, opts);
    /* Each step takes a word, or a letter of a cluster of flags ("-jjj"). */
    size_t steps = 0, most = (size_t)argc;
    for (int i = 0; i < argc; i++)
        most += strlen(words[i]);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END && c != POSE_CLI_ERROR;) {
        if (++steps > most)
            abort();
        if (cli.value && !from_line(cli.value, words, argc))
            abort();
        long l;
        double d;
        switch (c) {
        case 'm':
        case 'o':
        case POSE_CLI_ARGUMENT:
            if (!cli.value)
                abort();
            break;
        case 256:
            (void)pose_cli_long(&cli, 0, 1000000, &l);
            break;
        case 257:
        case 259:
            (void)pose_cli_double(&cli, 1e-3, 1e3, &d);
            break;
        default:
            break;
        }
    }
    free(text);
    return 0;
}
