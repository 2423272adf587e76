/* SPDX-License-Identifier: Apache-2.0
 *
 * The Linux usbmon text format ("u", and the older "t" without the bus
 * number), as the kernel's Documentation/usb/usbmon.rst describes it: one
 * event a line, words separated by blanks:
 *
 *   URB-tag timestamp-us event address status [setup] [iso] length data-tag [data words]
 *   ffff88003b8f9c00 4014796128 C Ii:1:005:1 0:1 32 = 3a00d5ff ... 
 *
 * event S (submission), C (callback), E (submission error); address
 * "Ii:BUS:DEV:EP" (Ci Co Zi Zo Ii Io Bi Bo; "t" format: "Ii:DEV:EP");
 * status: a decimal URB status, for interrupt and isochronous transfers
 * with ":interval" (isochronous also ":start_frame"), or for control
 * submissions a setup tag (a letter, 's' when captured) and its five words;
 * isochronous events then carry an error count, a descriptor count and up
 * to five "status:offset:length" words; length: requested (submission) or
 * actual (callback); data tag: '=' when data words follow, else '<', '>'
 * or another character; data words: the bytes in order, in hex, four to a
 * word (the last may hold one to three). The kernel captures at most 32
 * bytes of data, so `captured` may be less than `length`; pose-bridge
 * usb-record writes every byte. Lines beginning with '#' and blank lines
 * are comments (an extension of pose's recorder for its header; the kernel
 * never writes them). Errors name the file, the line and the byte offset
 * of the word in the line.
 */
#ifndef POSE_BRIDGE_USBMON_H
#define POSE_BRIDGE_USBMON_H

#include <stdint.h>
#include <stdio.h>

#include "pb_error.h"

typedef struct pb_usbmon_event {
    int64_t t_us;       /**< timestamp, microseconds (the kernel's clock, wrapping at 2^32 in old kernels is not undone) */
    char event;         /**< 'S', 'C' or 'E' */
    char xfer;          /**< 'C' control, 'Z' isochronous, 'I' interrupt, 'B' bulk */
    uint8_t in;         /**< 1 for device-to-host */
    uint16_t bus;       /**< 0 when the line has none ("t" format) */
    uint16_t dev;
    uint8_t ep;         /**< endpoint number without the direction bit */
    int status;         /**< URB status (0 for a control submission's setup tag) */
    int interval;       /**< interrupt/iso interval, -1 when not given */
    uint32_t length;    /**< data length word */
    uint32_t captured;  /**< data bytes present on the line (at data + offset) */
    size_t offset;
    uint32_t line;
} pb_usbmon_event;

typedef struct pb_usbmon_capture {
    pb_usbmon_event *events;
    size_t count;
    uint8_t *data;
    size_t data_len;
    uint32_t comment_lines;
} pb_usbmon_capture;

/** Parse text (`name` for messages). Every line is an event or a comment, or it is an error. */
pose_status pb_usbmon_parse(const char *text, size_t len, const char *name, pb_usbmon_capture **out, pb_error *err);
pose_status pb_usbmon_load(const char *path, pb_usbmon_capture **out, pb_error *err);
void pb_usbmon_capture_free(pb_usbmon_capture *c);

/**
 * Write one event line: tag (hex), time, event, address with bus, status
 * (with ":interval" when interval >= 0), length, and the data ('=' and
 * words when data has bytes, else '<' for IN, '>' for OUT). Returns 0 or -1.
 */
int pb_usbmon_write(FILE *f, uint64_t tag, const pb_usbmon_event *e, const uint8_t *data);

#endif /* POSE_BRIDGE_USBMON_H */
