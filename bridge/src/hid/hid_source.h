/* SPDX-License-Identifier: Apache-2.0
 *
 * The HID source: one state machine shared by live devices (hid_hidraw.c)
 * and simulated ones (hid_replay.c). A transport only moves bytes (open the
 * device and hand out its descriptor, read one report with a timeout); this
 * file decodes reports, keeps the last good values, and turns transport
 * events into source states:
 *
 *   open -> WAITING -> OK (reports decode) -> STALE (silent > stale_ms)
 *   read fails -> DISCONNECTED -> reopen every reopen_ms -> WAITING -> OK
 *   short / unknown-ID / empty report -> FAULT (until the next good report)
 *   recording ends -> ENDED
 *
 * Values of a channel change only on a good report, so a fault holds the
 * last good pose. Reading is single-threaded: one thread owns a source.
 */
#ifndef POSE_BRIDGE_HID_SOURCE_H
#define POSE_BRIDGE_HID_SOURCE_H

#include <stdio.h>

#include "hid_descriptor.h"
#include "hid_recorder.h"
#include "pb_error.h"
#include "source.h"

typedef struct pb_hid_transport pb_hid_transport;

/** Read results of a transport besides a byte count. */
enum { PB_HID_READ_GONE = -1, PB_HID_READ_ENDED = -2 };

typedef struct pb_hid_transport_ops {
    const char *kind; /**< source kind: "hid", "hid-replay" */
    /**
     * Find and open the device, copy its descriptor (at most cap bytes) and
     * fill t->info. POSE_OK, or POSE_ERR_NOT_FOUND / POSE_ERR_IO with err.
     */
    pose_status (*open)(pb_hid_transport *t, uint8_t *desc, size_t cap, size_t *desc_len, pb_error *err);
    /**
     * One input report into buf (with its ID byte when the device uses IDs),
     * waiting at most timeout_ms (-1 = forever). Returns its length, 0 on
     * timeout, PB_HID_READ_GONE when the device went away, PB_HID_READ_ENDED
     * at the end of a recording. *t_ns: the report's time.
     */
    int (*read)(pb_hid_transport *t, uint8_t *buf, size_t cap, int timeout_ms, int64_t *t_ns);
    /** Recordings only (else NULL): continue from recorded time t_ns; 0 or -1. */
    int (*seek)(pb_hid_transport *t, int64_t t_ns);
    /** Close the device; open may follow again. */
    void (*close)(pb_hid_transport *t);
    /** Free the transport (the source closes it first). */
    void (*destroy)(pb_hid_transport *t);
} pb_hid_transport_ops;

/** Common part of every transport; backends embed it first. */
struct pb_hid_transport {
    const pb_hid_transport_ops *ops;
    char origin[192];      /**< device path or file name, for messages */
    pb_hid_rec_device info;/**< name, phys, bus, vendor, product (desc unused) */
};

/** Options; zero means default. */
typedef struct pb_hid_source_options {
    int stale_ms;  /**< silence that makes the source STALE (default 500) */
    int reopen_ms; /**< interval of reopen attempts after a disconnect (default 1000) */
    /**
     * The descriptor the device is known to have (e.g. the mannequin's), or
     * NULL. With it, a device that is not plugged in yet is no error: the
     * source starts DISCONNECTED with that descriptor's channels and opens
     * the device when it appears (a device with another descriptor is a FAULT).
     */
    const uint8_t *expected_desc;
    size_t expected_desc_len;
    /**
     * A channel that freezes the pose while it reads non-zero (the
     * mannequin's "hold pose" button, "Button.1"), or NULL. While held,
     * updates carry only channels without a unit (buttons, counters), so a
     * mapping keeps the joints where they were; the angles resume on release.
     */
    const char *hold_channel;
} pb_hid_source_options;

/** Counters since creation. */
typedef struct pb_hid_source_stats {
    uint64_t reports;     /**< decoded */
    uint64_t bad_reports; /**< short or empty */
    uint64_t unknown_ids;
    uint64_t disconnects;
    uint64_t reopens;
} pb_hid_source_stats;

/**
 * Make a source over a transport (ownership passes to the source, even on
 * failure). Opens the device once to learn its descriptor and channels;
 * POSE_ERR_NOT_FOUND when it is not there (unless opt->expected_desc says
 * what it will be), POSE_ERR_FORMAT for a bad descriptor. Destroy with
 * pb_source_destroy.
 */
pose_status pb_hid_source_create(pb_hid_transport *t, const pb_hid_source_options *opt, pb_source **out,
                                 pb_error *err);

/** The parsed descriptor of a HID source (NULL for other sources). */
const pb_hid_desc *pb_hid_source_desc(const pb_source *src);
/** Raw descriptor bytes of a HID source. */
const uint8_t *pb_hid_source_desc_bytes(const pb_source *src, size_t *len);
/** Last good value of each channel (channel_count entries; NaN until first seen). */
const double *pb_hid_source_values(const pb_source *src);
/** Logical (raw) value of each channel from the last good report. */
const int32_t *pb_hid_source_logical(const pb_source *src);
/** Last raw report as read (good or not) and its length. */
const uint8_t *pb_hid_source_last_report(const pb_source *src, size_t *len);
pb_hid_source_stats pb_hid_source_get_stats(const pb_source *src);
/** Device name, bus and IDs as the transport reported them. */
const pb_hid_rec_device *pb_hid_source_info(const pb_source *src);

/**
 * Record every report read from now on to f in hid-recorder format (header
 * written now; times relative to the first recorded report). NULL stops.
 * The source does not close f. Returns 0, or -1 on a write error.
 */
int pb_hid_source_record(pb_source *src, FILE *f);

/** True when src is a HID source (live or replay). */
int pb_source_is_hid(const pb_source *src);

/** Sleep until CLOCK_MONOTONIC reaches t_ns. */
void pb_hid_sleep_until(int64_t t_ns);

#endif /* POSE_BRIDGE_HID_SOURCE_H */
