/* SPDX-License-Identifier: Apache-2.0
 *
 * hid-recorder text files (Linux hid-tools): reader and writer.
 *
 *     # comment                       ignored
 *     D: 0                            selects device 0 (header or events follow)
 *     R: 52 05 01 09 02 a1 01 ...      report descriptor: length, then bytes; may
 *                                      wrap onto following lines of bare hex
 *     N: Vendor Product                name
 *     P: usb-0000:00:14.0-1/input0     physical path
 *     I: 3 046d c077                   bus, vendor, product (hex)
 *     E: 000001.250000 4 01 00 ff 00   event: seconds.micro, length, bytes
 *
 * Timestamps may be zero-padded (current hid-tools) or not (older
 * hid-recorder); hex may be upper or lower case; a file may hold several
 * devices, each introduced by `D: n`, with events switching by `D:` lines.
 */
#ifndef POSE_BRIDGE_HID_RECORDER_H
#define POSE_BRIDGE_HID_RECORDER_H

#include <stdint.h>
#include <stdio.h>

#include "pb_error.h"

enum {
    PB_HID_REC_MAX_DEVICES = 64,
    PB_HID_REC_MAX_EVENT_BYTES = 4097, /**< a 4096-byte report and its ID byte */
};

typedef struct pb_hid_rec_device {
    char name[128];     /**< N: line, "" when absent */
    char phys[128];     /**< P: line */
    uint32_t bus, vendor, product; /**< I: line */
    uint8_t *desc;      /**< R: bytes */
    size_t desc_len;
    size_t event_count; /**< events of this device */
} pb_hid_rec_device;

typedef struct pb_hid_rec_event {
    int64_t t_ns;       /**< recorded time */
    uint32_t device;    /**< index in devices */
    uint32_t line;      /**< line in the file, for messages */
    size_t offset;      /**< first byte in pb_hid_recording.data */
    uint32_t len;
} pb_hid_rec_event;

typedef struct pb_hid_recording {
    pb_hid_rec_device *devices;
    size_t device_count;
    pb_hid_rec_event *events;  /**< in file order; times never decrease */
    size_t event_count;
    uint8_t *data;             /**< report bytes of all events */
    size_t data_len;
} pb_hid_recording;

/**
 * Parse a recording held in memory (`text` need not be NUL-terminated).
 * `name` labels messages ("file.hid:12: ..."). Every device must have a
 * descriptor. Returns POSE_OK, or POSE_ERR_FORMAT with the line in err.
 */
pose_status pb_hid_recording_parse(const char *text, size_t len, const char *name, pb_hid_recording **out,
                                   pb_error *err);

/** Read and parse a file (at most 256 MiB). */
pose_status pb_hid_recording_load(const char *path, pb_hid_recording **out, pb_error *err);

/** Free a recording; NULL is allowed. */
void pb_hid_recording_free(pb_hid_recording *rec);

/**
 * Write one device's header: `D: index` (when index >= 0), R:, N:, P:, I:
 * lines. Returns 0, or -1 on a write error.
 */
int pb_hid_recorder_write_device(FILE *f, int index, const pb_hid_rec_device *dev);

/** Write one `E:` line with a zero-padded timestamp. Returns 0, or -1 on a write error. */
int pb_hid_recorder_write_event(FILE *f, int64_t t_ns, const uint8_t *report, size_t len);

#endif /* POSE_BRIDGE_HID_RECORDER_H */
