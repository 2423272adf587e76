/* SPDX-License-Identifier: Apache-2.0
 * The public API's source strings (pose/bridge.h has the table): which
 * kind of source a string names, and opening the device kinds (HID, CAN,
 * their recordings) over the backends. Clips are opened by the caller
 * (mocap.h), because the runner and the scrubber share one loaded clip. */
#ifndef POSE_BRIDGE_SOURCE_SPEC_H
#define POSE_BRIDGE_SOURCE_SPEC_H

#include <stddef.h>
#include <stdint.h>

#include "pb_error.h"
#include "source.h"

typedef enum pb_spec_kind {
    PB_SPEC_BVH = 0,
    PB_SPEC_AMC = 1,
    PB_SPEC_HID_FILE = 2, /**< hid-recorder file */
    PB_SPEC_HID_LIVE = 3, /**< hid:VID:PID[:PAGE:USAGE], /dev/hidrawN, or hidusb:VID:PID[:IFACE] (hidapi's libusb backend) */
    PB_SPEC_CANDUMP = 4,  /**< candump -l log */
    PB_SPEC_CAN_LIVE = 5, /**< SocketCAN interface */
    PB_SPEC_USBMON = 6,   /**< usbmon text capture of a vendor-class USB device */
    PB_SPEC_USB_LIVE = 7, /**< usb:VID:PID[:SERIAL][/IFACE/EP] through libusb */
} pb_spec_kind;

typedef struct pb_spec {
    pb_spec_kind kind;
    const char *target; /**< path, interface or device spec: points into the parsed string */
} pb_spec;

/** Parse a source string; POSE_ERR_INVALID_ARGUMENT naming the string when no kind fits. */
pose_status pb_spec_parse(const char *source, pb_spec *out, pb_error *err);
/** The pb_source kind name of a spec's kind ("bvh", "asf-amc", "hid", "hid-replay", "can", "candump-replay"). */
const char *pb_spec_kind_name(pb_spec_kind kind);
static inline int pb_spec_is_clip(pb_spec_kind k) { return k == PB_SPEC_BVH || k == PB_SPEC_AMC; }
static inline int pb_spec_is_live(pb_spec_kind k)
{
    return k == PB_SPEC_HID_LIVE || k == PB_SPEC_CAN_LIVE || k == PB_SPEC_USB_LIVE;
}

/** How to open a device source; zero means default. */
typedef struct pb_spec_open_options {
    const char *map_path;   /**< the mapping file: a CAN source's "can" bus description (a USB source's "usb" frame) is read from it */
    const char *map_json;   /**< ... or the mapping as text (relative "dbc" paths: the working directory) */
    int as_fast_as_possible;/**< recordings: ignore recorded timing */
    int loop;               /**< recordings: start over at the end */
    double speed;           /**< recordings: recorded timing scaled; 0 = 1 */
    int stale_ms;           /**< HID: silence before STALE; 0 = the backend's default */
} pb_spec_open_options;

/**
 * Open a HID or CAN spec (live or recorded) as a source. POSE_ERR_UNSUPPORTED
 * in a build without the device backends (POSE_BRIDGE_CORE_ONLY).
 */
pose_status pb_spec_open_device(const pb_spec *spec, const pb_spec_open_options *opt, pb_source **out,
                                pb_error *err);

/** Samples a device source rejected or lost so far (malformed reports, short frames, overflows); 0 for others. */
uint64_t pb_spec_source_drops(pb_source *src);

#endif /* POSE_BRIDGE_SOURCE_SPEC_H */
