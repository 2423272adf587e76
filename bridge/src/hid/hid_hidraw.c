/* SPDX-License-Identifier: Apache-2.0 */
#include "hid_hidraw.h"
#include "clock.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

#if defined(__linux__)
#include <linux/hidraw.h>
#endif

pose_status pb_hid_hidraw_descriptor(const char *path, uint8_t *buf, size_t cap, size_t *len, pb_error *err)
{
    *len = 0;
    const char *node = strrchr(path, '/');
    node = node ? node + 1 : path;
    char sys[128];
    snprintf(sys, sizeof sys, "/sys/class/hidraw/%.32s/device/report_descriptor", node);
    FILE *f = fopen(sys, "rb");
    if (f) {
        size_t n = fread(buf, 1, cap, f);
        int more = fgetc(f) != EOF;
        fclose(f);
        if (more)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: report descriptor larger than %zu bytes", sys, cap);
        if (n > 0) {
            *len = n;
            return POSE_OK;
        }
    }
#if defined(__linux__) && defined(HIDIOCGRDESC)
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return pb_fail(err, POSE_ERR_IO, "%s: cannot open to read its descriptor: %s", path, strerror(errno));
    int size = 0;
    struct hidraw_report_descriptor rd;
    pose_status st = POSE_OK;
    if (ioctl(fd, HIDIOCGRDESCSIZE, &size) < 0 || size <= 0 || (size_t)size > sizeof rd.value ||
        (size_t)size > cap) {
        st = pb_fail(err, POSE_ERR_IO, "%s: HIDIOCGRDESCSIZE failed: %s", path, strerror(errno));
    } else {
        rd.size = (unsigned)size;
        if (ioctl(fd, HIDIOCGRDESC, &rd) < 0) {
            st = pb_fail(err, POSE_ERR_IO, "%s: HIDIOCGRDESC failed: %s", path, strerror(errno));
        } else {
            memcpy(buf, rd.value, (size_t)size);
            *len = (size_t)size;
        }
    }
    close(fd);
    return st;
#else
    return pb_fail(err, POSE_ERR_UNSUPPORTED, "%s: no sysfs descriptor and no HIDIOCGRDESC here", path);
#endif
}

#if defined(POSE_BRIDGE_HAVE_HIDAPI)
#include <hidapi.h>

static void narrow(char *dst, size_t size, const wchar_t *w)
{
    size_t i = 0;
    for (; w && w[i] && i + 1 < size; i++)
        dst[i] = w[i] > 0 && w[i] < 0x7F ? (char)w[i] : '?'; /* names are for people; ASCII is enough */
    dst[i] = '\0';
}

/* hidapi bus types to the Linux BUS_* numbers hid-recorder writes on I: lines. */
static unsigned linux_bus(int bus)
{
    switch (bus) {
    case 1: return 0x03; /* USB */
    case 2: return 0x05; /* Bluetooth */
    case 3: return 0x18; /* I2C */
    case 4: return 0x1C; /* SPI */
    default: return 0;
    }
}

static int matches(const pb_hid_match *m, const struct hid_device_info *d)
{
    return (!m->vendor || m->vendor == d->vendor_id) && (!m->product || m->product == d->product_id) &&
           (!m->usage_page || m->usage_page == d->usage_page) && (!m->usage || m->usage == d->usage) &&
           (!m->path || strcmp(m->path, d->path) == 0);
}

static void fill(pb_hid_found *f, const struct hid_device_info *d)
{
    memset(f, 0, sizeof *f);
    snprintf(f->path, sizeof f->path, "%s", d->path);
    char man[64], prod[64];
    narrow(man, sizeof man, d->manufacturer_string);
    narrow(prod, sizeof prod, d->product_string);
    snprintf(f->info.name, sizeof f->info.name, "%s%s%s", man, man[0] && prod[0] ? " " : "", prod);
    snprintf(f->info.phys, sizeof f->info.phys, "%s", d->path);
    f->info.bus = linux_bus((int)d->bus_type);
    f->info.vendor = d->vendor_id;
    f->info.product = d->product_id;
    f->usage_page = d->usage_page;
    f->usage = d->usage;
}

pose_status pb_hid_hidraw_list(const pb_hid_match *match, pb_hid_found *found, size_t cap, size_t *count,
                               pb_error *err)
{
    static const pb_hid_match any;
    if (!match)
        match = &any;
    *count = 0;
    if (hid_init() != 0)
        return pb_fail(err, POSE_ERR_IO, "hidapi: hid_init failed");
    struct hid_device_info *all = hid_enumerate((unsigned short)match->vendor, (unsigned short)match->product);
    for (struct hid_device_info *d = all; d; d = d->next) {
        if (!matches(match, d))
            continue;
        if (*count < cap)
            fill(&found[*count], d);
        (*count)++;
    }
    hid_free_enumeration(all);
    return POSE_OK;
}

typedef struct hidraw {
    pb_hid_transport base;
    pb_hid_match match;
    char path_filter[64];
    hid_device *dev;
} hidraw;

static pose_status hidraw_open(pb_hid_transport *t, uint8_t *desc, size_t cap, size_t *len, pb_error *err)
{
    hidraw *h = (hidraw *)t;
    pb_hid_found f;
    size_t n = 0;
    /* Enumerate on every attempt: after an unplug the node number may change. */
    pose_status st = pb_hid_hidraw_list(&h->match, &f, 1, &n, err);
    if (st != POSE_OK)
        return st;
    if (n == 0)
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no matching HID device", t->origin);
    st = pb_hid_hidraw_descriptor(f.path, desc, cap, len, err);
    if (st != POSE_OK)
        return st;
    h->dev = hid_open_path(f.path);
    if (!h->dev)
        return pb_fail(err, POSE_ERR_IO, "%s: cannot open (permissions? see bridge/devices/README.md)", f.path);
    t->info = f.info;
    return POSE_OK;
}

static int hidraw_read(pb_hid_transport *t, uint8_t *buf, size_t cap, int timeout_ms, int64_t *t_ns)
{
    hidraw *h = (hidraw *)t;
    int n = hid_read_timeout(h->dev, buf, cap, timeout_ms);
    *t_ns = pb_now_ns();
    return n < 0 ? PB_HID_READ_GONE : n;
}

static void hidraw_close(pb_hid_transport *t)
{
    hidraw *h = (hidraw *)t;
    if (h->dev)
        hid_close(h->dev);
    h->dev = NULL;
}

static void hidraw_destroy(pb_hid_transport *t)
{
    hidraw_close(t);
    free(t);
}

static const pb_hid_transport_ops hidraw_ops = {"hid", hidraw_open, hidraw_read, NULL, hidraw_close, hidraw_destroy};

pose_status pb_hid_hidraw_open(const pb_hid_match *match, const pb_hid_source_options *opt, pb_source **out,
                               pb_error *err)
{
    *out = NULL;
    hidraw *h = calloc(1, sizeof *h);
    if (!h)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "hid: out of memory");
    h->base.ops = &hidraw_ops;
    if (match)
        h->match = *match;
    if (h->match.path) {
        snprintf(h->path_filter, sizeof h->path_filter, "%s", h->match.path);
        h->match.path = h->path_filter;
        snprintf(h->base.origin, sizeof h->base.origin, "%s", h->path_filter);
    } else {
        snprintf(h->base.origin, sizeof h->base.origin, "hid %04x:%04x usage %04x:%04x", h->match.vendor,
                 h->match.product, h->match.usage_page, h->match.usage);
    }
    return pb_hid_source_create(&h->base, opt, out, err);
}

#else /* built without hidapi: recordings still work, live devices do not */

pose_status pb_hid_hidraw_list(const pb_hid_match *match, pb_hid_found *found, size_t cap, size_t *count,
                               pb_error *err)
{
    (void)match;
    (void)found;
    (void)cap;
    *count = 0;
    return pb_fail(err, POSE_ERR_UNSUPPORTED, "hid: pose-bridge was built without hidapi (libhidapi-dev)");
}

pose_status pb_hid_hidraw_open(const pb_hid_match *match, const pb_hid_source_options *opt, pb_source **out,
                               pb_error *err)
{
    (void)match;
    (void)opt;
    *out = NULL;
    return pb_fail(err, POSE_ERR_UNSUPPORTED, "hid: pose-bridge was built without hidapi (libhidapi-dev)");
}
#endif
