/* SPDX-License-Identifier: Apache-2.0
 *
 * HID input-report decoder: locates each channel of a parsed descriptor in a
 * raw report (leading ID byte when the device uses report IDs), extracts its
 * bits (little-endian, any alignment), sign-extends signed fields and scales
 * logical values to physical units. Shared by live devices and replays; it
 * never allocates, so it runs in the bridge's hot path.
 */
#ifndef POSE_BRIDGE_HID_REPORT_H
#define POSE_BRIDGE_HID_REPORT_H

#include "hid_descriptor.h"

/** Results of pb_hid_report_decode. */
typedef enum pb_hid_decode_result {
    PB_HID_DECODE_OK = 0,
    PB_HID_DECODE_EMPTY = -1,      /**< zero-length report */
    PB_HID_DECODE_UNKNOWN_ID = -2, /**< report ID the descriptor does not declare as input */
    PB_HID_DECODE_SHORT = -3,      /**< fewer bytes than the descriptor says the report has */
} pb_hid_decode_result;

/**
 * Decode one input report. Writes, for each channel c of that report
 * (c in [*first, *first + *count)), logical[c] (raw value, sign-extended) and
 * value[c] (scaled to the channel's unit; arrays: the selected usage ID, 0 for
 * none) and valid[c] (0 when a Null State field reports "no value").
 * The arrays are indexed by channel and hold desc->channel_count entries.
 * Reports longer than declared are accepted (devices pad); shorter ones are not.
 */
pb_hid_decode_result pb_hid_report_decode(const pb_hid_desc *d, const uint8_t *report, size_t len,
                                          int32_t *logical, double *value, uint8_t *valid,
                                          uint32_t *first, uint32_t *count);

/** Raw bits of a field as a (sign-extended when signed) logical value; report is the payload after the ID byte. */
int32_t pb_hid_field_extract(const pb_hid_field *f, const uint8_t *payload);

/** 1 when the descriptor defines a physical meaning (range or unit) for the field. */
int pb_hid_field_has_physical(const pb_hid_field *f);

/** Fixed text for a decode result. */
const char *pb_hid_decode_result_string(pb_hid_decode_result r);

#endif /* POSE_BRIDGE_HID_REPORT_H */
