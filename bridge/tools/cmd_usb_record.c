/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge usb-record: record a vendor-class USB device (or re-record a
 * usbmon capture) to usbmon text that usb-decode and the bridge replay:
 * every completed IN transfer on the map's endpoint, with all its bytes
 * (the kernel's own text capture keeps 32). */
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pose_bridge_cli.h"
#include "pose_cli.h"
#include "usb_source.h"
#include "clock.h"

static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
    (void)sig;
    stop = 1;
}

static void usage(FILE *f)
{
    fprintf(f, "usage: pose-bridge usb-record SOURCE --map MAP -o OUT.usbmon [--seconds S] [--count N] [--fast] [--json]\n"
               "SOURCE: usb:VID:PID[:SERIAL][/INTERFACE/ENDPOINT] (libusb; the rest from MAP's \"usb\" object),\n"
               "or a usbmon capture (re-recorded at its timing, or as fast as possible with --fast). Stops\n"
               "after S seconds, N transfers, the end of a capture, or Ctrl-C. Faults (stalls, babble,\n"
               "unplugging) are reported on stderr and recorded with their status; recording goes on.\n");
}

static void on_status(pb_source *src, pb_source_state state, const char *message, void *user)
{
    (void)src;
    (void)user;
    fprintf(stderr, "usb-record: %s: %s\n", pb_source_state_name(state), message);
}

static int run(int argc, char **argv)
{
    enum { OPT_SECONDS = POSE_CLI_LONG_ONLY, OPT_COUNT, OPT_FAST, OPT_JSON, OPT_MAP };
    static const struct option options[] = {
        {"output", required_argument, NULL, 'o'}, {"seconds", required_argument, NULL, OPT_SECONDS},
        {"count", required_argument, NULL, OPT_COUNT}, {"fast", no_argument, NULL, OPT_FAST},
        {"json", no_argument, NULL, OPT_JSON}, {"map", required_argument, NULL, OPT_MAP},
        {"help", no_argument, NULL, 'h'}, {0}};
    const char *spec = NULL, *out_path = NULL, *map = NULL;
    double seconds = 0;
    long count = 0;
    int fast = 0, json = 0;
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge usb-record", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            usage(stdout);
            return 0;
        case 'o':
            out_path = cli.value;
            break;
        case OPT_MAP:
            map = cli.value;
            break;
        case OPT_SECONDS:
            if (pose_cli_double(&cli, 0, 1e9, &seconds) < 0)
                return 2;
            break;
        case OPT_COUNT:
            if (pose_cli_long(&cli, 0, 1000000000, &count) < 0)
                return 2;
            break;
        case OPT_FAST:
            fast = 1;
            break;
        case OPT_JSON:
            json = 1;
            break;
        case POSE_CLI_ARGUMENT:
            if (spec) {
                pose_cli_error(&cli, "unexpected argument '%s' (one device only)", cli.value);
                return 2;
            }
            spec = cli.value;
            break;
        default:
            return 2;
        }
    if (!spec || !out_path || !map) {
        pose_cli_error(&cli, "a device, --map MAP and -o FILE are required");
        return 2;
    }
    static pb_usb_layout layout;
    pb_source *src = NULL;
    pb_error err;
    pose_status st = pb_usb_layout_load(map, &layout, &err);
    if (st == POSE_OK && strncmp(spec, "usb:", 4) == 0)
        st = pb_usb_live_open(spec, &layout, NULL, &src, &err);
    else if (st == POSE_OK)
        st = pb_usb_replay_open(spec, &layout, &(pb_usb_replay_options){.as_fast_as_possible = fast}, &src, &err);
    if (st != POSE_OK) {
        fprintf(stderr, "pose-bridge usb-record: %s\n", err.message);
        return 1;
    }
    FILE *f = fopen(out_path, "w");
    if (!f || pb_usb_source_record(src, f) != 0) {
        fprintf(stderr, "pose-bridge usb-record: cannot write %s\n", out_path);
        if (f)
            fclose(f);
        pb_source_destroy(src);
        return 1;
    }
    src->on_status = on_status;
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    int64_t t0 = pb_now_ns();
    long frames = 0;
    int rc = 0;
    while (!stop) {
        pb_update u;
        int r = pb_source_read(src, &u, 200);
        if (r < 0) {
            if (src->state != PB_SOURCE_ENDED) {
                fprintf(stderr, "pose-bridge usb-record: %s\n", src->message);
                rc = 1;
            }
            break;
        }
        frames += r;
        double el = (double)(pb_now_ns() - t0) * 1e-9;
        if ((seconds > 0 && el >= seconds) || (count > 0 && frames >= count))
            break;
    }
    const pb_usb_frame_stats s = *pb_usb_source_stats(src);
    pb_usb_source_record(src, NULL);
    pb_source_destroy(src);
    if (fclose(f) != 0) {
        fprintf(stderr, "pose-bridge usb-record: write error on %s\n", out_path);
        rc = 1;
    }
    if (json) {
        printf("{\"output\":");
        pb_cli_json_string(stdout, out_path);
        printf(",\"frames\":%llu,\"lost\":%llu,\"reordered\":%llu,\"malformed\":%llu,\"failed_transfers\":%llu,"
               "\"disconnects\":%llu}\n",
               (unsigned long long)s.frames, (unsigned long long)s.lost, (unsigned long long)s.reordered,
               (unsigned long long)(s.short_frames + s.long_frames + s.bad_checksums),
               (unsigned long long)(s.stalls + s.overflows + s.wire_errors), (unsigned long long)s.disconnects);
    } else {
        printf("%s: %llu frames recorded\n", out_path, (unsigned long long)s.frames);
    }
    return rc;
}

const pb_command pb_cmd_usb_record = {"usb-record", "record a vendor-class USB device to usbmon text", run};
