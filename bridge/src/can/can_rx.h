/* SPDX-License-Identifier: Apache-2.0
 *
 * The SocketCAN receive loop, on any file descriptor: a raw CAN socket in
 * use, a socketpair carrying struct can_frame / canfd_frame bytes in tests.
 * One recvmsg per frame; the ancillary data gives the receive time
 * (SO_TIMESTAMPING hardware, else software stamps, else SO_TIMESTAMP) and
 * the socket's drop counter (SO_RXQ_OVFL).
 */
#ifndef POSE_BRIDGE_CAN_RX_H
#define POSE_BRIDGE_CAN_RX_H

#include <stdint.h>
#include <sys/socket.h>

#include "can_frame.h"

typedef struct pb_can_rx {
    int fd;
    uint32_t ovfl;      /**< last SO_RXQ_OVFL value seen */
    int have_ovfl;
    uint64_t frames;
    uint64_t dropped;   /**< frames the kernel dropped for this socket, from SO_RXQ_OVFL */
    uint64_t bad;       /**< reads that were not a whole frame */
} pb_can_rx;

/** Start reading fd (not owned). */
void pb_can_rx_init(pb_can_rx *rx, int fd);

/**
 * Wait at most timeout_ms (-1 forever, 0 poll) for a frame and read it.
 * f->t_ns is CLOCK_MONOTONIC: kernel stamps are moved from the realtime
 * clock; *real_ns (may be NULL) gets the wall-clock receive time for
 * recording. *new_drops gets frames lost since the previous read.
 * Returns 1 with a frame, 0 on timeout, -1 when the descriptor failed or
 * closed (errno set; ENODEV when the interface went away, EPIPE at end of
 * stream), -2 when a read was not a frame (counted in bad, skipped).
 */
int pb_can_rx_read(pb_can_rx *rx, pb_can_frame *f, int64_t *real_ns, uint64_t *new_drops,
                   int timeout_ms);

/**
 * The ancillary data of one received frame: returns its wall-clock receive
 * stamp (0 when none; hardware stamps only when on the wall clock, which
 * `real`, the wall clock now, tells) and updates the drop counter from
 * SO_RXQ_OVFL, with the frames lost since the previous one in *new_drops.
 */
int64_t pb_can_rx_ancillary(pb_can_rx *rx, const struct msghdr *msg, int64_t real, uint64_t *new_drops);

/** Current CLOCK_MONOTONIC and CLOCK_REALTIME in ns. */
int64_t pb_can_mono_ns(void);
int64_t pb_can_real_ns(void);

#endif /* POSE_BRIDGE_CAN_RX_H */
