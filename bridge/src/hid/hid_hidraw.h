/* SPDX-License-Identifier: Apache-2.0
 *
 * Live HID devices through hidapi (hidraw backend). Only transport lives
 * here: enumeration, open, read with timeout, and the report descriptor,
 * which hidapi 0.13 does not hand out, read from sysfs
 * (/sys/class/hidraw/hidrawN/device/report_descriptor) or with the
 * HIDIOCGRDESC ioctl. Decoding, states and reopening are in hid_source.c.
 * Reopen after an unplug polls enumeration (hidapi 0.13 has no hotplug).
 */
#ifndef POSE_BRIDGE_HID_HIDRAW_H
#define POSE_BRIDGE_HID_HIDRAW_H

#include "hid_source.h"

/** Which device to open: zero fields match anything; the first match wins. */
typedef struct pb_hid_match {
    unsigned vendor, product;     /**< USB IDs */
    unsigned usage_page, usage;   /**< top-level collection usage */
    const char *path;             /**< "/dev/hidraw3": this node only */
} pb_hid_match;

/** One enumerated device. */
typedef struct pb_hid_found {
    char path[64];
    pb_hid_rec_device info;       /**< desc unused */
    unsigned usage_page, usage;
} pb_hid_found;

/** Open the first device that matches as a source. POSE_ERR_NOT_FOUND when none does. */
pose_status pb_hid_hidraw_open(const pb_hid_match *match, const pb_hid_source_options *opt, pb_source **out,
                               pb_error *err);

/**
 * List matching devices into found (at most cap; *count says how many
 * matched). POSE_ERR_UNSUPPORTED when built without hidapi.
 */
pose_status pb_hid_hidraw_list(const pb_hid_match *match, pb_hid_found *found, size_t cap, size_t *count,
                               pb_error *err);

/** Read a hidraw node's report descriptor (sysfs first, then HIDIOCGRDESC). */
pose_status pb_hid_hidraw_descriptor(const char *path, uint8_t *buf, size_t cap, size_t *len, pb_error *err);

#endif /* POSE_BRIDGE_HID_HIDRAW_H */
