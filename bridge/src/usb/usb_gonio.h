/* SPDX-License-Identifier: Apache-2.0
 *
 * The reference vendor-class goniometer box (bridge/devices/README.md):
 * the HID mannequin's 16 potentiometers behind a vendor-class interface
 * (class 0xFF), one 32-byte frame per 1 ms interrupt IN transfer on
 * endpoint 0x81 (full speed, wMaxPacketSize 32, bInterval 1):
 *
 *   bytes 0-1    sequence counter, uint16 little-endian, +1 per frame, wraps
 *   bytes 2-25   16 joint angles, 12-bit signed, packed little-endian
 *                (angle i at bit 12 i of byte 2), 0.1 degree per count
 *   byte 26      bit 0: the "hold pose" button
 *   bytes 27-29  zero
 *   bytes 30-31  CRC-16/CCITT-FALSE of bytes 0-29, little-endian
 *
 * 32 bytes: the kernel's usbmon text capture keeps exactly that much, so
 * captures taken with cat /sys/kernel/debug/usb/usbmon/Nu replay whole.
 * The motions and sensor errors are the HID mannequin's (hid_mannequin.h),
 * so the two devices' recordings share one truth.
 */
#ifndef POSE_BRIDGE_USB_GONIO_H
#define POSE_BRIDGE_USB_GONIO_H

#include <stdio.h>

#include "hid_mannequin.h"
#include "usb_frame.h"

enum {
    PB_GONIO_FRAME_BYTES = 32,
    PB_GONIO_VENDOR = 0x1209,  /**< pid.codes */
    PB_GONIO_PRODUCT = 0x0002, /**< placeholder: builders request their own */
    PB_GONIO_ENDPOINT = 0x81,
};

/** The box's layout (what bridge/maps/usb_gonio_full_body.json's "usb" object says). */
void pb_gonio_layout(pb_usb_layout *l);

/** Pack one frame from true angles: sensor error, noise from *rng (NULL none), 0.1-degree steps. */
void pb_gonio_pack(const pb_usb_layout *l, const double deg[PB_MANNEQUIN_AXES], int hold, uint16_t seq, uint32_t *rng,
                   uint8_t frame[PB_GONIO_FRAME_BYTES]);

/** Faults to inject into a capture (frame indices counted from 0). */
typedef struct pb_gonio_faults {
    int enabled;
    /* frames never sent (the counter skips them) */
    const uint32_t *lost;
    size_t lost_count;
    /* frames delivered after the next one (swapped with it) */
    const uint32_t *late;
    size_t late_count;
    /* frames delivered twice */
    const uint32_t *repeated;
    size_t repeated_count;
    /* transfers that stall (-32; the host clears the halt), babble (-75), fail on the wire (-71), come short (16 bytes),
     * or carry a flipped bit (checksum) instead of the frame, which the device then sends again */
    const uint32_t *stall, *babble, *wire, *short_xfer, *bad_crc;
    size_t stall_count, babble_count, wire_count, short_count, bad_crc_count;
    /* unplugged at this frame for unplug_ms (-108 on the transfer in flight, -19 on resubmission), 0 = never */
    uint32_t unplug_at;
    int unplug_ms;
} pb_gonio_faults;

/**
 * Write a usbmon "u" capture of the box running a motion for `seconds` at
 * rate_hz: the enumeration's control transfers, then S/C pairs on Ii:BUS:DEV:1
 * with the host's timing jitter, noise seed `seed`. Returns frames sent, or -1.
 */
long pb_gonio_write_capture(FILE *f, pb_mannequin_motion m, double rate_hz, double seconds, uint32_t seed,
                            const pb_gonio_faults *faults);

#endif /* POSE_BRIDGE_USB_GONIO_H */
