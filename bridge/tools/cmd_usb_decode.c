/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge usb-decode: every completed IN transfer of a usbmon capture on
 * the map's endpoint, decoded with the map's frame layout ("usb" object):
 * channel values per frame, or what was wrong with the transfer; then the
 * decoder's counters (frames, lost, reordered, short, bad checksums, stalls,
 * babble, wire errors, disconnects). One JSON object per line with --json. */
#include <stdlib.h>
#include <string.h>

#include "pose_bridge_cli.h"
#include "pose_cli.h"
#include "usb_frame.h"
#include "usbmon.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: pose-bridge usb-decode CAPTURE --map MAP [--limit N] [--json]\n"
               "Decodes the capture's completed IN transfers (usbmon text, u or t format) on the endpoint\n"
               "of MAP's \"usb\" object with its frame layout. --json prints one object per transfer:\n"
               "{\"t\": s, \"line\": n, \"seq\": k, \"values\": {channel: value}} or {\"t\": s, \"line\": n,\n"
               "\"error\": text}, then {\"summary\": {\"frames\": n, \"lost\": n, \"reordered\": n, ...}}.\n");
}

static void print_error(int json, double t, uint32_t line, const char *what)
{
    if (json) {
        printf("{\"t\":%.6f,\"line\":%u,\"error\":", t, line);
        pb_cli_json_string(stdout, what);
        printf("}\n");
    } else {
        printf("%.6f line %u: %s\n", t, line, what);
    }
}

static int run(int argc, char **argv)
{
    enum { OPT_JSON = POSE_CLI_LONG_ONLY, OPT_MAP, OPT_LIMIT };
    static const struct option options[] = {
        {"json", no_argument, NULL, OPT_JSON}, {"map", required_argument, NULL, OPT_MAP},
        {"limit", required_argument, NULL, OPT_LIMIT}, {"help", no_argument, NULL, 'h'}, {0}};
    const char *path = NULL, *map = NULL;
    int json = 0;
    long limit = -1;
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge usb-decode", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            usage(stdout);
            return 0;
        case OPT_JSON:
            json = 1;
            break;
        case OPT_MAP:
            map = cli.value;
            break;
        case OPT_LIMIT:
            if (pose_cli_long(&cli, 0, 1000000000, &limit) < 0)
                return 2;
            break;
        case POSE_CLI_ARGUMENT:
            if (path) {
                pose_cli_error(&cli, "unexpected argument '%s' (one capture only)", cli.value);
                return 2;
            }
            path = cli.value;
            break;
        default:
            return 2;
        }
    if (!path || !map) {
        pose_cli_error(&cli, "%s", !path ? "no usbmon capture given" : "--map MAP (with a \"usb\" object) is required");
        return 2;
    }
    static pb_warnings warnings;
    pb_cli_warnings_begin(&warnings);
    pb_error err;
    pb_usb_layout *l = malloc(sizeof *l);
    pb_usbmon_capture *cap = NULL;
    pb_usb_decoder dec;
    memset(&dec, 0, sizeof dec);
    int rc = 0;
    if (!l || pb_usb_layout_load(map, l, &err) != POSE_OK || pb_usbmon_load(path, &cap, &err) != POSE_OK ||
        pb_usb_decoder_init(&dec, l, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge usb-decode: %s\n", l ? err.message : "out of memory");
        rc = 1;
    }
    if (json && rc == 0)
        pb_cli_json_warnings_line(stdout, &warnings);
    const char want = rc == 0 && l->bulk ? 'B' : 'I';
    long shown = 0;
    int64_t t0 = -1;
    for (size_t i = 0; rc == 0 && i < cap->count && (limit < 0 || shown < limit); i++) {
        const pb_usbmon_event *e = &cap->events[i];
        if (!e->in || e->xfer != want || e->ep != (l->endpoint & 0x0F) || (e->event != 'C' && e->event != 'E'))
            continue;
        if (t0 < 0)
            t0 = e->t_us;
        double t = (double)(e->t_us - t0) * 1e-6;
        shown++;
        pb_usb_status st = pb_usb_status_from_errno(e->status);
        if (e->event == 'E' || st != PB_USB_XFER_OK) {
            char what[160];
            snprintf(what, sizeof what, "%s transfer: status %d (%s)", e->event == 'E' ? "submission of a" : "the",
                     e->status, pb_usb_status_name(st));
            if (e->event == 'E' && st != PB_USB_XFER_NO_DEVICE)
                continue;
            pb_usb_decoder_count_status(&dec, st);
            if (st == PB_USB_XFER_NO_DEVICE)
                pb_usb_decoder_resync(&dec);
            print_error(json, t, e->line, what);
            continue;
        }
        uint32_t n = e->captured < e->length ? e->captured : e->length;
        uint64_t seq = 0;
        pb_usb_decode_result r = pb_usb_decode(&dec, cap->data + e->offset, n, &seq);
        if (r != PB_USB_DECODE_OK) {
            char what[160];
            snprintf(what, sizeof what, "%s (%u bytes%s)", pb_usb_decode_result_string(r), n,
                     e->captured < e->length ? ", the capture cut the transfer" : "");
            print_error(json, t, e->line, what);
            continue;
        }
        if (json) {
            printf("{\"t\":%.6f,\"line\":%u", t, e->line);
            if (l->has_sequence)
                printf(",\"seq\":%llu", (unsigned long long)seq);
            printf(",\"values\":{");
        } else {
            printf("%.6f line %u", t, e->line);
            if (l->has_sequence)
                printf(" seq %llu", (unsigned long long)seq);
            printf(":");
        }
        for (size_t c = 0; c < l->channel_count; c++) {
            if (json) {
                printf("%s", c ? "," : "");
                pb_cli_json_string(stdout, l->channels[c].name);
                printf(":%.9g", dec.values[c]);
            } else {
                printf(" %s=%.6g%s", l->channels[c].name, dec.values[c], l->channels[c].unit);
            }
        }
        printf(json ? "}}\n" : "\n");
    }
    if (rc == 0) {
        const pb_usb_frame_stats *s = &dec.stats;
        printf(json ? "{\"summary\":{\"frames\":%llu,\"lost\":%llu,\"reordered\":%llu,\"short\":%llu,\"long\":%llu,"
                      "\"bad_checksums\":%llu,\"stalls\":%llu,\"babble\":%llu,\"wire_errors\":%llu,\"disconnects\":%llu}}\n"
                    : "frames %llu, lost %llu, reordered %llu, short %llu, long %llu, bad checksums %llu, stalls %llu, "
                      "babble %llu, wire errors %llu, disconnects %llu\n",
               (unsigned long long)s->frames, (unsigned long long)s->lost, (unsigned long long)s->reordered,
               (unsigned long long)s->short_frames, (unsigned long long)s->long_frames,
               (unsigned long long)s->bad_checksums, (unsigned long long)s->stalls, (unsigned long long)s->overflows,
               (unsigned long long)s->wire_errors, (unsigned long long)s->disconnects);
    }
    pb_usb_decoder_free(&dec);
    pb_usbmon_capture_free(cap);
    free(l);
    pb_warnings_install(NULL);
    return rc;
}

const pb_command pb_cmd_usb_decode = {"usb-decode", "decode a usbmon capture with a map's USB frame layout", run};
