/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge hid-describe: the fields and channels of a HID device, a
 * hid-recorder file or a raw report-descriptor file (as sysfs exports it). */
#include <stdlib.h>
#include <string.h>

#include "hid_hidraw.h"
#include "hid_open.h"
#include "hid_report.h"
#include "pose_bridge_cli.h"
#include "pose_cli.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: pose-bridge hid-describe SOURCE [--device N] [--json]\n"
               "       pose-bridge hid-describe --list [--json]\n"
               "SOURCE: a hid-recorder file, a binary report descriptor (e.g. a copy of\n"
               "/sys/class/hidraw/hidraw0/device/report_descriptor), /dev/hidrawN, or hid:VID:PID.\n"
               "Prints every field (report ID, bit position, size, usage, ranges, unit) and the\n"
               "channels the bridge maps. --list enumerates connected HID devices.\n");
}

static const char *kind_name(int k)
{
    return k == PB_HID_INPUT ? "input" : k == PB_HID_OUTPUT ? "output" : "feature";
}

static void flags_text(unsigned fl, char *buf, size_t n)
{
    snprintf(buf, n, "%s,%s,%s%s%s", fl & PB_HID_CONSTANT ? "Const" : "Data", fl & PB_HID_VARIABLE ? "Var" : "Array",
             fl & PB_HID_RELATIVE ? "Rel" : "Abs", fl & PB_HID_NULL_STATE ? ",Null" : "",
             fl & PB_HID_WRAP ? ",Wrap" : "");
}

static int channel_of(const pb_hid_desc *d, size_t field)
{
    for (size_t c = 0; c < d->channel_count; c++)
        if (d->channel_field[c] == field)
            return (int)c;
    return -1;
}

static pb_warnings warnings; /* what parsing the descriptor warned about */

static void print_json(const char *origin, const pb_hid_rec_device *info, const pb_hid_desc *d, size_t desc_len)
{
    printf("{\"source\":");
    pb_cli_json_string(stdout, origin);
    if (info) {
        printf(",\"name\":");
        pb_cli_json_string(stdout, info->name);
        printf(",\"bus\":%u,\"vendor\":\"%04x\",\"product\":\"%04x\"", info->bus, info->vendor, info->product);
    }
    printf(",\"descriptor_bytes\":%zu,\"report_ids\":%s,\"reports\":[", desc_len, d->uses_report_ids ? "true" : "false");
    int first = 1;
    for (int r = 0; r < 256; r++) {
        const uint16_t *sz[3] = {d->input_bytes, d->output_bytes, d->feature_bytes};
        for (int k = 0; k < 3; k++)
            if (sz[k][r]) {
                printf("%s{\"id\":%d,\"kind\":\"%s\",\"bytes\":%u}", first ? "" : ",", r, kind_name(k),
                       sz[k][r] + (d->uses_report_ids ? 1u : 0u));
                first = 0;
            }
    }
    printf("],\"collections\":[");
    for (size_t i = 0; i < d->collection_count; i++) {
        char name[64];
        printf("%s{\"type\":%u,\"usage\":\"0x%08x\",\"usage_name\":", i ? "," : "", d->collections[i].type,
               d->collections[i].usage);
        pb_cli_json_string(stdout, pb_hid_usage_name(d->collections[i].usage, name, sizeof name));
        printf(",\"parent\":%d}", d->collections[i].parent);
    }
    printf("],\"fields\":[");
    for (size_t i = 0; i < d->field_count; i++) {
        const pb_hid_field *f = &d->fields[i];
        char name[64], flags[48];
        flags_text(f->flags, flags, sizeof flags);
        printf("%s{\"report_id\":%u,\"kind\":\"%s\",\"flags\":\"%s\",\"bit_offset\":%u,\"bit_size\":%u,"
               "\"usage\":\"0x%08x\",\"usage_name\":",
               i ? "," : "", f->report_id, kind_name(f->kind), flags, f->bit_offset, f->bit_size, f->usage);
        pb_cli_json_string(stdout, pb_hid_usage_name(f->usage, name, sizeof name));
        if (!(f->flags & PB_HID_VARIABLE) && !(f->flags & PB_HID_CONSTANT))
            printf(",\"usage_last\":\"0x%08x\",\"array_index\":%u", f->usage_last, f->array_index);
        printf(",\"logical\":[%d,%d],\"signed\":%s", f->logical_min, f->logical_max, f->is_signed ? "true" : "false");
        if (pb_hid_field_has_physical(f))
            printf(",\"physical\":[%d,%d],\"unit\":\"%s\",\"unit_code\":\"0x%x\",\"unit_exponent\":%d,"
                   "\"scale\":%.9g,\"offset\":%.9g",
                   f->physical_min, f->physical_max, f->unit_name, f->unit, f->unit_exponent, f->scale, f->offset);
        int c = channel_of(d, i);
        if (c >= 0) {
            printf(",\"channel\":");
            pb_cli_json_string(stdout, d->channels[c].name);
        }
        printf("}");
    }
    printf("],\"channels\":[");
    for (size_t c = 0; c < d->channel_count; c++) {
        const pb_channel *ch = &d->channels[c];
        printf("%s{\"index\":%zu,\"name\":", c ? "," : "", c);
        pb_cli_json_string(stdout, ch->name);
        printf(",\"usage\":\"0x%08x\",\"unit\":", ch->usage);
        pb_cli_json_string(stdout, ch->unit);
        if (ch->min <= ch->max)
            printf(",\"min\":%.9g,\"max\":%.9g", ch->min, ch->max);
        printf("}");
    }
    printf("],");
    pb_cli_json_warnings(stdout, &warnings);
    printf("}\n");
}

static void print_text(const char *origin, const pb_hid_rec_device *info, const pb_hid_desc *d, size_t desc_len)
{
    printf("%s", origin);
    if (info)
        printf(": %s (bus %u, %04x:%04x)", info->name, info->bus, info->vendor, info->product);
    printf("\ndescriptor: %zu bytes, %zu fields, %zu channels, report IDs %s\n", desc_len, d->field_count,
           d->channel_count, d->uses_report_ids ? "yes" : "no");
    printf("%-7s %-4s %-16s %6s %4s  %-22s %-20s %-20s %s\n", "kind", "id", "flags", "bit", "size", "usage",
           "logical", "physical", "channel");
    for (size_t i = 0; i < d->field_count; i++) {
        const pb_hid_field *f = &d->fields[i];
        char name[64], flags[48], lg[32], ph[64] = "";
        flags_text(f->flags, flags, sizeof flags);
        snprintf(lg, sizeof lg, "%d..%d", f->logical_min, f->logical_max);
        if (pb_hid_field_has_physical(f))
            snprintf(ph, sizeof ph, "%.6g..%.6g %s", f->logical_min * f->scale + f->offset,
                     f->logical_max * f->scale + f->offset, f->unit_name);
        int c = channel_of(d, i);
        printf("%-7s %-4u %-16s %6u %4u  %-22s %-20s %-20s %s\n", kind_name(f->kind), f->report_id, flags,
               f->bit_offset, f->bit_size, f->flags & PB_HID_CONSTANT ? "(padding)" : pb_hid_usage_name(f->usage, name, sizeof name),
               lg, ph, c >= 0 ? d->channels[c].name : "");
    }
}

static int list_devices(int json)
{
    pb_hid_found found[64];
    size_t n = 0;
    pb_error err;
    if (pb_hid_hidraw_list(NULL, found, 64, &n, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge hid-describe: %s\n", err.message);
        return 1;
    }
    if (json)
        printf("[");
    for (size_t i = 0; i < n && i < 64; i++) {
        const pb_hid_found *f = &found[i];
        if (json) {
            printf("%s{\"path\":", i ? "," : "");
            pb_cli_json_string(stdout, f->path);
            printf(",\"name\":");
            pb_cli_json_string(stdout, f->info.name);
            printf(",\"vendor\":\"%04x\",\"product\":\"%04x\",\"usage_page\":\"%04x\",\"usage\":\"%04x\"}",
                   f->info.vendor, f->info.product, f->usage_page, f->usage);
        } else {
            printf("%s  hid:%04x:%04x:%04x:%04x  %s\n", f->path, f->info.vendor, f->info.product, f->usage_page,
                   f->usage, f->info.name);
        }
    }
    if (json)
        printf("]\n");
    else if (n == 0)
        fprintf(stderr, "no HID devices found (permissions? see bridge/devices/README.md)\n");
    return 0;
}

/* A file that is not hid-recorder text is taken as raw descriptor bytes. */
static int is_recording(const char *data, size_t size)
{
    size_t i = 0;
    while (i < size && (data[i] == ' ' || data[i] == '\t' || data[i] == '\r' || data[i] == '\n'))
        i++;
    return i < size && (data[i] == '#' || (i + 1 < size && data[i + 1] == ':' && strchr("DRNPIE", data[i])));
}

static int describe_file(const char *path, unsigned device, int json)
{
    char *data;
    size_t size;
    pb_error err;
    if (pb_read_file(path, (size_t)256 << 20, &data, &size, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge hid-describe: %s\n", err.message);
        return 1;
    }
    int rc = 1;
    pb_hid_recording *rec = NULL;
    pb_hid_desc *d = NULL;
    const pb_hid_rec_device *info = NULL;
    const uint8_t *bytes = (const uint8_t *)data;
    size_t len = size;
    if (is_recording(data, size)) {
        if (pb_hid_recording_parse(data, size, path, &rec, &err) != POSE_OK)
            goto done;
        if (device >= rec->device_count) {
            pb_fail(&err, POSE_ERR_NOT_FOUND, "%s: no device %u (the file has %zu)", path, device, rec->device_count);
            goto done;
        }
        info = &rec->devices[device];
        bytes = info->desc;
        len = info->desc_len;
    }
    if (pb_hid_desc_parse(bytes, len, path, &d, &err) != POSE_OK)
        goto done;
    if (json)
        print_json(path, info, d, len);
    else
        print_text(path, info, d, len);
    rc = 0;
done:
    if (rc)
        fprintf(stderr, "pose-bridge hid-describe: %s\n", err.message);
    pb_hid_desc_free(d);
    pb_hid_recording_free(rec);
    free(data);
    return rc;
}

static int run(int argc, char **argv)
{
    enum { OPT_JSON = POSE_CLI_LONG_ONLY, OPT_LIST, OPT_DEVICE };
    static const struct option options[] = {
        {"json", no_argument, NULL, OPT_JSON}, {"list", no_argument, NULL, OPT_LIST},
        {"device", required_argument, NULL, OPT_DEVICE}, {"help", no_argument, NULL, 'h'},
        {0}};
    const char *spec = NULL;
    int json = 0, list = 0;
    unsigned device = 0;
    long n;
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge hid-describe", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            usage(stdout);
            return 0;
        case OPT_JSON:
            json = 1;
            break;
        case OPT_LIST:
            list = 1;
            break;
        case OPT_DEVICE:
            if (pose_cli_long(&cli, 0, 65535, &n) < 0)
                return 2;
            device = (unsigned)n;
            break;
        case POSE_CLI_ARGUMENT:
            if (spec) {
                pose_cli_error(&cli, "unexpected argument '%s' (one device or file only)", cli.value);
                return 2;
            }
            spec = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    if (list)
        return list_devices(json);
    if (!spec) {
        pose_cli_error(&cli, "no device or hid-recorder file given");
        return 2;
    }
    pb_cli_warnings_begin(&warnings);
    if (!pb_hid_spec_is_live(spec)) {
        int rc = describe_file(spec, device, json);
        pb_warnings_install(NULL);
        return rc;
    }
    pb_source *src;
    pb_error err;
    if (pb_hid_open(spec, NULL, &src, &err) != POSE_OK) {
        fprintf(stderr, "pose-bridge hid-describe: %s\n", err.message);
        pb_warnings_install(NULL);
        return 1;
    }
    pb_warnings_install(NULL);
    size_t len;
    pb_hid_source_desc_bytes(src, &len);
    if (json)
        print_json(spec, pb_hid_source_info(src), pb_hid_source_desc(src), len);
    else
        print_text(spec, pb_hid_source_info(src), pb_hid_source_desc(src), len);
    pb_source_destroy(src);
    return 0;
}

const pb_command pb_cmd_hid_describe = {"hid-describe", "fields and channels of a HID device or recording", run};
