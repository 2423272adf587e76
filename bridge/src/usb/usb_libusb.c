/* SPDX-License-Identifier: Apache-2.0
 * The vendor-class USB transport on libusb 1.0: the only file of the USB
 * family that talks to hardware. Opens VID:PID[:serial], claims the
 * interface (detaching a bound kernel driver only when the layout says
 * "detach_kernel_driver": true, and giving it back on close), keeps four
 * asynchronous interrupt or bulk IN transfers in flight, and handles
 * libusb's events on the calling thread (the bridge thread): completions
 * land in a ring the source reads. Hotplug (libusb_hotplug_register_callback,
 * where the platform has it: Linux does) reports the device leaving and
 * coming back, so a reopen waits for the arrival instead of polling. A
 * stalled endpoint is cleared (libusb_clear_halt) before the next transfer. */
#include "usb_source.h"
#include "clock.h"

#if POSE_BRIDGE_HAVE_LIBUSB

#include <libusb.h>
#include <stdlib.h>
#include <string.h>

enum { IN_FLIGHT = 4, RING = 64 };

typedef struct slot {
    pb_usb_completion c;
    uint8_t data[PB_USB_MAX_FRAME];
} slot;

typedef struct live {
    pb_usb_transport base;
    libusb_context *ctx;
    libusb_device_handle *h;
    libusb_hotplug_callback_handle hp;
    int hp_registered;
    struct libusb_transfer *xfer[IN_FLIGHT];
    int active;                /* transfers submitted and not yet returned */
    int closing;
    int detached;              /* we detached a kernel driver: give it back */
    int need_clear_halt;
    volatile int arrived, left;/* set by the hotplug callback (same thread) */
    size_t want;               /* transfer length */
    slot ring[RING];
    unsigned head, tail;       /* ring: tail..head-1 hold completions */
    uint64_t ring_overflows;
} live;

static pb_usb_status from_libusb(enum libusb_transfer_status s)
{
    switch (s) {
    case LIBUSB_TRANSFER_COMPLETED: return PB_USB_XFER_OK;
    case LIBUSB_TRANSFER_STALL: return PB_USB_XFER_STALL;
    case LIBUSB_TRANSFER_OVERFLOW: return PB_USB_XFER_OVERFLOW;
    case LIBUSB_TRANSFER_NO_DEVICE: return PB_USB_XFER_NO_DEVICE;
    case LIBUSB_TRANSFER_CANCELLED: return PB_USB_XFER_CANCELLED;
    default: return PB_USB_XFER_ERROR; /* ERROR, TIMED_OUT */
    }
}

static void LIBUSB_CALL on_transfer(struct libusb_transfer *x)
{
    live *l = x->user_data;
    pb_usb_status st = from_libusb(x->status);
    if (st != PB_USB_XFER_CANCELLED) {
        if (l->head - l->tail < RING) {
            slot *s = &l->ring[l->head++ % RING];
            s->c.status = st;
            s->c.t_ns = pb_now_ns();
            s->c.len = st == PB_USB_XFER_OK ? (size_t)x->actual_length : 0;
            if (s->c.len > sizeof s->data)
                s->c.len = sizeof s->data;
            memcpy(s->data, x->buffer, s->c.len);
        } else {
            l->ring_overflows++; /* the reader fell 64 transfers behind */
        }
    }
    if (st == PB_USB_XFER_STALL)
        l->need_clear_halt = 1; /* resubmitted after the halt is cleared, outside the callback */
    if (l->closing || st == PB_USB_XFER_NO_DEVICE || st == PB_USB_XFER_CANCELLED || st == PB_USB_XFER_STALL ||
        libusb_submit_transfer(x) != 0)
        l->active--;
}

static int LIBUSB_CALL on_hotplug(libusb_context *ctx, libusb_device *dev, libusb_hotplug_event ev, void *user)
{
    (void)ctx;
    (void)dev;
    live *l = user;
    if (ev == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED)
        l->arrived = 1;
    else
        l->left = 1;
    return 0; /* stay registered */
}

static int serial_matches(libusb_device_handle *h, const struct libusb_device_descriptor *d, const char *want)
{
    unsigned char s[256];
    if (!want[0])
        return 1;
    if (!d->iSerialNumber || libusb_get_string_descriptor_ascii(h, d->iSerialNumber, s, sizeof s) < 0)
        return 0;
    return strcmp((const char *)s, want) == 0;
}

static void stop_transfers(live *l)
{
    l->closing = 1;
    for (int i = 0; i < IN_FLIGHT; i++)
        if (l->xfer[i])
            libusb_cancel_transfer(l->xfer[i]);
    struct timeval tv = {0, 100000};
    for (int spins = 0; l->active > 0 && spins < 50; spins++)
        libusb_handle_events_timeout_completed(l->ctx, &tv, NULL);
    for (int i = 0; i < IN_FLIGHT; i++) {
        if (l->xfer[i] && l->active <= 0)
            libusb_free_transfer(l->xfer[i]); /* frees the buffer too (LIBUSB_TRANSFER_FREE_BUFFER) */
        l->xfer[i] = NULL;
    }
    l->active = 0;
}

static void live_close(pb_usb_transport *t)
{
    live *l = (live *)t;
    if (!l->h)
        return;
    stop_transfers(l);
    libusb_release_interface(l->h, t->layout->interface);
    if (l->detached)
        libusb_attach_kernel_driver(l->h, t->layout->interface);
    libusb_close(l->h);
    l->h = NULL;
    l->detached = 0;
}

static int submit_all(live *l)
{
    const pb_usb_layout *ly = l->base.layout;
    for (int i = 0; i < IN_FLIGHT; i++) {
        if (!l->xfer[i]) {
            l->xfer[i] = libusb_alloc_transfer(0);
            unsigned char *buf = l->xfer[i] ? malloc(l->want) : NULL;
            if (!buf)
                return -1;
            if (ly->bulk)
                libusb_fill_bulk_transfer(l->xfer[i], l->h, ly->endpoint, buf, (int)l->want, on_transfer, l, 0);
            else
                libusb_fill_interrupt_transfer(l->xfer[i], l->h, ly->endpoint, buf, (int)l->want, on_transfer, l, 0);
            l->xfer[i]->flags |= LIBUSB_TRANSFER_FREE_BUFFER;
        }
        if (libusb_submit_transfer(l->xfer[i]) != 0)
            return -1;
        l->active++;
    }
    return 0;
}

static pose_status live_open(pb_usb_transport *t, pb_error *err)
{
    live *l = (live *)t;
    const pb_usb_layout *ly = t->layout;
    libusb_device **list;
    ssize_t n = libusb_get_device_list(l->ctx, &list);
    if (n < 0)
        return pb_fail(err, POSE_ERR_IO, "%s: libusb: %s", t->origin, libusb_strerror((int)n));
    int found = 0, last_error = 0;
    for (ssize_t i = 0; i < n && !l->h; i++) {
        struct libusb_device_descriptor d;
        if (libusb_get_device_descriptor(list[i], &d) != 0 || d.idVendor != ly->vid || d.idProduct != ly->pid)
            continue;
        found = 1;
        libusb_device_handle *h;
        if ((last_error = libusb_open(list[i], &h)) != 0)
            continue;
        if (!serial_matches(h, &d, ly->serial)) {
            libusb_close(h);
            continue;
        }
        /* the endpoint's packet size: transfers ask for whole packets, so only babble overflows */
        int mps = libusb_get_max_packet_size(list[i], ly->endpoint);
        if (mps <= 0) {
            last_error = LIBUSB_ERROR_NOT_FOUND;
            libusb_close(h);
            continue;
        }
        l->want = ((ly->frame_bytes + (size_t)mps - 1) / (size_t)mps) * (size_t)mps;
        l->h = h;
        t->bus = libusb_get_bus_number(list[i]);
        t->dev = libusb_get_device_address(list[i]);
    }
    libusb_free_device_list(list, 1);
    if (!l->h) {
        if (found && last_error)
            return pb_fail(err, last_error == LIBUSB_ERROR_ACCESS ? POSE_ERR_IO : POSE_ERR_NOT_FOUND,
                           "%s: found but not usable: %s%s", t->origin, libusb_strerror(last_error),
                           last_error == LIBUSB_ERROR_ACCESS ? " (install the udev rule of bridge/devices)" : "");
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no such device%s%s plugged in", t->origin,
                       ly->serial[0] ? " with serial " : "", ly->serial);
    }
    int active = libusb_kernel_driver_active(l->h, ly->interface);
    if (active == 1) {
        if (!ly->detach_kernel_driver) {
            live_close(t);
            return pb_fail(err, POSE_ERR_IO,
                           "%s: interface %d is bound to a kernel driver; set \"detach_kernel_driver\": true in the "
                           "map's \"usb\" object to take it over",
                           t->origin, ly->interface);
        }
        if (libusb_detach_kernel_driver(l->h, ly->interface) == 0)
            l->detached = 1;
    }
    int rc = libusb_claim_interface(l->h, ly->interface);
    if (rc != 0) {
        live_close(t);
        return pb_fail(err, POSE_ERR_IO, "%s: claiming interface %d: %s", t->origin, ly->interface,
                       libusb_strerror(rc));
    }
    l->closing = 0;
    l->left = 0;
    l->arrived = 0;
    l->need_clear_halt = 0;
    l->head = l->tail = 0;
    if (submit_all(l) != 0) {
        live_close(t);
        return pb_fail(err, POSE_ERR_IO, "%s: submitting transfers on endpoint 0x%02x failed", t->origin, ly->endpoint);
    }
    return POSE_OK;
}

static int live_read(pb_usb_transport *t, uint8_t *buf, size_t cap, int timeout_ms, pb_usb_completion *c)
{
    live *l = (live *)t;
    int64_t deadline = timeout_ms < 0 ? INT64_MAX : pb_now_ns() + (int64_t)timeout_ms * 1000000;
    for (;;) {
        if (l->tail != l->head) {
            slot *s = &l->ring[l->tail++ % RING];
            *c = s->c;
            if (c->len > cap)
                c->len = cap;
            memcpy(buf, s->data, c->len);
            return 1;
        }
        if (l->left)
            return PB_USB_READ_GONE;
        if (l->need_clear_halt) {
            l->need_clear_halt = 0;
            libusb_clear_halt(l->h, t->layout->endpoint);
            for (int i = 0; i < IN_FLIGHT; i++)
                if (l->active < IN_FLIGHT && libusb_submit_transfer(l->xfer[i]) == 0)
                    l->active++;
        }
        if (l->active == 0 && !l->need_clear_halt)
            return PB_USB_READ_GONE; /* every transfer ended: no device */
        /* handle events at least once, even when polled with timeout 0, then wait in slices of 100 ms */
        int64_t now = pb_now_ns();
        int64_t wait = deadline == INT64_MAX ? 100000000 : deadline - now;
        wait = wait < 0 ? 0 : wait > 100000000 ? 100000000 : wait;
        struct timeval tv = {(time_t)(wait / 1000000000), (long)(wait % 1000000000 / 1000)};
        libusb_handle_events_timeout_completed(l->ctx, &tv, NULL);
        if (l->tail == l->head && !l->left && !l->need_clear_halt && pb_now_ns() >= deadline)
            return 0;
    }
}

static int live_wait_arrival(pb_usb_transport *t, int timeout_ms)
{
    live *l = (live *)t;
    int64_t deadline = pb_now_ns() + (int64_t)timeout_ms * 1000000;
    for (;;) {
        int64_t left = deadline - pb_now_ns();
        left = left < 0 ? 0 : left;
        struct timeval tv = {(time_t)(left / 1000000000), (long)(left % 1000000000 / 1000)};
        libusb_handle_events_timeout_completed(l->ctx, &tv, NULL); /* once at least, even for timeout 0 */
        if (l->arrived) {
            l->arrived = 0;
            return 1;
        }
        if (pb_now_ns() >= deadline)
            return 0;
    }
}

static void live_destroy(pb_usb_transport *t)
{
    live *l = (live *)t;
    if (l->hp_registered)
        libusb_hotplug_deregister_callback(l->ctx, l->hp);
    if (l->ctx)
        libusb_exit(l->ctx);
    free(l);
}

static const pb_usb_transport_ops live_ops = {
    "usb", live_open, live_read, NULL, live_wait_arrival, live_close, live_destroy,
};

pose_status pb_usb_live_open(const char *spec, const pb_usb_layout *layout, const pb_usb_source_options *opt,
                             pb_source **out, pb_error *err)
{
    *out = NULL;
    pb_usb_layout *ly = malloc(sizeof *ly);
    if (!ly)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", spec);
    *ly = *layout;
    pose_status st = pb_usb_parse_spec(spec, ly, err);
    live *l = st == POSE_OK ? calloc(1, sizeof *l) : NULL;
    if (st == POSE_OK && !l)
        st = pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", spec);
    if (st != POSE_OK) {
        free(ly);
        return st;
    }
    l->base.ops = &live_ops;
    snprintf(l->base.origin, sizeof l->base.origin, "%s", spec);
    int rc = libusb_init(&l->ctx);
    if (rc != 0) {
        l->ctx = NULL;
        live_destroy(&l->base);
        free(ly);
        return pb_fail(err, POSE_ERR_IO, "%s: libusb_init: %s", spec, libusb_strerror(rc));
    }
    if (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) &&
        libusb_hotplug_register_callback(l->ctx, LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT,
                                         0, ly->vid, ly->pid, LIBUSB_HOTPLUG_MATCH_ANY, on_hotplug, l,
                                         &l->hp) == LIBUSB_SUCCESS) {
        l->hp_registered = 1;
        l->base.hotplug = 1;
    }
    st = pb_usb_source_create(&l->base, ly, opt, out, err); /* copies the layout */
    free(ly);
    return st;
}

#else /* built without libusb */

pose_status pb_usb_live_open(const char *spec, const pb_usb_layout *layout, const pb_usb_source_options *opt,
                             pb_source **out, pb_error *err)
{
    (void)layout;
    (void)opt;
    *out = NULL;
    return pb_fail(err, POSE_ERR_UNSUPPORTED,
                   "%s: this libpose_bridge was built without libusb 1.0 (libusb-1.0-0-dev); usbmon captures still "
                   "replay",
                   spec);
}

#endif
