/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for the usbmon text reader (usbmon.h) and the simulated
 * device over it (usb_replay.c). A capture that parses must keep every
 * event's data inside the buffer, write back (pb_usbmon_write, for events
 * without a setup packet) to a line that parses to the same event, and
 * replay through the reference box's decoder to its end with every
 * completion accounted for. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pb_warn.h"
#include "usb_gonio.h"
#include "usb_source.h"
#include "usbmon.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_round_trip(const pb_usbmon_capture *c, size_t i)
{
    const pb_usbmon_event *e = &c->events[i];
    if (e->xfer == 'C' && e->event == 'S')
        return; /* a control submission's setup words are not kept */
    if (e->xfer == 'Z' || (e->event == 'E' && e->length == 0))
        return; /* isochronous descriptors are not kept either */
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return;
    pb_usbmon_event w = *e;
    if (w.interval >= 0 && w.xfer != 'I')
        w.interval = -1;
    int bad = pb_usbmon_write(f, 1, &w, c->data + e->offset);
    fclose(f);
    pb_usbmon_capture *back = NULL;
    pb_error err;
    if (bad || pb_usbmon_parse(buf, len, "rewritten", &back, &err) != POSE_OK || back->count != 1)
        abort();
    const pb_usbmon_event *b = &back->events[0];
    /* Nothing captured: the data may be NULL, and NULL + 0 is undefined. */
    if (b->t_us != e->t_us || b->event != e->event || b->xfer != e->xfer || b->in != e->in || b->dev != e->dev ||
        b->ep != e->ep || b->status != e->status || b->length != e->length || b->captured != e->captured ||
        (e->captured && memcmp(back->data + b->offset, c->data + e->offset, e->captured) != 0))
        abort();
    pb_usbmon_capture_free(back);
    free(buf);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static pb_warnings warnings;
    pb_warnings_install(&warnings);
    warnings.count = 0;
    pb_usbmon_capture *c = NULL;
    pb_error err;
    if (pb_usbmon_parse((const char *)data, size, "fuzz.usbmon", &c, &err) != POSE_OK) {
        if (!strstr(err.message, "fuzz.usbmon"))
            abort(); /* errors name the file */
        return 0;
    }
    for (size_t i = 0; i < c->count; i++) {
        const pb_usbmon_event *e = &c->events[i];
        if (e->offset + e->captured > c->data_len)
            abort();
        if (i < 64)
            check_round_trip(c, i);
    }
    if (c->count > 20000) {
        pb_usbmon_capture_free(c);
        return 0;
    }
    static pb_usb_layout l;
    pb_gonio_layout(&l);
    pb_source *src = NULL;
    pb_usb_replay_options o = {.as_fast_as_possible = 1, .source = {.hold_channel = "hold"}};
    if (pb_usb_replay_create(c, "fuzz.usbmon", &l, &o, &src, &err) != POSE_OK)
        return 0; /* the capture went with the failure */
    uint64_t updates = 0;
    for (int guard = 0; guard < 100000; guard++) {
        pb_update u;
        int r = pb_source_read(src, &u, 0);
        if (r < 0)
            break;
        updates += (uint64_t)r;
    }
    if (pb_usb_source_stats(src)->frames != updates)
        abort();
    pb_source_destroy(src);
    return 0;
}
