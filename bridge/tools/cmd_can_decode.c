/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge can-decode: every decodable frame of a candump -l log, with
 * the signals a DBC gives it (or, with --bus, the channels of a bus
 * description: DBC, CANopen and J1939 together). One line per frame; with
 * --json each line is {"t":..,"id":..,"msg":..,"signals":{..}}. Frames whose
 * length disagrees with the DBC and malformed lines are reported on stderr,
 * never fatal: the tool for wiring a rig and for checking the decoder
 * against other tools (cantools decode, candump). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "can_bus.h"
#include "candump_log.h"
#include "dbc_decode.h"
#include "pose_bridge_cli.h"
#include "pose_cli.h"

static void help(FILE *f)
{
    fprintf(f, "usage: pose-bridge can-decode (--dbc FILE.dbc | --bus MAP.json) LOG [--json] [--all]\n"
               "  --dbc FILE   decode the DBC's messages: one line per frame with its signals\n"
               "  --bus FILE   a bus description (a mapping file's \"can\" object): DBC signals,\n"
               "               CANopen CiA 406/410 nodes and J1939 slope sensors as channels\n"
               "  LOG          a candump -l log\n"
               "  --json       {\"t\":..,\"id\":..,\"msg\":..,\"signals\":{..}} per line, after a line\n"
               "               {\"warnings\":[..]} when the DBC raised warnings (also on stderr)\n"
               "  --all        also list frames nothing decodes (id only)\n"
               "Signals a multiplexor switches off and signals past a short frame's end are\n"
               "left out of the frame's line; short frames and malformed lines are counted on\n"
               "stderr with their line numbers.\n");
}

static void print_value(double v)
{
    if (!isfinite(v))
        fputs("null", stdout);
    else if (v == floor(v) && fabs(v) < 1e15)
        printf("%.0f", v);
    else
        printf("%.10g", v);
}

static void print_head(const pb_can_frame *f, int json, const char *name)
{
    const double t = (double)f->t_ns * 1e-9;
    if (json) {
        printf("{\"t\":%.6f,\"id\":%u,", t, (unsigned)f->id);
        if (f->flags & PB_CAN_EXT)
            fputs("\"extended\":true,", stdout);
        if (name) {
            fputs("\"msg\":", stdout);
            pb_cli_json_string(stdout, name);
            fputc(',', stdout);
        }
    } else {
        printf("%.6f %0*X %s", t, (f->flags & PB_CAN_EXT) ? 8 : 3, (unsigned)f->id, name ? name : "?");
    }
}

static int run(int argc, char **argv)
{
    enum { OPT_DBC = POSE_CLI_LONG_ONLY, OPT_BUS, OPT_JSON, OPT_ALL };
    static const struct option options[] = {
        {"dbc", required_argument, NULL, OPT_DBC}, {"bus", required_argument, NULL, OPT_BUS},
        {"json", no_argument, NULL, OPT_JSON},     {"all", no_argument, NULL, OPT_ALL},
        {"help", no_argument, NULL, 'h'},          {0}};
    const char *dbc_path = NULL, *bus_path = NULL, *log = NULL;
    int json = 0, all = 0;
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge can-decode", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            help(stdout);
            return 0;
        case OPT_DBC:
            dbc_path = cli.value;
            break;
        case OPT_BUS:
            bus_path = cli.value;
            break;
        case OPT_JSON:
            json = 1;
            break;
        case OPT_ALL:
            all = 1;
            break;
        case POSE_CLI_ARGUMENT:
            if (log) {
                pose_cli_error(&cli, "unexpected argument '%s' (one log only)", cli.value);
                return 2;
            }
            log = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    if (!log || !!dbc_path == !!bus_path) {
        pose_cli_error(&cli, "a candump log and one of --dbc, --bus are required");
        return 2;
    }
    pb_error err;
    pb_can_bus *bus = NULL;
    static pb_warnings warnings;
    pb_cli_warnings_begin(&warnings);
    pose_status st = bus_path ? pb_can_bus_load(bus_path, &bus, &err) : pb_can_bus_create(dbc_path, &bus, &err);
    pb_warnings_install(NULL);
    if (st != POSE_OK) {
        fprintf(stderr, "pose-bridge can-decode: %s\n", err.message);
        return 1;
    }
    pb_can_decoder *dec = NULL;
    if (bus_path && pb_can_decoder_create(pb_can_bus_config(bus), &dec, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge can-decode: %s\n", err.message);
        pb_can_bus_free(bus);
        return 1;
    }
    const pb_dbc *dbc = pb_can_bus_dbc(bus);
    if (json)
        pb_cli_json_warnings_line(stdout, &warnings);
    pb_candump_reader r;
    char msg[256];
    if (pb_candump_open(&r, log, msg, sizeof msg) != 0) {
        fprintf(stderr, "pose-bridge can-decode: %s\n", msg);
        pb_can_decoder_free(dec);
        pb_can_bus_free(bus);
        return 1;
    }
    size_t max_signals = 1;
    for (size_t i = 0; dbc && i < dbc->message_count; i++)
        if (dbc->messages[i].signal_count > max_signals)
            max_signals = dbc->messages[i].signal_count;
    double *values = malloc(max_signals * sizeof *values);
    uint8_t *presence = malloc(max_signals);
    size_t channel_count = 0, bad_seen = 0, length_mismatch = 0, decoded = 0;
    const pb_channel *channels = dec ? pb_can_decoder_channels(dec, &channel_count) : NULL;
    pb_can_frame f;
    int rc;
    while ((rc = pb_candump_next(&r, &f)) == 1) {
        if (r.bad_lines != bad_seen) {
            fprintf(stderr, "pose-bridge can-decode: skipped %zu malformed line(s), the last %s\n",
                    r.bad_lines - bad_seen, r.last_error);
            bad_seen = r.bad_lines;
        }
        if (dec) {
            pb_update u;
            size_t n = pb_can_decoder_feed(dec, &f, &u);
            if (!n && !all)
                continue;
            print_head(&f, json, NULL);
            if (json)
                fputs("\"channels\":{", stdout);
            for (size_t k = 0; k < n; k++) {
                if (json) {
                    if (k)
                        fputc(',', stdout);
                    pb_cli_json_string(stdout, channels[u.channels[k]].name);
                    fputc(':', stdout);
                } else {
                    printf(" %s=", channels[u.channels[k]].name);
                }
                print_value(u.values[k]);
            }
            fputs(json ? "}}\n" : "\n", stdout);
            decoded += n > 0;
            continue;
        }
        const pb_dbc_message *m = (f.flags & (PB_CAN_ERR | PB_CAN_RTR)) ? NULL
                                  : pb_dbc_find(dbc, f.id, (f.flags & PB_CAN_EXT) != 0);
        if (!m) {
            if (all) {
                print_head(&f, json, NULL);
                fputs(json ? "\"signals\":{}}\n" : "\n", stdout);
            }
            continue;
        }
        if (f.len != m->size && length_mismatch++ < 10)
            fprintf(stderr, "pose-bridge can-decode: %s:%zu: %s has %u data bytes, the DBC says %u\n", log, r.line,
                    m->name, f.len, m->size);
        pb_dbc_decode(m, f.data, f.len, values, NULL, presence);
        print_head(&f, json, m->name);
        if (json)
            fputs("\"signals\":{", stdout);
        int first = 1;
        for (size_t j = 0; j < m->signal_count; j++) {
            if (presence[j] != PB_DBC_PRESENT)
                continue;
            if (json) {
                if (!first)
                    fputc(',', stdout);
                pb_cli_json_string(stdout, m->signals[j].name);
                fputc(':', stdout);
            } else {
                printf(" %s=", m->signals[j].name);
            }
            print_value(values[j]);
            if (!json && m->signals[j].unit[0])
                printf(" %s", m->signals[j].unit);
            first = 0;
        }
        fputs(json ? "}}\n" : "\n", stdout);
        decoded++;
    }
    if (r.bad_lines != bad_seen)
        fprintf(stderr, "pose-bridge can-decode: skipped %zu malformed line(s), the last %s\n",
                r.bad_lines - bad_seen, r.last_error);
    fprintf(stderr, "pose-bridge can-decode: %zu frames, %zu decoded, %zu with a length other than the DBC's, "
                    "%zu malformed lines\n",
            r.frames, decoded, length_mismatch, r.bad_lines);
    free(values);
    free(presence);
    pb_candump_close(&r);
    pb_can_decoder_free(dec);
    pb_can_bus_free(bus);
    return rc < 0 ? 1 : 0;
}

const pb_command pb_cmd_can_decode = {"can-decode", "decode a candump -l log with a DBC or a bus description", run};
