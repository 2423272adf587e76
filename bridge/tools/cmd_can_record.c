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

static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
    (void)sig;
    stop = 1;
}

static void help(FILE *f)
{
    fprintf(f, "usage: pose-bridge can-record IFACE [-o FILE.log] [--seconds S] [--count N]\n"
               "  IFACE        SocketCAN interface (can0, vcan0 ...)\n"
               "  -o FILE      write the log there (default: standard output)\n"
               "  --seconds S  stop after S seconds;  --count N: after N frames\n"
               "Records until Ctrl-C otherwise. Time stamps are the kernel's receive times\n"
               "(wall clock, as candump -l writes them). A count goes to stderr every second\n"
               "when stderr is a terminal.\n");
}

static int run(int argc, char **argv)
{
    if (pb_cli_wants_help(argc, argv)) {
        help(stdout);
        return 0;
    }
    const char *iface = NULL, *out = NULL;
    double seconds = 0;
    unsigned long long count = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "-o") == 0 && i + 1 < argc)
            out = argv[++i];
        else if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc)
            seconds = atof(argv[++i]);
        else if (strcmp(argv[i], "--count") == 0 && i + 1 < argc)
            count = strtoull(argv[++i], NULL, 10);
        else if (argv[i][0] != '-' && !iface)
            iface = argv[i];
        else {
            fprintf(stderr, "pose-bridge can-record: unexpected argument '%s'\n", argv[i]);
            help(stderr);
            return 2;
        }
    }
    if (!iface) {
        help(stderr);
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
    else if (!out)
        fflush(stdout);
    close(fd);
    return status;
}

const pb_command pb_cmd_can_record = {"can-record", "record a SocketCAN interface to a candump -l log", run};
