/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness: report-descriptor parser, then the decoder over the
 * same bytes taken as a report of every declared input report ID. A
 * warning sink is installed so the warning path (reserved items, trailing
 * zero bytes) is formatted too. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "hid_report.h"
#include "pb_warn.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static pb_warnings warnings;
    memset(&warnings, 0, sizeof warnings);
    pb_warnings_install(&warnings);
    pb_hid_desc *d;
    pb_error err;
    pose_status st = pb_hid_desc_parse(data, size, "fuzz", &d, &err);
    for (size_t i = 0; i < warnings.count; i++)
        if (strlen(warnings.text[i]) >= PB_WARN_LEN)
            abort();
    pb_warnings_install(NULL);
    if (st != POSE_OK)
        return 0;
    size_t n = d->channel_count ? d->channel_count : 1;
    int32_t *lg = malloc(n * sizeof *lg);
    double *v = malloc(n * sizeof *v);
    uint8_t *ok = malloc(n);
    uint8_t report[PB_HID_MAX_REPORT_BYTES + 1] = {0};
    for (size_t i = 0; i < sizeof report; i++)
        report[i] = size ? data[i % size] : 0;
    for (int id = 0; lg && v && ok && id < 256; id++) {
        size_t len = pb_hid_desc_input_length(d, (uint8_t)id);
        if (!len)
            continue;
        report[0] = (uint8_t)id;
        uint32_t first, count;
        pb_hid_report_decode(d, report, len, lg, v, ok, &first, &count);
        pb_hid_report_decode(d, report, len - 1, lg, v, ok, &first, &count);
    }
    free(lg);
    free(v);
    free(ok);
    pb_hid_desc_free(d);
    return 0;
}
