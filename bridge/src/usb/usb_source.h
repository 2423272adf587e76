/* SPDX-License-Identifier: Apache-2.0
 *
 * The vendor-class USB source: one state machine shared by live devices
 * (usb_libusb.c, libusb 1.0) and simulated ones (usb_replay.c, usbmon
 * captures). A transport moves completed IN transfers (bytes and outcome);
 * this file decodes them with the mapping's frame layout (usb_frame.h) and
 * turns outcomes into source states:
 *
 *   open -> WAITING -> OK (frames decode) -> STALE (silent > stale_ms)
 *   device gone (unplug, ENODEV) -> DISCONNECTED -> reopened when hotplug
 *     reports the device back (live), else every reopen_ms -> WAITING -> OK
 *   stall, babble, wire error, short / long frame, bad checksum, counter
 *     that went back -> FAULT (until the next good frame)
 *   capture ends -> ENDED
 *
 * Channel values change only on a good frame, so a fault holds the last
 * good pose. The decoder's counters (usb_frame.h) say what was lost.
 */
#ifndef POSE_BRIDGE_USB_SOURCE_H
#define POSE_BRIDGE_USB_SOURCE_H

#include <stdio.h>

#include "usb_frame.h"

typedef struct pb_usb_transport pb_usb_transport;

enum { PB_USB_READ_GONE = -1, PB_USB_READ_ENDED = -2 };

/** One completed IN transfer. */
typedef struct pb_usb_completion {
    pb_usb_status status;
    size_t len;    /**< bytes in the buffer */
    int64_t t_ns;  /**< completion time (CLOCK_MONOTONIC live, recorded for captures) */
} pb_usb_completion;

typedef struct pb_usb_transport_ops {
    const char *kind; /**< source kind: "usb", "usbmon-replay" */
    /** Find and open the device, claim its interface, start transfers. POSE_ERR_NOT_FOUND when absent. */
    pose_status (*open)(pb_usb_transport *t, pb_error *err);
    /**
     * Wait at most timeout_ms (-1 forever) for a completed transfer: 1 with
     * buf and *c filled, 0 on timeout, PB_USB_READ_GONE when the device left,
     * PB_USB_READ_ENDED at the end of a capture.
     */
    int (*read)(pb_usb_transport *t, uint8_t *buf, size_t cap, int timeout_ms, pb_usb_completion *c);
    /** Captures only (else NULL): continue from recorded time t_ns. */
    int (*seek)(pb_usb_transport *t, int64_t t_ns);
    /** Live only (else NULL): wait at most timeout_ms for the device to arrive (hotplug); 1 when it did. */
    int (*wait_arrival)(pb_usb_transport *t, int timeout_ms);
    void (*close)(pb_usb_transport *t);
    void (*destroy)(pb_usb_transport *t);
} pb_usb_transport_ops;

struct pb_usb_transport {
    const pb_usb_transport_ops *ops;
    char origin[192];          /**< "usb:1209:0002" or the capture's file name */
    const pb_usb_layout *layout;/**< the source's, set before open */
    int hotplug;               /**< 1: arrivals are signalled (libusb hotplug), no polling */
    uint16_t bus, dev;         /**< where the device is now (0 when unknown), for recordings */
};

typedef struct pb_usb_source_options {
    int stale_ms;   /**< default 500 */
    int reopen_ms;  /**< reopen attempts without hotplug; default 1000 */
    /** A channel that freezes the pose while non-zero (the box's hold button), or NULL. */
    const char *hold_channel;
} pb_usb_source_options;

/**
 * A source over a transport (owned by the source from now on, even on
 * failure) and a layout (copied). A live device that is not plugged in is
 * no error: the source starts DISCONNECTED and opens it when it arrives.
 */
pose_status pb_usb_source_create(pb_usb_transport *t, const pb_usb_layout *layout, const pb_usb_source_options *opt,
                                 pb_source **out, pb_error *err);

int pb_source_is_usb(const pb_source *src);
/** The decoder's counters (NULL for other sources). */
const pb_usb_frame_stats *pb_usb_source_stats(const pb_source *src);
/** Frames lost or unusable so far: lost + malformed + reordered + failed transfers. */
uint64_t pb_usb_source_drops(const pb_source *src);
/** Reopens after a disconnect. */
uint64_t pb_usb_source_reopens(const pb_source *src);
/** The layout (NULL for other sources). */
const pb_usb_layout *pb_usb_source_layout(const pb_source *src);
/** Last transfer as read (good or not). */
const uint8_t *pb_usb_source_last_frame(const pb_source *src, size_t *len, pb_usb_status *status);
/** Decoded raw integers of the last good frame. */
const int64_t *pb_usb_source_raw(const pb_source *src);

/**
 * Record every completed transfer from now on to f as usbmon text (C lines
 * with all bytes; header comment written now). NULL stops. 0 or -1.
 */
int pb_usb_source_record(pb_source *src, FILE *f);

/* ----------------------------------------------------------- transports */

typedef struct pb_usbmon_capture pb_usbmon_capture;

typedef struct pb_usb_replay_options {
    pb_usb_source_options source;
    double speed;              /**< recorded timing x speed (default 1) */
    int as_fast_as_possible;
    int loop;
} pb_usb_replay_options;

/** Replay a usbmon capture (taken over) through the layout's decoder. */
pose_status pb_usb_replay_create(pb_usbmon_capture *cap, const char *origin, const pb_usb_layout *layout,
                                 const pb_usb_replay_options *opt, pb_source **out, pb_error *err);
pose_status pb_usb_replay_open(const char *path, const pb_usb_layout *layout, const pb_usb_replay_options *opt,
                               pb_source **out, pb_error *err);

/**
 * Parse "usb:VID:PID[:SERIAL][/IFACE/EP]" (hex ids, decimal interface, hex
 * endpoint) into the layout's device fields. 0 or -1 with err.
 */
pose_status pb_usb_parse_spec(const char *spec, pb_usb_layout *l, pb_error *err);

/**
 * A live device through libusb 1.0 (usb_libusb.c): VID:PID[:serial],
 * interface and endpoint from the layout (after pb_usb_parse_spec).
 * POSE_ERR_UNSUPPORTED in a build without libusb.
 */
pose_status pb_usb_live_open(const char *spec, const pb_usb_layout *layout, const pb_usb_source_options *opt,
                             pb_source **out, pb_error *err);


#endif /* POSE_BRIDGE_USB_SOURCE_H */
