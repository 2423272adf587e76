/* SPDX-License-Identifier: Apache-2.0
 *
 * Vendor-class USB frames: a device sends one fixed binary frame per
 * interrupt or bulk IN transfer. Its layout is described in the mapping's
 * "usb" object (or a file holding just that object):
 *
 *   "usb": {
 *     "vid": "0x1209", "pid": "0x0002", "serial": "GON-0042",   live devices (optional here)
 *     "interface": 0, "endpoint": "0x81", "transfer": "interrupt" | "bulk",
 *     "detach_kernel_driver": false,         detach a bound kernel driver only when true
 *     "frame_bytes": 32,                     the transfer length of a good frame
 *     "hold_channel": "hold",                optional: freezes the pose while non-zero
 *     "sequence": {"byte": 0, "size": 2, "endian": "little"},        optional: drop detection
 *     "checksum": {"kind": "crc16-ccitt" | "sum8" | "xor8", "byte": 30,
 *                  "from": 0, "to": 30, "endian": "little"},         optional
 *     "channels": [
 *       {"name": "knee_l.flexion", "byte": 2, "size": 2, "endian": "little",
 *        "signed": true, "shift": 0, "bits": 12, "scale": 0.1, "offset": 0, "unit": "deg"}
 *     ]
 *   }
 *
 * A channel reads `size` bytes (1, 2, 4 or 8) at `byte` as an unsigned
 * integer of that endianness, shifts it right by `shift`, keeps `bits` bits
 * (default size * 8), sign-extends when `signed`, and reports
 * value * scale + offset. The checksum covers bytes [from, to) and is stored
 * at `byte` (two bytes for crc16, one for sum8/xor8).
 *
 * The decoder checks a transfer against the layout (length, checksum) and
 * tracks the sequence counter: a counter that skips counts the frames lost;
 * one that goes back (a frame delivered late or twice) counts a reordered
 * frame, which is not decoded (its values are older than the ones held) and
 * takes back one of the frames counted lost when it was one of them.
 */
#ifndef POSE_BRIDGE_USB_FRAME_H
#define POSE_BRIDGE_USB_FRAME_H

#include <stddef.h>
#include <stdint.h>

#include "pb_error.h"
#include "source.h"

enum { PB_USB_MAX_CHANNELS = 256, PB_USB_MAX_FRAME = 4096 };

typedef enum pb_usb_checksum_kind {
    PB_USB_CHECKSUM_NONE = 0,
    PB_USB_CHECKSUM_SUM8 = 1,       /**< low byte of the sum of the bytes */
    PB_USB_CHECKSUM_XOR8 = 2,       /**< xor of the bytes */
    PB_USB_CHECKSUM_CRC16_CCITT = 3,/**< CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF */
} pb_usb_checksum_kind;

typedef struct pb_usb_field {
    uint32_t byte;    /**< offset of the first byte */
    uint8_t size;     /**< 1, 2, 4 or 8 */
    uint8_t big_endian;
    uint8_t is_signed;
    uint8_t shift;    /**< right shift of the raw integer */
    uint8_t bits;     /**< bits kept after the shift (1..64) */
} pb_usb_field;

typedef struct pb_usb_channel {
    char name[64];
    char unit[16];
    pb_usb_field field;
    double scale, offset;
} pb_usb_channel;

typedef struct pb_usb_layout {
    /* the device (live sources; 0 / empty when not given) */
    uint16_t vid, pid;
    char serial[128];
    int interface;
    uint8_t endpoint;       /**< with the direction bit: 0x81 */
    int bulk;               /**< 0 interrupt, 1 bulk */
    int detach_kernel_driver;
    char hold_channel[64];  /**< "hold_channel": a channel that freezes the pose while non-zero, or "" */
    /* the frame */
    uint32_t frame_bytes;
    int has_sequence;
    pb_usb_field sequence;
    pb_usb_checksum_kind checksum;
    uint32_t checksum_byte, checksum_from, checksum_to;
    int checksum_big_endian;
    size_t channel_count;
    pb_usb_channel channels[PB_USB_MAX_CHANNELS];
} pb_usb_layout;

/** Parse the "usb" object of a mapping (or the whole text when it is the object). Errors name `name` and the key. */
pose_status pb_usb_layout_parse(const char *json, size_t len, const char *name, pb_usb_layout *out, pb_error *err);
/** From a file (see above). */
pose_status pb_usb_layout_load(const char *path, pb_usb_layout *out, pb_error *err);
/** Check a layout built in code: fields inside the frame, sizes valid. */
pose_status pb_usb_layout_check(const pb_usb_layout *l, const char *name, pb_error *err);

/** The raw integer of a field (bounds are the caller's: field inside len). */
int64_t pb_usb_field_get(const pb_usb_field *f, const uint8_t *frame);
/** Write the low bits of v into a field (for generators and tests). */
void pb_usb_field_put(const pb_usb_field *f, uint8_t *frame, int64_t v);
/** The checksum of bytes [from, to) of the layout's kind. */
uint32_t pb_usb_checksum(pb_usb_checksum_kind kind, const uint8_t *p, size_t n);
/** Store the checksum into a frame built for the layout. */
void pb_usb_checksum_store(const pb_usb_layout *l, uint8_t *frame);

/** What a transfer did (the outcome the transport reports). */
typedef enum pb_usb_status {
    PB_USB_XFER_OK = 0,
    PB_USB_XFER_STALL = 1,     /**< endpoint halted (EPIPE) */
    PB_USB_XFER_OVERFLOW = 2,  /**< babble: the device sent more than asked (EOVERFLOW) */
    PB_USB_XFER_NO_DEVICE = 3, /**< unplugged (ENODEV, ESHUTDOWN) */
    PB_USB_XFER_ERROR = 4,     /**< CRC/bit-stuff/timeout on the wire (EPROTO, EILSEQ, ETIME ...) */
    PB_USB_XFER_CANCELLED = 5, /**< unlinked by the host (ENOENT, ECONNRESET) */
} pb_usb_status;

const char *pb_usb_status_name(pb_usb_status s);
/** A Linux URB status (negative errno, as usbmon prints it) as a transfer outcome. */
pb_usb_status pb_usb_status_from_errno(int urb_status);

typedef enum pb_usb_decode_result {
    PB_USB_DECODE_OK = 0,
    PB_USB_DECODE_SHORT = 1,     /**< fewer bytes than frame_bytes */
    PB_USB_DECODE_LONG = 2,      /**< more bytes than frame_bytes */
    PB_USB_DECODE_CHECKSUM = 3,  /**< checksum mismatch */
    PB_USB_DECODE_REORDERED = 4, /**< sequence counter went back: late or repeated frame, not decoded */
} pb_usb_decode_result;

const char *pb_usb_decode_result_string(pb_usb_decode_result r);

/** Counters of a decoder. */
typedef struct pb_usb_frame_stats {
    uint64_t frames;      /**< decoded */
    uint64_t short_frames, long_frames, bad_checksums;
    uint64_t lost;        /**< sequence numbers never seen (skips, less the late frames that filled them) */
    uint64_t reordered;   /**< frames whose counter went back (late or repeated) */
    uint64_t stalls, overflows, wire_errors, disconnects;
} pb_usb_frame_stats;

typedef struct pb_usb_decoder {
    const pb_usb_layout *layout;
    double *values;        /**< channel_count, last good values */
    int64_t *raw;          /**< channel_count, last good raw integers */
    uint64_t last_seq;
    uint64_t seen;         /**< bit k: counter last_seq - k was decoded */
    int gone;              /**< the device left and no frame came since (one disconnect counted) */
    int have_seq;
    uint64_t seq_modulus;  /**< 2^(sequence bits) */
    pb_usb_frame_stats stats;
} pb_usb_decoder;

/** Allocate a decoder for a layout (which must outlive it). */
pose_status pb_usb_decoder_init(pb_usb_decoder *d, const pb_usb_layout *l, pb_error *err);
void pb_usb_decoder_free(pb_usb_decoder *d);
/** Forget the sequence (a device that reconnected starts counting anew). */
void pb_usb_decoder_resync(pb_usb_decoder *d);
/**
 * Decode one completed transfer into d->values (changed only on OK) and
 * count it. *seq (may be NULL) receives the frame's counter when it has one.
 */
pb_usb_decode_result pb_usb_decode(pb_usb_decoder *d, const uint8_t *frame, size_t len, uint64_t *seq);
/** Count a transfer that did not complete (stall, babble, wire error, unplug: one disconnect until a frame decodes, and the sequence restarts). */
void pb_usb_decoder_count_status(pb_usb_decoder *d, pb_usb_status s);
/** The layout's channels as source channels (count = layout->channel_count). */
void pb_usb_layout_channels(const pb_usb_layout *l, pb_channel *out);

#endif /* POSE_BRIDGE_USB_FRAME_H */
