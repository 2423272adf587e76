/* SPDX-License-Identifier: Apache-2.0
 *
 * Live SocketCAN source. Kept thin: socket setup here, the receive loop in
 * can_rx.c, decoding in can_decoder.c. When the interface goes away the
 * source reports DISCONNECTED and reopens it every 500 ms from read().
 */
#define _GNU_SOURCE 1 /* SO_RXQ_OVFL, SO_TIMESTAMPING */
#include "can_source.h"

#include <errno.h>
#include <net/if.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/raw.h>
#include <linux/net_tstamp.h>

#include "candump_log.h"

typedef struct can_live {
    pb_can_source_core core;
    pb_can_rx rx;
    int own_fd;
    int no_filters;
    char label[IFNAMSIZ + 16];
    char iface[IFNAMSIZ];    /* empty for a descriptor given by the caller */
    FILE *record;
    int64_t next_reopen_ns;
} can_live;

static void set_opt(int fd, int level, int name, int value)
{
    /* Best effort: a missing option (old kernel, socketpair) costs a feature, not the source. */
    (void)setsockopt(fd, level, name, &value, sizeof value);
}

static int socketcan_open(const char *iface, const pb_can_filter *filters, size_t count, pb_error *err)
{
    int fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        pb_fail(err, POSE_ERR_IO, "CAN: socket(PF_CAN): %s", strerror(errno));
        return -1;
    }
    struct ifreq ifr;
    memset(&ifr, 0, sizeof ifr);
    memcpy(ifr.ifr_name, iface, strlen(iface));
    if (ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
        pb_fail(err, POSE_ERR_IO, "CAN: interface %s: %s", iface, strerror(errno));
        close(fd);
        return -1;
    }
    set_opt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, 1);
    const can_err_mask_t errs = CAN_ERR_MASK;
    (void)setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errs, sizeof errs);
    if (count && count <= CAN_RAW_FILTER_MAX) {
        struct can_filter *kf = calloc(count, sizeof *kf);
        if (!kf) {
            close(fd);
            pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "CAN: out of memory");
            return -1;
        }
        for (size_t i = 0; i < count; i++) {
            /* Match the frame format too (EFF flag in the mask) and refuse remote frames. */
            kf[i].can_id = filters[i].id | (filters[i].extended ? CAN_EFF_FLAG : 0);
            kf[i].can_mask = filters[i].mask | CAN_EFF_FLAG | CAN_RTR_FLAG;
        }
        if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, kf, (socklen_t)(count * sizeof *kf)) < 0) {
            pb_fail(err, POSE_ERR_IO, "CAN: %s: filters: %s", iface, strerror(errno));
            free(kf);
            close(fd);
            return -1;
        }
        free(kf);
    }
    const int ts = SOF_TIMESTAMPING_RX_HARDWARE | SOF_TIMESTAMPING_RAW_HARDWARE |
                   SOF_TIMESTAMPING_RX_SOFTWARE | SOF_TIMESTAMPING_SOFTWARE;
    if (setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPING, &ts, sizeof ts) < 0)
        set_opt(fd, SOL_SOCKET, SO_TIMESTAMP, 1);
    set_opt(fd, SOL_SOCKET, SO_RXQ_OVFL, 1);
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    if (bind(fd, (struct sockaddr *)&addr, sizeof addr) < 0) {
        pb_fail(err, POSE_ERR_IO, "CAN: bind %s: %s", iface, strerror(errno));
        close(fd);
        return -1;
    }
    return fd;
}

static pb_can_socket_opener opener = socketcan_open;

void pb_can_set_socket_opener(pb_can_socket_opener fn) { opener = fn ? fn : socketcan_open; }

int pb_can_socket_open(const char *iface, const pb_can_filter *filters, size_t count, pb_error *err)
{
    if (!iface || strlen(iface) >= IFNAMSIZ) {
        pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "CAN: bad interface name");
        return -1;
    }
    return opener(iface, filters, count, err);
}

static void live_record(can_live *s, const pb_can_frame *f, int64_t real_ns)
{
    if (!s->record)
        return;
    pb_can_frame w = *f;
    w.t_ns = real_ns;
    /* On a write error (disk full) recording stops and the pose keeps running. */
    if (pb_candump_write(s->record, &w, s->iface[0] ? s->iface : "can0") != 0) {
        fclose(s->record);
        s->record = NULL;
    }
}

static int live_reopen(can_live *s)
{
    const int64_t now = pb_can_mono_ns();
    if (!s->iface[0] || now < s->next_reopen_ns)
        return -1;
    s->next_reopen_ns = now + 500000000;
    size_t nf = 0;
    const pb_can_filter *f = pb_can_decoder_filters(s->core.dec, &nf);
    int fd = pb_can_socket_open(s->iface, s->no_filters ? NULL : f, s->no_filters ? 0 : nf, NULL);
    if (fd < 0)
        return -1;
    pb_can_rx_init(&s->rx, fd);
    s->own_fd = 1;
    pb_source_set_state(&s->core.base, PB_SOURCE_WAITING, "%s reopened", s->label);
    return 0;
}

static int live_read(pb_source *src, pb_update *out, int timeout_ms)
{
    can_live *s = (can_live *)src;
    const int64_t deadline = timeout_ms < 0 ? INT64_MAX : pb_can_mono_ns() + (int64_t)timeout_ms * 1000000;
    for (;;) {
        if (s->rx.fd < 0 && live_reopen(s) != 0) {
            return -1;
        }
        int64_t left_ms = -1;
        if (timeout_ms >= 0) {
            const int64_t left = deadline - pb_can_mono_ns();
            left_ms = left > 0 ? (left + 999999) / 1000000 : 0;
        }
        pb_can_frame f;
        int64_t real;
        uint64_t drops;
        int r = pb_can_rx_read(&s->rx, &f, &real, &drops, left_ms > INT32_MAX ? INT32_MAX : (int)left_ms);
        if (drops)
            pb_can_decoder_add_dropped(s->core.dec, drops);
        if (r == 1) {
            live_record(s, &f, real);
            if (pb_can_source_core_frame(&s->core, &f, out))
                return 1;
        } else if (r == 0) {
            pb_can_decoder_tick(s->core.dec, pb_can_mono_ns());
            pb_can_source_core_report(&s->core);
            if (timeout_ms >= 0 && pb_can_mono_ns() >= deadline)
                return 0;
        } else if (r == -1) {
            const int e = errno;
            if (s->own_fd)
                close(s->rx.fd);
            s->rx.fd = -1;
            s->own_fd = 0;
            s->next_reopen_ns = pb_can_mono_ns() + 500000000;
            pb_source_set_state(src, PB_SOURCE_DISCONNECTED, "%s: %s%s", s->label, strerror(e),
                                s->iface[0] ? "; reopening" : "");
            return -1;
        }
        /* r == -2: not a frame, counted by the receiver; keep reading */
        if (timeout_ms >= 0 && pb_can_mono_ns() >= deadline)
            return 0;
    }
}

static void live_close(pb_source *src)
{
    can_live *s = (can_live *)src;
    if (s->own_fd && s->rx.fd >= 0)
        close(s->rx.fd);
    s->rx.fd = -1;
    if (s->record)
        fclose(s->record);
    s->record = NULL;
    pb_can_source_core_close(&s->core);
}

static const pb_source_ops live_ops = {"can", live_read, NULL, live_close};

static pose_status live_make(int fd, int own_fd, const char *label, const char *iface, pb_can_bus *bus,
                             const pb_can_live_options *opt, pb_source **out, pb_error *err)
{
    *out = NULL;
    can_live *s = calloc(1, sizeof *s);
    if (!s) {
        if (own_fd && fd >= 0)
            close(fd);
        pb_can_bus_free(bus);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "CAN: out of memory");
    }
    pose_status st = pb_can_source_core_init(&s->core, &live_ops, bus, err);
    pb_can_rx_init(&s->rx, fd);
    s->own_fd = own_fd;
    s->no_filters = opt && opt->no_filters;
    snprintf(s->label, sizeof s->label, "%s", label ? label : "CAN");
    if (iface)
        snprintf(s->iface, sizeof s->iface, "%s", iface);
    if (st == POSE_OK && opt && opt->record_path) {
        s->record = fopen(opt->record_path, "w");
        if (!s->record)
            st = pb_fail(err, POSE_ERR_IO, "%s: %s", opt->record_path, strerror(errno));
    }
    if (st != POSE_OK) {
        live_close(&s->core.base);
        free(s);
        return st;
    }
    *out = &s->core.base;
    return POSE_OK;
}

pose_status pb_can_live_open_fd(int fd, int own_fd, const char *label, pb_can_bus *bus,
                                const pb_can_live_options *opt, pb_source **out, pb_error *err)
{
    return live_make(fd, own_fd, label, NULL, bus, opt, out, err);
}

pose_status pb_can_live_open(const char *iface, pb_can_bus *bus, const pb_can_live_options *opt,
                             pb_source **out, pb_error *err)
{
    *out = NULL;
    pb_can_decoder *probe = NULL;
    /* The filters come from the decoder: build it once to learn them. */
    pose_status st = pb_can_decoder_create(pb_can_bus_config(bus), &probe, err);
    if (st != POSE_OK) {
        pb_can_bus_free(bus);
        return st;
    }
    size_t nf = 0;
    const pb_can_filter *f = pb_can_decoder_filters(probe, &nf);
    const int all = opt && opt->no_filters;
    int fd = pb_can_socket_open(iface, all ? NULL : f, all ? 0 : nf, err);
    pb_can_decoder_free(probe);
    if (fd < 0) {
        pb_can_bus_free(bus);
        return POSE_ERR_IO;
    }
    return live_make(fd, 1, iface, iface, bus, opt, out, err);
}
