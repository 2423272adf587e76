/* SPDX-License-Identifier: Apache-2.0 */
#define _GNU_SOURCE 1 /* SO_RXQ_OVFL, SO_TIMESTAMPING, struct scm_timestamping */
#include "can_rx.h"

#include <errno.h>
#include <poll.h>
#include <stddef.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/errqueue.h>

#include "can_error.h"

_Static_assert(CAN_ERR_BUSOFF == PB_CAN_ERR_BUSOFF && CAN_ERR_CRTL == PB_CAN_ERR_CRTL &&
                   CAN_ERR_RESTARTED == PB_CAN_ERR_RESTARTED,
               "portable error classes must match linux/can/error.h");

static int64_t clock_ns(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

int64_t pb_can_mono_ns(void) { return clock_ns(CLOCK_MONOTONIC); }
int64_t pb_can_real_ns(void) { return clock_ns(CLOCK_REALTIME); }

void pb_can_rx_init(pb_can_rx *rx, int fd)
{
    memset(rx, 0, sizeof *rx);
    rx->fd = fd;
}

/* Kernel frame bytes -> pb_can_frame. Classic frames are CAN_MTU bytes, FD
 * frames CANFD_MTU; anything else is not a frame. */
static int convert(const struct canfd_frame *k, size_t n, pb_can_frame *f)
{
    memset(f, 0, offsetof(pb_can_frame, data));
    if (n != CAN_MTU && n != CANFD_MTU)
        return 0;
    const canid_t id = k->can_id;
    if (id & CAN_ERR_FLAG) {
        f->flags = PB_CAN_ERR;
        f->id = id & CAN_ERR_MASK;
    } else if (id & CAN_EFF_FLAG) {
        f->flags = PB_CAN_EXT;
        f->id = id & CAN_EFF_MASK;
    } else {
        f->id = id & CAN_SFF_MASK;
    }
    if (n == CAN_MTU) {
        const struct can_frame *c = (const struct can_frame *)k;
        f->len = c->len > 8 ? 8 : c->len;
        f->dlc = f->len;
        if (f->len == 8 && c->len8_dlc > 8 && c->len8_dlc <= 15)
            f->dlc = c->len8_dlc;
        if (id & CAN_RTR_FLAG)
            f->flags |= PB_CAN_RTR;
    } else {
        f->flags |= PB_CAN_FD;
        if (k->flags & CANFD_BRS)
            f->flags |= PB_CAN_BRS;
        if (k->flags & CANFD_ESI)
            f->flags |= PB_CAN_ESI;
        f->len = k->len > CANFD_MAX_DLEN ? CANFD_MAX_DLEN : k->len;
        f->dlc = f->len;
    }
    if (f->flags & PB_CAN_RTR)
        f->len = 0;
    memcpy(f->data, k->data, f->len);
    return 1;
}

int64_t pb_can_rx_ancillary(pb_can_rx *rx, const struct msghdr *msg, int64_t real, uint64_t *new_drops)
{
    int64_t stamp = 0;
    *new_drops = 0;
    for (struct cmsghdr *c = CMSG_FIRSTHDR(msg); c; c = CMSG_NXTHDR((struct msghdr *)msg, c)) {
        if (c->cmsg_level != SOL_SOCKET)
            continue;
        if (c->cmsg_type == SO_TIMESTAMPING) {
            struct scm_timestamping ts;
            memcpy(&ts, CMSG_DATA(c), sizeof ts);
            const int64_t sw = (int64_t)ts.ts[0].tv_sec * 1000000000 + ts.ts[0].tv_nsec;
            const int64_t hw = (int64_t)ts.ts[2].tv_sec * 1000000000 + ts.ts[2].tv_nsec;
            /* A raw hardware stamp counts on the adapter's clock; trust it only
             * when the driver has put it on the wall clock (within a second of it). */
            if (hw && hw > real - 1000000000 && hw < real + 1000000000)
                stamp = hw;
            else if (sw)
                stamp = sw;
        } else if (c->cmsg_type == SO_TIMESTAMP && !stamp) {
            struct timeval tv;
            memcpy(&tv, CMSG_DATA(c), sizeof tv);
            stamp = (int64_t)tv.tv_sec * 1000000000 + (int64_t)tv.tv_usec * 1000;
        } else if (c->cmsg_type == SO_RXQ_OVFL) {
            uint32_t ovfl;
            memcpy(&ovfl, CMSG_DATA(c), sizeof ovfl);
            /* The counter is cumulative per socket and wraps at 2^32. */
            const uint32_t d = rx->have_ovfl ? ovfl - rx->ovfl : ovfl;
            rx->ovfl = ovfl;
            rx->have_ovfl = 1;
            rx->dropped += d;
            *new_drops = d;
        }
    }
    return stamp;
}

int pb_can_rx_read(pb_can_rx *rx, pb_can_frame *f, int64_t *real_ns, uint64_t *new_drops,
                   int timeout_ms)
{
    if (new_drops)
        *new_drops = 0;
    struct pollfd p = {.fd = rx->fd, .events = POLLIN};
    int r;
    do
        r = poll(&p, 1, timeout_ms);
    while (r < 0 && errno == EINTR);
    if (r < 0)
        return -1;
    if (r == 0)
        return 0;
    if (!(p.revents & POLLIN)) {
        errno = (p.revents & POLLNVAL) ? EBADF : (p.revents & POLLHUP) ? EPIPE : ENODEV;
        return -1;
    }
    struct canfd_frame k;
    struct iovec iov = {.iov_base = &k, .iov_len = sizeof k};
    union {
        char buf[CMSG_SPACE(sizeof(struct scm_timestamping)) + CMSG_SPACE(sizeof(struct timeval)) +
                 CMSG_SPACE(sizeof(uint32_t))];
        struct cmsghdr align;
    } ctrl;
    struct msghdr msg = {.msg_iov = &iov, .msg_iovlen = 1, .msg_control = ctrl.buf,
                         .msg_controllen = sizeof ctrl.buf};
    ssize_t n;
    do
        n = recvmsg(rx->fd, &msg, MSG_DONTWAIT);
    while (n < 0 && errno == EINTR);
    if (n < 0)
        return (errno == EAGAIN || errno == EWOULDBLOCK) ? 0 : -1;
    if (n == 0) { /* peer closed (socketpair) */
        errno = EPIPE;
        return -1;
    }
    const int64_t mono = pb_can_mono_ns(), real = pb_can_real_ns();
    uint64_t d = 0;
    const int64_t stamp = pb_can_rx_ancillary(rx, &msg, real, &d);
    if (new_drops)
        *new_drops = d;
    if (!convert(&k, (size_t)n, f)) {
        rx->bad++;
        return -2;
    }
    rx->frames++;
    /* Stamps are wall-clock: move them onto the monotonic clock by the
     * offset between the two clocks now (the frame arrived microseconds ago). */
    f->t_ns = stamp ? stamp - (real - mono) : mono;
    if (real_ns)
        *real_ns = stamp ? stamp : real;
    return 1;
}
