/* SPDX-License-Identifier: Apache-2.0 */
#include "hid_report.h"

int32_t pb_hid_field_extract(const pb_hid_field *f, const uint8_t *payload)
{
    uint32_t byte = f->bit_offset >> 3, shift = f->bit_offset & 7;
    uint32_t nbytes = (shift + f->bit_size + 7) >> 3; /* at most 5 for 32-bit fields */
    uint64_t v = 0;
    for (uint32_t i = 0; i < nbytes; i++)
        v |= (uint64_t)payload[byte + i] << (8 * i);
    v >>= shift;
    if (f->bit_size < 32) {
        v &= (1ull << f->bit_size) - 1;
        if (f->is_signed && (v >> (f->bit_size - 1)) & 1)
            v |= ~0ull << f->bit_size; /* sign-extend from the field's top bit */
    }
    return (int32_t)(uint32_t)v;
}

int pb_hid_field_has_physical(const pb_hid_field *f)
{
    return !(f->physical_min == 0 && f->physical_max == 0) || f->unit != 0;
}

/* Array slot: logical value indexes the usage list; out of range means "no control active". */
static double array_usage(const pb_hid_field *f, int32_t logical)
{
    if (logical < f->logical_min || logical > f->logical_max)
        return 0.0;
    uint32_t index = (uint32_t)((int64_t)logical - f->logical_min);
    for (uint32_t k = 0; k < f->usage_count; k++) {
        uint32_t a = f->usages[2 * k], b = f->usages[2 * k + 1];
        if (index <= b - a)
            return (double)((a + index) & 0xFFFF);
        index -= b - a + 1;
    }
    return 0.0;
}

pb_hid_decode_result pb_hid_report_decode(const pb_hid_desc *d, const uint8_t *report, size_t len,
                                          int32_t *logical, double *value, uint8_t *valid,
                                          uint32_t *first, uint32_t *count)
{
    *first = *count = 0;
    if (len == 0)
        return PB_HID_DECODE_EMPTY;
    uint8_t id = d->uses_report_ids ? report[0] : 0;
    size_t need = pb_hid_desc_input_length(d, id);
    if (need == 0)
        return PB_HID_DECODE_UNKNOWN_ID;
    if (len < need)
        return PB_HID_DECODE_SHORT;
    const uint8_t *payload = d->uses_report_ids ? report + 1 : report;
    uint32_t c0 = d->report_first[id], n = d->report_count[id];
    for (uint32_t c = c0; c < c0 + n; c++) {
        const pb_hid_field *f = &d->fields[d->channel_field[c]];
        int32_t l = pb_hid_field_extract(f, payload);
        logical[c] = l;
        if (f->flags & PB_HID_VARIABLE) {
            valid[c] = !((f->flags & PB_HID_NULL_STATE) && (l < f->logical_min || l > f->logical_max));
            value[c] = l * f->scale + f->offset;
        } else {
            valid[c] = 1;
            value[c] = array_usage(f, l);
        }
    }
    *first = c0;
    *count = n;
    return PB_HID_DECODE_OK;
}

const char *pb_hid_decode_result_string(pb_hid_decode_result r)
{
    switch (r) {
    case PB_HID_DECODE_OK:
        return "ok";
    case PB_HID_DECODE_EMPTY:
        return "empty report";
    case PB_HID_DECODE_UNKNOWN_ID:
        return "unknown report ID";
    case PB_HID_DECODE_SHORT:
        return "report shorter than its descriptor says";
    }
    return "unknown decode result";
}
