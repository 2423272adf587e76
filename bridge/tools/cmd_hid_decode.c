/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge hid-decode: every event of a hid-recorder file, decoded with
 * its device's descriptor (logical values, and physical values where the
 * descriptor defines them). One JSON object per line with --json. */
#include <stdlib.h>
#include <string.h>

#include "hid_recorder.h"
#include "hid_report.h"
#include "pose_bridge_cli.h"
#include "pose_cli.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: pose-bridge hid-decode RECORDING.hid [--device N] [--limit N] [--json]\n"
               "Decodes every E: line with its device's report descriptor. --json prints one object\n"
               "per event: {\"t\": s, \"device\": n, \"report_id\": id, \"values\": {channel: {\"logical\": v,\n"
               "\"physical\": p}}} or {\"t\": s, \"device\": n, \"line\": l, \"error\": text}; a first line\n"
               "{\"warnings\": [text, ...]} when the descriptors raised warnings (also printed on stderr).\n");
}

static void print_event(const char *path, const pb_hid_desc *d, const pb_hid_rec_event *e, const uint8_t *bytes,
                        int json, int32_t *logical, double *value, uint8_t *valid)
{
    uint32_t first, count;
    pb_hid_decode_result r = pb_hid_report_decode(d, bytes, e->len, logical, value, valid, &first, &count);
    double t = (double)e->t_ns * 1e-9;
    if (r != PB_HID_DECODE_OK) {
        if (json) {
            printf("{\"t\":%.6f,\"device\":%u,\"line\":%u,\"error\":", t, e->device, e->line);
            pb_cli_json_string(stdout, pb_hid_decode_result_string(r));
            printf("}\n");
        } else {
            printf("%.6f dev %u line %u: %s\n", t, e->device, e->line, pb_hid_decode_result_string(r));
        }
        return;
    }
    unsigned id = d->uses_report_ids ? bytes[0] : 0;
    const size_t declared = pb_hid_desc_input_length(d, (uint8_t)id);
    if (e->len > declared) /* decoded all the same: devices pad reports */
        pb_warn("%s:%u: report of %u bytes, its descriptor declares %zu: the extra bytes are ignored", path, e->line,
                e->len, declared);
    if (json)
        printf("{\"t\":%.6f,\"device\":%u,\"report_id\":%u,\"values\":{", t, e->device, id);
    else
        printf("%.6f dev %u id %u:", t, e->device, id);
    for (uint32_t c = first; c < first + count; c++) {
        const pb_hid_field *f = &d->fields[d->channel_field[c]];
        int phys = (f->flags & PB_HID_VARIABLE) && pb_hid_field_has_physical(f);
        if (json) {
            printf("%s", c == first ? "" : ",");
            pb_cli_json_string(stdout, d->channels[c].name);
            printf(":{\"logical\":%d", logical[c]);
            if (!valid[c])
                printf(",\"null\":true");
            else if (phys)
                printf(",\"physical\":%.9g", value[c]);
            else if (!(f->flags & PB_HID_VARIABLE))
                printf(",\"usage\":%.0f", value[c]);
            printf("}");
        } else if (phys) {
            printf(" %s=%.6g%s", d->channels[c].name, value[c], d->channels[c].unit);
        } else {
            printf(" %s=%d", d->channels[c].name, logical[c]);
        }
    }
    printf(json ? "}}\n" : "\n");
}

static int run(int argc, char **argv)
{
    enum { OPT_JSON = POSE_CLI_LONG_ONLY, OPT_DEVICE, OPT_LIMIT };
    static const struct option options[] = {
        {"json", no_argument, NULL, OPT_JSON}, {"device", required_argument, NULL, OPT_DEVICE},
        {"limit", required_argument, NULL, OPT_LIMIT}, {"help", no_argument, NULL, 'h'},
        {0}};
    const char *path = NULL;
    int json = 0;
    long device = -1, limit = -1;
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge hid-decode", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            usage(stdout);
            return 0;
        case OPT_JSON:
            json = 1;
            break;
        case OPT_DEVICE:
            if (pose_cli_long(&cli, 0, 65535, &device) < 0)
                return 2;
            break;
        case OPT_LIMIT:
            if (pose_cli_long(&cli, 0, 1000000000, &limit) < 0)
                return 2;
            break;
        case POSE_CLI_ARGUMENT:
            if (path) {
                pose_cli_error(&cli, "unexpected argument '%s' (one recording only)", cli.value);
                return 2;
            }
            path = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    if (!path) {
        pose_cli_error(&cli, "no hid-recorder file given");
        return 2;
    }
    static pb_warnings warnings;
    pb_cli_warnings_begin(&warnings);
    pb_hid_recording *rec;
    pb_error err;
    if (pb_hid_recording_load(path, &rec, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge hid-decode: %s\n", err.message);
        pb_warnings_install(NULL);
        return 1;
    }
    int rc = 0;
    pb_hid_desc **descs = calloc(rec->device_count, sizeof *descs);
    size_t most = 1;
    for (size_t i = 0; descs && i < rec->device_count; i++) {
        char origin[300];
        snprintf(origin, sizeof origin, "%s (device %zu)", path, i);
        if (pb_hid_desc_parse(rec->devices[i].desc, rec->devices[i].desc_len, origin, &descs[i], &err) != POSE_OK) {
            fprintf(stderr, "pose-bridge hid-decode: %s\n", err.message);
            rc = 1;
            break;
        }
        if (descs[i]->channel_count > most)
            most = descs[i]->channel_count;
    }
    int32_t *logical = malloc(most * sizeof *logical);
    double *value = malloc(most * sizeof *value);
    uint8_t *valid = malloc(most);
    if (!descs || !logical || !value || !valid) {
        fprintf(stderr, "pose-bridge hid-decode: out of memory\n");
        rc = 1;
    }
    if (json && rc == 0)
        pb_cli_json_warnings_line(stdout, &warnings);
    long shown = 0;
    for (size_t i = 0; rc == 0 && i < rec->event_count && (limit < 0 || shown < limit); i++) {
        const pb_hid_rec_event *e = &rec->events[i];
        if (device >= 0 && e->device != (uint32_t)device)
            continue;
        print_event(path, descs[e->device], e, rec->data + e->offset, json, logical, value, valid);
        shown++;
    }
    pb_warnings_install(NULL); /* the events' warnings went to stderr as they came */
    for (size_t i = 0; descs && i < rec->device_count; i++)
        pb_hid_desc_free(descs[i]);
    free(descs);
    free(logical);
    free(value);
    free(valid);
    pb_hid_recording_free(rec);
    return rc;
}

const pb_command pb_cmd_hid_decode = {"hid-decode", "decode every event of a hid-recorder file", run};
