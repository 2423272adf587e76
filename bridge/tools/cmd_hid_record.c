/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge hid-record: record a HID device (or re-record a recording) to a
 * hid-recorder file that hid-replay, hid-decode and the bridge can read. */
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hid_open.h"
#include "pose_bridge_cli.h"
#include "pose_cli.h"
#include "clock.h"

static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
    (void)sig;
    stop = 1;
}

static void usage(FILE *f)
{
    fprintf(f, "usage: pose-bridge hid-record SOURCE -o OUT.hid [--seconds S] [--count N] [--fast] [--json]\n"
               "SOURCE: /dev/hidrawN, hid:VID:PID[:PAGE:USAGE], or a hid-recorder file (re-recorded at its\n"
               "timing, or as fast as possible with --fast). Stops after S seconds, N reports, the end of\n"
               "a recording, or Ctrl-C. Device faults are reported on stderr; recording goes on.\n");
}

static void on_status(pb_source *src, pb_source_state state, const char *message, void *user)
{
    (void)src;
    (void)user;
    fprintf(stderr, "hid-record: %s: %s\n", pb_source_state_name(state), message);
}

static int run(int argc, char **argv)
{
    enum { OPT_SECONDS = POSE_CLI_LONG_ONLY, OPT_COUNT, OPT_FAST, OPT_JSON };
    static const struct option options[] = {
        {"output", required_argument, NULL, 'o'}, {"seconds", required_argument, NULL, OPT_SECONDS},
        {"count", required_argument, NULL, OPT_COUNT}, {"fast", no_argument, NULL, OPT_FAST},
        {"json", no_argument, NULL, OPT_JSON},   {"help", no_argument, NULL, 'h'},
        {0}};
    const char *spec = NULL, *out_path = NULL;
    double seconds = 0;
    long count = 0;
    int fast = 0, json = 0;
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge hid-record", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            usage(stdout);
            return 0;
        case 'o':
            out_path = cli.value;
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
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    if (!spec || !out_path) {
        pose_cli_error(&cli, "a device and -o FILE are required");
        return 2;
    }
    pb_hid_replay_options opt = {.as_fast_as_possible = fast};
    pb_source *src;
    pb_error err;
    static pb_warnings warnings;
    pb_cli_warnings_begin(&warnings);
    pose_status opened = pb_hid_open(spec, &opt, &src, &err);
    pb_warnings_install(NULL);
    if (opened != POSE_OK) {
        fprintf(stderr, "pose-bridge hid-record: %s\n", err.message);
        return 1;
    }
    FILE *f = fopen(out_path, "w");
    if (!f || pb_hid_source_record(src, f) != 0) {
        fprintf(stderr, "pose-bridge hid-record: cannot write %s\n", out_path);
        if (f)
            fclose(f);
        pb_source_destroy(src);
        return 1;
    }
    src->on_status = on_status;
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    int tty = isatty(STDERR_FILENO);
    int64_t t0 = pb_now_ns(), last_progress = 0;
    long reports = 0;
    int rc = 0;
    while (!stop) {
        pb_update u;
        int r = pb_source_read(src, &u, 200);
        if (r < 0) {
            if (src->state != PB_SOURCE_ENDED) {
                fprintf(stderr, "pose-bridge hid-record: %s\n", src->message);
                rc = 1;
            }
            break;
        }
        reports += r;
        int64_t now = pb_now_ns();
        double el = (double)(now - t0) * 1e-9;
        if (tty && now - last_progress > 250000000) {
            last_progress = now;
            if (seconds > 0)
                fprintf(stderr, "\rrecording: %ld reports, %.1f / %.1f s (%.0f%%, ETA %.0f s)", reports, el,
                        seconds, 100.0 * el / seconds, seconds > el ? seconds - el : 0.0);
            else
                fprintf(stderr, "\rrecording: %ld reports, %.1f s", reports, el);
        }
        if ((seconds > 0 && el >= seconds) || (count > 0 && reports >= count))
            break;
    }
    if (tty)
        fprintf(stderr, "\n");
    pb_hid_source_stats st = pb_hid_source_get_stats(src);
    pb_hid_source_record(src, NULL);
    pb_source_destroy(src);
    if (fclose(f) != 0) {
        fprintf(stderr, "pose-bridge hid-record: write error on %s\n", out_path);
        rc = 1;
    }
    if (json) {
        printf("{\"output\":");
        pb_cli_json_string(stdout, out_path);
        printf(",\"reports\":%llu,\"bad_reports\":%llu,\"unknown_ids\":%llu,\"disconnects\":%llu,",
               (unsigned long long)st.reports, (unsigned long long)st.bad_reports,
               (unsigned long long)st.unknown_ids, (unsigned long long)st.disconnects);
        pb_cli_json_warnings(stdout, &warnings);
        printf("}\n");
    } else
        printf("%s: %llu reports recorded\n", out_path, (unsigned long long)st.reports);
    return rc;
}

const pb_command pb_cmd_hid_record = {"hid-record", "record a HID device to a hid-recorder file", run};
