/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge can-monitor: per-node frame rates and states of a CAN bus,
 * live (SocketCAN) or from a candump -l log replayed as the bus, once a
 * second: the view for wiring a rig and finding the node that drops out. */
#define _GNU_SOURCE 1 /* sigaction */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "can_source.h"
#include "canopen_decode.h"
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
    fprintf(f, "usage: pose-bridge can-monitor (IFACE | --log FILE.log [--fast]) --bus MAP.json\n"
               "                              [--json] [--seconds S]\n"
               "  IFACE       SocketCAN interface to watch\n"
               "  --log FILE  replay a candump -l log as the bus (recorded timing; --fast: at once)\n"
               "  --bus FILE  bus description (a mapping file's \"can\" object)\n"
               "  --json      one JSON object per report, after a line {\"warnings\":[..]} when the\n"
               "              DBC raised warnings (also on stderr)\n"
               "  --seconds S stop after S seconds of bus time\n"
               "Every second of bus time: the source state, the controller state, and per node\n"
               "its state (alive, silent, never seen), frames per second and CANopen NMT state.\n");
}

static const char *node_state(pb_can_node_state s)
{
    return s == PB_CAN_NODE_ALIVE ? "alive" : s == PB_CAN_NODE_SILENT ? "silent" : "never";
}

static void report(pb_source *src, pb_can_decoder *dec, uint64_t *last_frames, double t, double span, int json)
{
    const pb_can_stats *st = pb_can_decoder_stats(dec);
    const size_t n = pb_can_decoder_node_count(dec);
    if (json) {
        printf("{\"t\":%.3f,\"state\":\"%s\",\"message\":", t, pb_source_state_name(src->state));
        pb_cli_json_string(stdout, src->message);
        printf(",\"bus\":\"%s\",\"frames\":%llu,\"errors\":%llu,\"dropped\":%llu,\"nodes\":[",
               pb_can_bus_state_name(st->bus), (unsigned long long)st->frames,
               (unsigned long long)st->error_frames, (unsigned long long)st->dropped);
    } else {
        printf("t=%.1f s  %s%s%s  bus %s  frames %llu  errors %llu  dropped %llu\n", t,
               pb_source_state_name(src->state), src->message[0] ? ": " : "", src->message,
               pb_can_bus_state_name(st->bus), (unsigned long long)st->frames,
               (unsigned long long)st->error_frames, (unsigned long long)st->dropped);
    }
    for (size_t i = 0; i < n; i++) {
        pb_can_node_info info;
        pb_can_decoder_node(dec, i, &info);
        const double rate = span > 0 ? (double)(info.frames - last_frames[i]) / span : 0;
        last_frames[i] = info.frames;
        if (json) {
            printf("%s{\"name\":", i ? "," : "");
            pb_cli_json_string(stdout, info.name);
            printf(",\"state\":\"%s\",\"rate_hz\":%.1f", node_state(info.state), rate);
            if (info.nmt >= 0)
                printf(",\"nmt\":\"%s\"", pb_canopen_nmt_name((unsigned)info.nmt));
            putchar('}');
        } else {
            printf("  %-16s %-6s %8.1f Hz", info.name, node_state(info.state), rate);
            if (info.nmt >= 0)
                printf("  %s", pb_canopen_nmt_name((unsigned)info.nmt));
            putchar('\n');
        }
    }
    if (json)
        puts("]}");
    fflush(stdout);
}

static int run(int argc, char **argv)
{
    enum { OPT_LOG = POSE_CLI_LONG_ONLY, OPT_BUS, OPT_SECONDS, OPT_JSON, OPT_FAST };
    static const struct option options[] = {
        {"log", required_argument, NULL, OPT_LOG},         {"bus", required_argument, NULL, OPT_BUS},
        {"seconds", required_argument, NULL, OPT_SECONDS}, {"json", no_argument, NULL, OPT_JSON},
        {"fast", no_argument, NULL, OPT_FAST},             {"help", no_argument, NULL, 'h'},
        {0}};
    const char *iface = NULL, *log = NULL, *bus_path = NULL;
    int json = 0, fast = 0;
    double seconds = 0;
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge can-monitor", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            help(stdout);
            return 0;
        case OPT_LOG:
            log = cli.value;
            break;
        case OPT_BUS:
            bus_path = cli.value;
            break;
        case OPT_SECONDS:
            if (pose_cli_double(&cli, 0, 1e9, &seconds) < 0)
                return 2;
            break;
        case OPT_JSON:
            json = 1;
            break;
        case OPT_FAST:
            fast = 1;
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
    if (!bus_path || !!iface == !!log) {
        pose_cli_error(&cli, "--bus and one of IFACE, --log are required");
        return 2;
    }
    pb_error err;
    pb_can_bus *bus = NULL;
    static pb_warnings warnings;
    pb_cli_warnings_begin(&warnings);
    /* Installed for the whole run: a log's bad lines and time jumps are found while it plays. */
    pose_status loaded = pb_can_bus_load(bus_path, &bus, &err);
    if (loaded != POSE_OK) {
        fprintf(stderr, "pose-bridge can-monitor: %s\n", err.message);
        return 1;
    }
    if (json)
        pb_cli_json_warnings_line(stdout, &warnings);
    pb_source *src = NULL;
    pose_status st;
    if (log) {
        pb_candump_replay_options opt = {.as_fast_as_possible = fast};
        st = pb_candump_replay_open(log, bus, &opt, &src, &err);
    } else {
        st = pb_can_live_open(iface, bus, NULL, &src, &err);
    }
    if (st != POSE_OK) {
        fprintf(stderr, "pose-bridge can-monitor: %s\n", err.message);
        return 1;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    pb_can_decoder *dec = pb_can_source_decoder(src);
    uint64_t *last = calloc(pb_can_decoder_node_count(dec) + 1, sizeof *last);
    /* Bus time: the replay's recorded clock, or the monotonic clock live. */
    const int64_t t0 = log ? 0 : pb_can_mono_ns();
    int64_t next = t0 + 1000000000, prev = t0;
    int status = 0;
    while (!stop && last) {
        pb_update u;
        int r = src->ops->read(src, &u, 200);
        const int64_t now = log ? (r == 1 ? u.t_ns : prev) : pb_can_mono_ns();
        if (r < 0) {
            if (src->state == PB_SOURCE_ENDED)
                break;
            if (src->state == PB_SOURCE_DISCONNECTED) {
                usleep(200000); /* the live source reopens its interface on the next read */
                continue;
            }
            status = 1;
            break;
        }
        if (now >= next) {
            report(src, dec, last, (now - t0) * 1e-9, (now - prev) * 1e-9, json);
            prev = now;
            next = now + 1000000000;
        }
        if (seconds > 0 && now - t0 >= (int64_t)(seconds * 1e9))
            break;
    }
    report(src, dec, last, (prev - t0) * 1e-9, 0, json);
    free(last);
    pb_source_destroy(src);
    pb_warnings_install(NULL);
    return status;
}

const pb_command pb_cmd_can_monitor = {"can-monitor", "per-node rates and states of a CAN bus (live or a log)", run};
