/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness: hid-recorder reader; every device's descriptor is then
 * parsed and every event decoded, as hid-decode does. */
#include <stdint.h>
#include <stdlib.h>

#include "hid_recorder.h"
#include "hid_report.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pb_hid_recording *rec;
    pb_error err;
    if (pb_hid_recording_parse((const char *)data, size, "fuzz.hid", &rec, &err) != POSE_OK)
        return 0;
    for (size_t k = 0; k < rec->device_count; k++) {
        pb_hid_desc *d;
        if (pb_hid_desc_parse(rec->devices[k].desc, rec->devices[k].desc_len, "fuzz.hid", &d, &err) != POSE_OK)
            continue;
        size_t n = d->channel_count ? d->channel_count : 1;
        int32_t *lg = malloc(n * sizeof *lg);
        double *v = malloc(n * sizeof *v);
        uint8_t *ok = malloc(n);
        for (size_t i = 0; lg && v && ok && i < rec->event_count; i++) {
            const pb_hid_rec_event *e = &rec->events[i];
            uint32_t first, count;
            if (e->device == k)
                pb_hid_report_decode(d, rec->data + e->offset, e->len, lg, v, ok, &first, &count);
        }
        free(lg);
        free(v);
        free(ok);
        pb_hid_desc_free(d);
    }
    pb_hid_recording_free(rec);
    return 0;
}
