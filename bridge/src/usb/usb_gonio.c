/* SPDX-License-Identifier: Apache-2.0 */
#include "usb_gonio.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "usbmon.h"

#define TWO_PI 6.283185307179586

void pb_gonio_layout(pb_usb_layout *l)
{
    memset(l, 0, sizeof *l);
    l->vid = PB_GONIO_VENDOR;
    l->pid = PB_GONIO_PRODUCT;
    l->interface = 0;
    l->endpoint = PB_GONIO_ENDPOINT;
    l->frame_bytes = PB_GONIO_FRAME_BYTES;
    l->has_sequence = 1;
    l->sequence = (pb_usb_field){0, 2, 0, 0, 0, 16};
    l->checksum = PB_USB_CHECKSUM_CRC16_CCITT;
    l->checksum_byte = 30;
    l->checksum_from = 0;
    l->checksum_to = 30;
    snprintf(l->hold_channel, sizeof l->hold_channel, "hold");
    for (int i = 0; i < PB_MANNEQUIN_AXES; i++) {
        pb_usb_channel *c = &l->channels[i];
        uint32_t bit = 12u * (uint32_t)i;
        /* two bytes hold the 12 bits: from the byte of the first bit, shifted by its bit within it */
        c->field = (pb_usb_field){2 + bit / 8, 2, 0, 1, (uint8_t)(bit % 8), 12};
        c->scale = 0.1;
        c->offset = 0;
        snprintf(c->name, sizeof c->name, "%s", pb_mannequin_axis_names[i]);
        snprintf(c->unit, sizeof c->unit, "deg");
    }
    pb_usb_channel *h = &l->channels[PB_MANNEQUIN_AXES];
    h->field = (pb_usb_field){26, 1, 0, 0, 0, 1};
    h->scale = 1;
    snprintf(h->name, sizeof h->name, "hold");
    l->channel_count = PB_MANNEQUIN_AXES + 1;
}

static double uniform(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return ((*s >> 8) + 0.5) / 16777216.0;
}

static double gaussian(uint32_t *s)
{
    double u = uniform(s), v = uniform(s);
    return sqrt(-2.0 * log(u)) * cos(TWO_PI * v);
}

void pb_gonio_pack(const pb_usb_layout *l, const double deg[PB_MANNEQUIN_AXES], int hold, uint16_t seq, uint32_t *rng,
                   uint8_t frame[PB_GONIO_FRAME_BYTES])
{
    memset(frame, 0, PB_GONIO_FRAME_BYTES);
    pb_usb_field_put(&l->sequence, frame, seq);
    for (int i = 0; i < PB_MANNEQUIN_AXES; i++) {
        double g, o;
        pb_mannequin_sensor(i, &g, &o);
        double v = g * deg[i] + o + (rng ? 0.12 * gaussian(rng) : 0.0);
        long c = lround(v * 10.0);
        c = c < -2048 ? -2048 : c > 2047 ? 2047 : c;
        pb_usb_field_put(&l->channels[i].field, frame, c);
    }
    frame[26] = hold ? 1 : 0;
    pb_usb_checksum_store(l, frame);
}

/* ------------------------------------------------------------- captures */

typedef struct writer {
    FILE *f;
    int64_t t0_us;
    uint64_t tag_base;
    unsigned bus, dev;
    int bad;
} writer;

static void line(writer *w, uint64_t tag, int64_t t_us, char event, char xfer, int in, unsigned ep, int status,
                 int interval, uint32_t length, const uint8_t *data, uint32_t captured)
{
    pb_usbmon_event e = {.t_us = w->t0_us + t_us, .event = event, .xfer = xfer, .in = (uint8_t)in,
                         .bus = (uint16_t)w->bus, .dev = (uint16_t)w->dev, .ep = (uint8_t)ep, .status = status,
                         .interval = interval, .length = length, .captured = captured};
    w->bad |= pb_usbmon_write(w->f, w->tag_base + tag, &e, data) != 0;
}

/* Control transfer with its setup packet (the writer has no setup words: written here). */
static void control(writer *w, int64_t t_us, int in, const char *setup, uint32_t length, const uint8_t *reply)
{
    uint64_t tag = w->tag_base + 0x100;
    if (fprintf(w->f, "%016llx %lld S C%c:%u:%03u:0 s %s %u %c\n", (unsigned long long)tag,
                (long long)(w->t0_us + t_us), in ? 'i' : 'o', w->bus, w->dev, setup, length, in ? '<' : '>') < 0)
        w->bad = 1;
    line(w, 0x100, t_us + 180, 'C', 'C', in, 0, 0, -1, length, reply, reply ? length : 0);
}

static void enumerate(writer *w, int64_t t_us)
{
    static const uint8_t device_desc[18] = {0x12, 0x01, 0x00, 0x02, 0x00, 0x00, 0x00, 0x40, 0x09,
                                            0x12, 0x02, 0x00, 0x00, 0x01, 0x01, 0x02, 0x03, 0x01};
    control(w, t_us, 1, "80 06 0100 0000 0012", 18, device_desc);
    control(w, t_us + 1000, 0, "00 09 0001 0000 0000", 0, NULL); /* SET_CONFIGURATION 1 */
}

static int listed(const uint32_t *v, size_t n, uint32_t k)
{
    for (size_t i = 0; i < n; i++)
        if (v[i] == k)
            return 1;
    return 0;
}

long pb_gonio_write_capture(FILE *f, pb_mannequin_motion m, double rate_hz, double seconds, uint32_t seed,
                            const pb_gonio_faults *fl)
{
    if (!(rate_hz > 0 && rate_hz <= 8000) || !(seconds > 0 && seconds <= 3600))
        return -1;
    static const pb_gonio_faults none = {0};
    if (!fl)
        fl = &none;
    pb_usb_layout l;
    pb_gonio_layout(&l);
    writer w = {f, 3141592653LL, 0xffff8881c2a4e000ULL, 3, 5, 0};
    uint32_t rng = seed ? seed : 1;
    const double period = 1.0 / rate_hz;
    const int interval = (int)lround(1000.0 / rate_hz) > 0 ? (int)lround(1000.0 / rate_hz) : 1;
    const size_t n = (size_t)(seconds * rate_hz);
    enumerate(&w, 0);
    const int64_t start_us = 5000; /* transfers begin 5 ms after SET_CONFIGURATION */
    line(&w, 1, start_us - 500, 'S', 'I', 1, 1, -EINPROGRESS, interval, 32, NULL, 0);
    uint8_t frame[PB_GONIO_FRAME_BYTES], held[PB_GONIO_FRAME_BYTES];
    int have_held = 0;
    uint16_t seq = 0;
    long sent = 0;
    int64_t back_at_us = -1, last_us = start_us - 500;
    for (size_t k = 0; k < n; k++) {
        double t = (double)k * period;
        double jitter = (uniform(&rng) - 0.5) * 0.08 * period;
        int64_t t_us = start_us + llround((t + jitter) * 1e6);
        if (t_us <= last_us)
            t_us = last_us + 1;
        double deg[PB_MANNEQUIN_AXES];
        int hold;
        pb_mannequin_pose(m, t, deg, &hold);
        if (back_at_us >= 0) {
            if (t_us < back_at_us)
                continue; /* unplugged: nothing on the bus */
            back_at_us = -1;
            w.dev++; /* re-enumerated at the next address; the box restarts its counter */
            seq = 0;
            enumerate(&w, t_us - 4000);
            line(&w, 1, t_us - 500, 'S', 'I', 1, 1, -EINPROGRESS, interval, 32, NULL, 0);
        }
        pb_gonio_pack(&l, deg, hold, seq, &rng, frame);
        uint16_t this_seq = seq++;
        (void)this_seq;
        last_us = t_us;
        uint32_t kk = (uint32_t)k;
        if (fl->unplug_at && kk == fl->unplug_at) {
            line(&w, 1, t_us, 'C', 'I', 1, 1, -ESHUTDOWN, interval, 0, NULL, 0);
            line(&w, 1, t_us + 40, 'E', 'I', 1, 1, -ENODEV, interval, 32, NULL, 0);
            back_at_us = t_us + (int64_t)fl->unplug_ms * 1000;
            have_held = 0;
            continue;
        }
        if (listed(fl->lost, fl->lost_count, kk))
            continue; /* the box skipped it: the counter moves on */
        /* failed transfers before the frame, which then comes */
        int pre_status = listed(fl->stall, fl->stall_count, kk)    ? -EPIPE
                         : listed(fl->babble, fl->babble_count, kk) ? -EOVERFLOW
                         : listed(fl->wire, fl->wire_count, kk)     ? -EPROTO
                                                                    : 0;
        if (pre_status) {
            line(&w, 1, t_us - 300, 'C', 'I', 1, 1, pre_status, interval, 0, NULL, 0);
            if (pre_status == -EPIPE) {
                /* the host clears the halt: CLEAR_FEATURE(ENDPOINT_HALT) on endpoint 0x81 */
                if (fprintf(f, "%016llx %lld S Co:%u:%03u:0 s 02 01 0000 0081 0000 0 >\n",
                            (unsigned long long)(w.tag_base + 0x200), (long long)(w.t0_us + t_us - 250), w.bus,
                            w.dev) < 0)
                    w.bad = 1;
                line(&w, 0x200, t_us - 200, 'C', 'C', 0, 0, 0, -1, 0, NULL, 0);
            }
            line(&w, 1, t_us - 150, 'S', 'I', 1, 1, -EINPROGRESS, interval, 32, NULL, 0);
        }
        if (listed(fl->short_xfer, fl->short_count, kk)) {
            line(&w, 1, t_us - 300, 'C', 'I', 1, 1, 0, interval, 16, frame, 16);
            line(&w, 1, t_us - 290, 'S', 'I', 1, 1, -EINPROGRESS, interval, 32, NULL, 0);
        }
        if (listed(fl->bad_crc, fl->bad_crc_count, kk)) {
            uint8_t bad[PB_GONIO_FRAME_BYTES];
            memcpy(bad, frame, sizeof bad);
            bad[9] ^= 0x10;
            line(&w, 1, t_us - 300, 'C', 'I', 1, 1, 0, interval, 32, bad, 32);
            line(&w, 1, t_us - 290, 'S', 'I', 1, 1, -EINPROGRESS, interval, 32, NULL, 0);
        }
        if (listed(fl->late, fl->late_count, kk)) {
            memcpy(held, frame, sizeof held); /* goes out after the next one */
            have_held = 1;
            continue;
        }
        line(&w, 1, t_us, 'C', 'I', 1, 1, 0, interval, 32, frame, 32);
        line(&w, 1, t_us + 3, 'S', 'I', 1, 1, -EINPROGRESS, interval, 32, NULL, 0);
        sent++;
        if (have_held) {
            line(&w, 1, t_us + 20, 'C', 'I', 1, 1, 0, interval, 32, held, 32);
            line(&w, 1, t_us + 23, 'S', 'I', 1, 1, -EINPROGRESS, interval, 32, NULL, 0);
            have_held = 0;
            sent++;
        }
        if (listed(fl->repeated, fl->repeated_count, kk)) {
            line(&w, 1, t_us + 30, 'C', 'I', 1, 1, 0, interval, 32, frame, 32);
            line(&w, 1, t_us + 33, 'S', 'I', 1, 1, -EINPROGRESS, interval, 32, NULL, 0);
            sent++;
        }
    }
    return w.bad ? -1 : sent;
}
