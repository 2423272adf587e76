/* SPDX-License-Identifier: Apache-2.0
 * HID devices without a hidraw node (usbhid detached, containers without
 * /dev/hidraw) through hidapi's libusb backend (libhidapi-libusb0, the same
 * API as the hidraw backend): the thin hardware file of "hidusb:" sources.
 *
 * Both hidapi backends export the same symbols, and libpose_bridge links the
 * hidraw one, so the libusb backend is loaded at run time with dlmopen into
 * a link-map namespace of its own, where its calls resolve to itself.
 * hidapi 0.13 hands out no report descriptor: it is read here first, with a
 * GET_DESCRIPTOR(Report) control transfer to the interface through libusb
 * (before hidapi claims the interface). Reports then come from hidapi's
 * reader thread (hid_read_timeout); libusb's hotplug callback reports the
 * device leaving (the read gives up at once) and coming back (until then a
 * reopen attempt costs a flag test, not an enumeration). The HID source
 * (hid_source.c) decodes, keeps the states and reopens as for hidraw. */
#define _GNU_SOURCE /* dlmopen */
#include "usb_hid.h"
#include "clock.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if POSE_BRIDGE_HAVE_LIBUSB && defined(POSE_BRIDGE_HAVE_HIDAPI)

#include <dlfcn.h>
#include <hidapi.h>
#include <libusb.h>

typedef struct hidapi_fns {
    void *lib;
    int (*init)(void);
    struct hid_device_info *(*enumerate)(unsigned short, unsigned short);
    void (*free_enumeration)(struct hid_device_info *);
    hid_device *(*open_path)(const char *);
    int (*read_timeout)(hid_device *, unsigned char *, size_t, int);
    void (*close)(hid_device *);
} hidapi_fns;

typedef struct hidusb {
    pb_hid_transport base;
    unsigned vid, pid;
    int iface;               /* -1: the first HID interface */
    hidapi_fns api;
    libusb_context *ctx;
    libusb_hotplug_callback_handle hp;
    int hotplug;
    volatile int arrived, left;
    hid_device *dev;
} hidusb;

static int LIBUSB_CALL on_hotplug(libusb_context *ctx, libusb_device *d, libusb_hotplug_event ev, void *user)
{
    (void)ctx;
    (void)d;
    hidusb *h = user;
    if (ev == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED)
        h->arrived = 1;
    else
        h->left = 1;
    return 0;
}

static void pump(hidusb *h)
{
    struct timeval zero = {0, 0};
    if (h->hotplug)
        libusb_handle_events_timeout_completed(h->ctx, &zero, NULL);
}

/* GET_DESCRIPTOR(Report) on the device's HID interface, through our own libusb handle. */
static pose_status read_descriptor(hidusb *h, uint8_t *desc, size_t cap, size_t *len, int *iface_out, pb_error *err)
{
    libusb_device_handle *dh = libusb_open_device_with_vid_pid(h->ctx, (uint16_t)h->vid, (uint16_t)h->pid);
    if (!dh)
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no such device plugged in (or no permission: see "
                       "bridge/devices/README.md)", h->base.origin);
    struct libusb_config_descriptor *cfg = NULL;
    pose_status st = POSE_ERR_NOT_FOUND;
    if (libusb_get_active_config_descriptor(libusb_get_device(dh), &cfg) != 0 || !cfg) {
        libusb_close(dh);
        return pb_fail(err, POSE_ERR_IO, "%s: cannot read the configuration descriptor", h->base.origin);
    }
    int iface = -1;
    uint16_t want = 4096;
    for (int i = 0; i < cfg->bNumInterfaces && iface < 0; i++) {
        const struct libusb_interface_descriptor *id = &cfg->interface[i].altsetting[0];
        if (id->bInterfaceClass != LIBUSB_CLASS_HID || (h->iface >= 0 && id->bInterfaceNumber != h->iface))
            continue;
        iface = id->bInterfaceNumber;
        /* the HID class descriptor (0x21) gives the report descriptor's length at bytes 7-8 */
        for (int k = 0; k + 9 <= id->extra_length; k += id->extra[k] ? id->extra[k] : id->extra_length) {
            if (id->extra[k + 1] == 0x21 && id->extra[k] >= 9)
                want = (uint16_t)(id->extra[k + 7] | id->extra[k + 8] << 8);
        }
    }
    libusb_free_config_descriptor(cfg);
    if (iface < 0) {
        libusb_close(dh);
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no HID interface%s", h->base.origin,
                       h->iface >= 0 ? " with that number" : "");
    }
    if (want > cap)
        want = (uint16_t)cap;
    int n = libusb_control_transfer(dh, LIBUSB_ENDPOINT_IN | LIBUSB_REQUEST_TYPE_STANDARD | LIBUSB_RECIPIENT_INTERFACE,
                                    LIBUSB_REQUEST_GET_DESCRIPTOR, 0x22 << 8, (uint16_t)iface, desc, want, 1000);
    if (n <= 0) {
        st = pb_fail(err, POSE_ERR_IO, "%s: GET_DESCRIPTOR(Report) on interface %d: %s", h->base.origin, iface,
                     n < 0 ? libusb_strerror(n) : "empty");
    } else {
        *len = (size_t)n;
        *iface_out = iface;
        st = POSE_OK;
    }
    libusb_close(dh); /* gives back the interface usbfs claimed for the request */
    return st;
}

static pose_status hidusb_open(pb_hid_transport *t, uint8_t *desc, size_t cap, size_t *len, pb_error *err)
{
    hidusb *h = (hidusb *)t;
    pump(h);
    if (h->hotplug && h->left && !h->arrived)
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: unplugged; waiting for hotplug to report it back", t->origin);
    h->left = h->arrived = 0;
    int iface = -1;
    pose_status st = read_descriptor(h, desc, cap, len, &iface, err);
    if (st != POSE_OK)
        return st;
    struct hid_device_info *all = h->api.enumerate((unsigned short)h->vid, (unsigned short)h->pid), *d = all;
    while (d && d->interface_number != iface)
        d = d->next;
    if (!d) {
        h->api.free_enumeration(all);
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: hidapi (libusb) does not list interface %d", t->origin, iface);
    }
    h->dev = h->api.open_path(d->path);
    if (h->dev) {
        char name[120] = "";
        size_t k = 0;
        for (const wchar_t *w = d->product_string; w && *w && k + 1 < sizeof name; w++)
            name[k++] = *w > 0 && *w < 0x7F ? (char)*w : '?';
        name[k] = '\0';
        snprintf(t->info.name, sizeof t->info.name, "%s", name);
        snprintf(t->info.phys, sizeof t->info.phys, "%s", d->path);
        t->info.bus = 0x03;
        t->info.vendor = d->vendor_id;
        t->info.product = d->product_id;
    }
    h->api.free_enumeration(all);
    if (!h->dev)
        return pb_fail(err, POSE_ERR_IO, "%s: hidapi (libusb) cannot open interface %d (permissions, or a kernel "
                       "driver holds it: this path is for devices without one)", t->origin, iface);
    return POSE_OK;
}

static int hidusb_read(pb_hid_transport *t, uint8_t *buf, size_t cap, int timeout_ms, int64_t *t_ns)
{
    hidusb *h = (hidusb *)t;
    pump(h);
    if (h->left)
        return PB_HID_READ_GONE;
    int n = h->api.read_timeout(h->dev, buf, cap, timeout_ms);
    *t_ns = pb_now_ns();
    return n < 0 ? PB_HID_READ_GONE : n;
}

static void hidusb_close(pb_hid_transport *t)
{
    hidusb *h = (hidusb *)t;
    if (h->dev)
        h->api.close(h->dev);
    h->dev = NULL;
}

static void hidusb_destroy(pb_hid_transport *t)
{
    hidusb *h = (hidusb *)t;
    hidusb_close(t);
    if (h->hotplug)
        libusb_hotplug_deregister_callback(h->ctx, h->hp);
    if (h->ctx)
        libusb_exit(h->ctx);
    /* the hidapi namespace stays loaded: its libusb context lives until exit */
    free(h);
}

static const pb_hid_transport_ops hidusb_ops = {"hid", hidusb_open, hidusb_read, NULL, hidusb_close, hidusb_destroy};

static pose_status load_hidapi(hidapi_fns *f, const char *origin, pb_error *err)
{
    static const char *const names[] = {"libhidapi-libusb.so.0", "libhidapi-libusb.so"};
    for (size_t i = 0; i < 2 && !f->lib; i++) {
#if defined(LM_ID_NEWLM)
        f->lib = dlmopen(LM_ID_NEWLM, names[i], RTLD_NOW | RTLD_LOCAL);
#else
        f->lib = dlopen(names[i], RTLD_NOW | RTLD_LOCAL);
#endif
    }
    if (!f->lib)
        return pb_fail(err, POSE_ERR_UNSUPPORTED, "%s: hidapi's libusb backend is not installed (libhidapi-libusb0): %s",
                       origin, dlerror());
    *(void **)&f->init = dlsym(f->lib, "hid_init");
    *(void **)&f->enumerate = dlsym(f->lib, "hid_enumerate");
    *(void **)&f->free_enumeration = dlsym(f->lib, "hid_free_enumeration");
    *(void **)&f->open_path = dlsym(f->lib, "hid_open_path");
    *(void **)&f->read_timeout = dlsym(f->lib, "hid_read_timeout");
    *(void **)&f->close = dlsym(f->lib, "hid_close");
    if (!f->init || !f->enumerate || !f->free_enumeration || !f->open_path || !f->read_timeout || !f->close)
        return pb_fail(err, POSE_ERR_UNSUPPORTED, "%s: libhidapi-libusb lacks the hidapi 0.13 functions", origin);
    if (f->init() != 0)
        return pb_fail(err, POSE_ERR_IO, "%s: hid_init (libusb backend) failed", origin);
    return POSE_OK;
}

pose_status pb_usb_hid_open(const char *spec, const pb_hid_source_options *opt, pb_source **out, pb_error *err)
{
    *out = NULL;
    unsigned v[3] = {0, 0, 0};
    int n = 0;
    const char *p = strncmp(spec, "hidusb:", 7) == 0 ? spec + 7 : spec;
    while (n < 3 && *p) {
        char *end;
        unsigned long x = strtoul(p, &end, n < 2 ? 16 : 10);
        if (end == p || x > (n < 2 ? 0xFFFFul : 255ul) || (*end && *end != ':'))
            break;
        v[n++] = (unsigned)x;
        p = *end ? end + 1 : end;
    }
    if (*p || n < 2)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT,
                       "%s: expected hidusb:VID:PID[:INTERFACE] (hex ids, decimal interface number)", spec);
    hidusb *h = calloc(1, sizeof *h);
    if (!h)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", spec);
    h->base.ops = &hidusb_ops;
    h->vid = v[0];
    h->pid = v[1];
    h->iface = n == 3 ? (int)v[2] : -1;
    snprintf(h->base.origin, sizeof h->base.origin, "hidusb %04x:%04x", h->vid, h->pid);
    pose_status st = load_hidapi(&h->api, h->base.origin, err);
    int rc = st == POSE_OK ? libusb_init(&h->ctx) : 0;
    if (rc != 0) {
        h->ctx = NULL;
        st = pb_fail(err, POSE_ERR_IO, "%s: libusb_init: %s", h->base.origin, libusb_strerror(rc));
    }
    if (st != POSE_OK) {
        hidusb_destroy(&h->base);
        return st;
    }
    if (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) &&
        libusb_hotplug_register_callback(h->ctx, LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT,
                                         0, (int)h->vid, (int)h->pid, LIBUSB_HOTPLUG_MATCH_ANY, on_hotplug, h,
                                         &h->hp) == LIBUSB_SUCCESS)
        h->hotplug = 1;
    return pb_hid_source_create(&h->base, opt, out, err);
}

#else

pose_status pb_usb_hid_open(const char *spec, const pb_hid_source_options *opt, pb_source **out, pb_error *err)
{
    (void)opt;
    *out = NULL;
    return pb_fail(err, POSE_ERR_UNSUPPORTED,
                   "%s: this libpose_bridge was built without libusb 1.0 or hidapi (libusb-1.0-0-dev, libhidapi-dev)",
                   spec);
}

#endif
