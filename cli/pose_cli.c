/* SPDX-License-Identifier: Apache-2.0 */
#include "pose_cli.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void pose_cli_begin(pose_cli *cli, const char *tool, int argc, char **argv, const struct option *options)
{
    memset(cli, 0, sizeof *cli);
    cli->tool = tool;
    cli->argc = argc;
    cli->argv = argv;
    cli->options = options;
    /* '-': arguments come back in order (as 1) instead of being permuted to the
     * end; ':': a missing value is told apart from an unknown option. */
    size_t n = 0;
    cli->shorts[n++] = '-';
    cli->shorts[n++] = ':';
    for (const struct option *o = options; o->name && n + 3 < sizeof cli->shorts; o++) {
        if (o->flag || o->val <= 0 || o->val >= 128 || !isalnum(o->val))
            continue;
        cli->shorts[n++] = (char)o->val;
        if (o->has_arg != no_argument)
            cli->shorts[n++] = ':';
        if (o->has_arg == optional_argument)
            cli->shorts[n++] = ':';
    }
    cli->shorts[n] = '\0';
    optind = 0; /* glibc: start afresh, also after another parse in this process */
    opterr = 0; /* the messages are ours */
}

int pose_cli_error(const pose_cli *cli, const char *format, ...)
{
    va_list ap;
    va_start(ap, format);
    fprintf(stderr, "%s: ", cli->tool);
    vfprintf(stderr, format, ap);
    fprintf(stderr, " (see %s --help)\n", cli->tool);
    va_end(ap);
    return POSE_CLI_ERROR;
}

/* The long option `typed` ("--name" or "--name=value") names exactly, or NULL. */
static const struct option *find_exact(const pose_cli *cli, const char *typed)
{
    if (strncmp(typed, "--", 2) != 0)
        return NULL;
    typed += 2;
    size_t len = strcspn(typed, "=");
    for (const struct option *o = cli->options; o->name; o++)
        if (strlen(o->name) == len && strncmp(o->name, typed, len) == 0)
            return o;
    return NULL;
}

/* An unknown long option; the options it begins, as a hint. Abbreviations are
 * refused rather than taken (as getopt_long would), so a script's --fr does
 * not change meaning when a tool gains --frame-rate beside --frames. */
static int report_long(const pose_cli *cli, const char *typed)
{
    size_t len = strcspn(typed + 2, "=");
    char matches[256] = "";
    int count = 0;
    for (const struct option *o = cli->options; o->name && len > 0; o++)
        if (strncmp(o->name, typed + 2, len) == 0) {
            size_t used = strlen(matches);
            snprintf(matches + used, sizeof matches - used, "%s--%s", count ? " or " : "", o->name);
            count++;
        }
    if (count > 0)
        return pose_cli_error(cli, "unknown option '%.*s' (did you mean %s?)", (int)len + 2, typed, matches);
    return pose_cli_error(cli, "unknown option '%.*s'", (int)len + 2, typed);
}

int pose_cli_next(pose_cli *cli)
{
    cli->value = NULL;
    cli->name[0] = '\0';
    if (cli->after_dashes) {
        if (optind >= cli->argc)
            return POSE_CLI_END;
        cli->value = cli->argv[optind++];
        return POSE_CLI_ARGUMENT;
    }
    int index = -1;
    int c = getopt_long(cli->argc, cli->argv, cli->shorts, cli->options, &index);
    const char *typed = optind > 0 && optind <= cli->argc ? cli->argv[optind - 1] : "";
    switch (c) {
    case -1: /* the end, or "--": everything after it is an argument */
        if (optind >= cli->argc)
            return POSE_CLI_END;
        cli->after_dashes = 1;
        return pose_cli_next(cli);
    case 1:
        cli->value = optarg;
        return POSE_CLI_ARGUMENT;
    case ':':
        if (strncmp(typed, "--", 2) == 0)
            snprintf(cli->name, sizeof cli->name, "%s", typed);
        else
            snprintf(cli->name, sizeof cli->name, "-%c", optopt);
        return pose_cli_error(cli, "%s needs a value", cli->name);
    case '?':
        if (strncmp(typed, "--", 2) == 0 && typed[2]) {
            const struct option *o = find_exact(cli, typed);
            if (o && o->has_arg == no_argument && strchr(typed, '='))
                return pose_cli_error(cli, "--%s takes no value", o->name);
            return report_long(cli, typed);
        }
        return pose_cli_error(cli, "unknown option '-%c'", optopt ? optopt : '?');
    default:
        break;
    }
    if (index >= 0) {
        /* The option's own word: before its value when that came separately. */
        const char *word = optarg && optind >= 2 && optarg == cli->argv[optind - 1] ? cli->argv[optind - 2] : typed;
        if (find_exact(cli, word) != &cli->options[index])
            return report_long(cli, word);
        snprintf(cli->name, sizeof cli->name, "--%s", cli->options[index].name);
    } else
        snprintf(cli->name, sizeof cli->name, "-%c", c);
    cli->value = optarg;
    /* "--map --json": getopt_long would take --json as the map's file name. */
    if (cli->value && find_exact(cli, cli->value))
        return pose_cli_error(cli, "%s needs a value (got the option %s)", cli->name, cli->value);
    return c;
}

int pose_cli_long(const pose_cli *cli, long lo, long hi, long *out)
{
    const char *s = cli->value ? cli->value : "";
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (end == s || *end || errno || v < lo || v > hi) {
        pose_cli_error(cli, "%s: expected an integer in [%ld, %ld], got '%s'", cli->name, lo, hi, s);
        return -1;
    }
    *out = v;
    return 0;
}

int pose_cli_double(const pose_cli *cli, double lo, double hi, double *out)
{
    const char *s = cli->value ? cli->value : "";
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno || !isfinite(v) || v < lo || v > hi) {
        pose_cli_error(cli, "%s: expected a number in [%g, %g], got '%s'", cli->name, lo, hi, s);
        return -1;
    }
    *out = v;
    return 0;
}
