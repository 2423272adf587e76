/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge can-record: everything a SocketCAN interface receives, error
 * frames included, written as a candump -l log (readable by candump's
 * tools, by can-decode and by the replay source), flushed per frame. */
#define _GNU_SOURCE 1 /* sigaction */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "can_record.h"
#include "can_source.h"
#include "pose_bridge_cli.h"
#include "pose_cli.h"

static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
    (void)sig;
    stop = 1;
}

static void help(FILE *f)
{
    fprintf(f, "usage: pose-bridge can-record IFACE [-o FILE.log] [--seconds S] [--count N] [--json]\n"
               "  IFACE        SocketCAN interface (can0, vcan0 ...)\n"
               "  -o, --output FILE  write the log there (default: standard output)\n"
               "  --seconds S  stop after S seconds;  --count N: after N frames\n"
               "  --json       at the end, {\"interface\",\"file\",\"frames\",\"kernel_drops\",\"ok\"} on\n"
               "               standard output (needs -o)\n"
               "Records until Ctrl-C otherwise. Time stamps are the kernel's receive times\n"
               "(wall clock, as candump -l writes them). A count goes to stderr every second\n"
               "when stderr is a terminal.\n");
}

static int run(int argc, char **argv)
{
    enum { OPT_SECONDS = POSE_CLI_LONG_ONLY, OPT_COUNT, OPT_JSON };
    static const struct option options[] = {
        {"output", required_argument, NULL, 'o'}, {"seconds", required_argument, NULL, OPT_SECONDS},
        {"count", required_argument, NULL, OPT_COUNT}, {"json", no_argument, NULL, OPT_JSON},
        {"help", no_argument, NULL, 'h'},       {0}};
    const char *iface = NULL, *out = NULL;
    double seconds = 0;
    unsigned long long count = 0;
    int json = 0;
    long n;
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge can-record", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            help(stdout);
            return 0;
        case 'o':
            out = cli.value;
            break;
        case OPT_SECONDS:
            if (pose_cli_double(&cli, 0, 1e9, &seconds) < 0)
                return 2;
            break;
        case OPT_COUNT:
            if (pose_cli_long(&cli, 0, 1000000000000L, &n) < 0)
                return 2;
            count = (unsigned long long)n;
            break;
        case OPT_JSON:
            json = 1;
            break;
        case POSE_CLI_ARGUMENT:
            if (iface) {
                pose_cli_error(&cli, "unexpected argument '%s' (one interface only)", cli.value);
                return 2;
            }
            iface = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    if (!iface) {
        pose_cli_error(&cli, "no interface given");
        return 2;
    }
    if (json && !out) { /* the log itself goes to standard output then */
        pose_cli_error(&cli, "--json needs -o FILE");
        return 2;
    }
    pb_error err;
    int fd = pb_can_socket_open(iface, NULL, 0, &err);
    if (fd < 0) {
        fprintf(stderr, "pose-bridge can-record: %s\n", err.message);
        return 1;
    }
    FILE *f = out ? fopen(out, "w") : stdout;
    if (!f) {
        fprintf(stderr, "pose-bridge can-record: %s: %s\n", out, strerror(errno));
        close(fd);
        return 1;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    const pb_can_record_options ro = {
        .seconds = seconds, .count = count, .stop = &stop, .progress = isatty(STDERR_FILENO)};
    pb_can_record_result res;
    int status = 0;
    if (pb_can_record_run(fd, iface, f, &ro, &res, &err) != 0) {
        fprintf(stderr, "pose-bridge can-record: %s\n", err.message);
        status = 1;
    }
    if (ro.progress)
        fputc('\n', stderr);
    fprintf(stderr, "pose-bridge can-record: %llu frames, %llu dropped by the kernel\n", res.frames, res.drops);
    if (out && fclose(f) != 0)
        status = 1;
    if (json) {
        printf("{\"interface\":");
        pb_cli_json_string(stdout, iface);
        printf(",\"file\":");
        pb_cli_json_string(stdout, out);
        printf(",\"frames\":%llu,\"kernel_drops\":%llu,\"ok\":%s}\n", res.frames, res.drops,
               status == 0 ? "true" : "false");
    }
    else if (!out)
        fflush(stdout);
    close(fd);
    return status;
}

const pb_command pb_cmd_can_record = {"can-record", "record a SocketCAN interface to a candump -l log", run};
