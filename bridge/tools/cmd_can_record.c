/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge can-record: everything a SocketCAN interface receives, error
 * frames included, written as a candump -l log (readable by candump's
 * tools, by can-decode and by the replay source). */
#define _GNU_SOURCE 1 /* sigaction */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "can_rx.h"
#include "can_source.h"
#include "candump_log.h"
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
    pb_can_rx rx;
    pb_can_rx_init(&rx, fd);
    const int progress = isatty(STDERR_FILENO);
    const int64_t start = pb_can_mono_ns();
    int64_t next_report = start + 1000000000;
    unsigned long long frames = 0, drops = 0;
    int status = 0;
    while (!stop) {
        const int64_t now = pb_can_mono_ns();
        if (seconds > 0 && now - start >= (int64_t)(seconds * 1e9))
            break;
        if (progress && now >= next_report) {
            fprintf(stderr, "\rpose-bridge can-record: %llu frames, %llu dropped, %.0f s", frames, drops,
                    (now - start) * 1e-9);
            next_report += 1000000000;
        }
        pb_can_frame fr;
        int64_t real;
        uint64_t d;
        int r = pb_can_rx_read(&rx, &fr, &real, &d, 200);
        drops += d;
        if (r == 1) {
            char line[PB_CANDUMP_LINE_MAX];
            fr.t_ns = real;
            int n = pb_candump_format(&fr, iface, line, sizeof line);
            if (n > 0 && fwrite(line, 1, (size_t)n, f) != (size_t)n) {
                fprintf(stderr, "pose-bridge can-record: write failed: %s\n", strerror(errno));
                status = 1;
                break;
            }
            if (count && ++frames >= count)
                break;
            if (!count)
                frames++;
        } else if (r == -1) {
            if (errno == EINTR)
                continue;
            fprintf(stderr, "pose-bridge can-record: %s: %s\n", iface, strerror(errno));
            status = 1;
            break;
        }
    }
    if (progress)
        fputc('\n', stderr);
    fprintf(stderr, "pose-bridge can-record: %llu frames, %llu dropped by the kernel\n", frames, drops);
    if (out && fclose(f) != 0)
        status = 1;
    else if (!out)
        fflush(stdout);
    close(fd);
    return status;
}

const pb_command pb_cmd_can_record = {"can-record", "record a SocketCAN interface to a candump -l log", run};
