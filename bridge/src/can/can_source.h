/* SPDX-License-Identifier: Apache-2.0
 *
 * CAN bus sources: the live SocketCAN bus (can_socketcan.c) and a candump -l
 * log replayed as a simulated bus (candump_replay.c). Both run the same
 * pb_can_decoder, so a recording behaves like the rig that made it. Every
 * frame with channel values is one pb_update stamped with the frame's time;
 * health changes (silent node, error-passive, bus-off, malformed lines,
 * short frames) go through pb_source_set_state.
 */
#ifndef POSE_BRIDGE_CAN_SOURCE_H
#define POSE_BRIDGE_CAN_SOURCE_H

#include <stdio.h>

#include "can_bus.h"
#include "can_rx.h"
#include "source.h"

/** Options of the live source; zero means default. */
typedef struct pb_can_live_options {
    const char *record_path; /**< also write every received frame to this candump -l file */
    int no_filters;          /**< receive every identifier (can-record, can-monitor) */
} pb_can_live_options;

/**
 * Open SocketCAN interface iface ("can0"): raw socket, CAN FD enabled,
 * kernel filters from the bus's channels, error frames, receive stamps and
 * drop counters. Takes ownership of bus (freed on failure too).
 */
pose_status pb_can_live_open(const char *iface, pb_can_bus *bus, const pb_can_live_options *opt,
                             pb_source **out, pb_error *err);

/**
 * The same source over a descriptor that already delivers frames (a raw
 * socket opened elsewhere, or a socketpair in tests). label names it in
 * messages and recordings; own_fd: close fd with the source.
 */
pose_status pb_can_live_open_fd(int fd, int own_fd, const char *label, pb_can_bus *bus,
                                const pb_can_live_options *opt, pb_source **out, pb_error *err);

/** Raw CAN socket bound to iface with the given filters (none: everything). -1 with err on failure. */
int pb_can_socket_open(const char *iface, const pb_can_filter *filters, size_t count, pb_error *err);

/** What pb_can_socket_open calls to open an interface by name. */
typedef int (*pb_can_socket_opener)(const char *iface, const pb_can_filter *filters, size_t count, pb_error *err);
/**
 * Replace the SocketCAN opener (NULL restores it). For tests: containers have
 * no vcan, and a stand-in that hands out socketpair ends exercises the paths
 * that need an interface name (the live source's reopen after the interface
 * went away). Set it before opening sources; it is not synchronised.
 */
void pb_can_set_socket_opener(pb_can_socket_opener fn);

/** Options of the replay; zero means default. */
typedef struct pb_candump_replay_options {
    int as_fast_as_possible; /**< ignore recorded timing */
    double speed;            /**< recorded timing scaled: 2 = twice as fast; 0: 1 */
    int loop;                /**< start over at the end instead of ENDED */
} pb_candump_replay_options;

/**
 * Replay a candump -l log through the bus's decoder. Update times are
 * nanoseconds since the log's first frame. Takes ownership of bus.
 */
pose_status pb_candump_replay_open(const char *log_path, pb_can_bus *bus,
                                   const pb_candump_replay_options *opt, pb_source **out, pb_error *err);

/** The decoder behind a CAN source ("can" or "candump-replay"), or NULL for other sources. */
pb_can_decoder *pb_can_source_decoder(pb_source *src);

/* ---- shared by the two backends ---- */

typedef struct pb_can_source_core {
    pb_source base; /* first: the backends are pb_sources */
    pb_can_bus *bus;
    pb_can_decoder *dec;
} pb_can_source_core;

pose_status pb_can_source_core_init(pb_can_source_core *c, const pb_source_ops *ops, pb_can_bus *bus,
                                    pb_error *err);
/** Feed a frame, report a health change; returns the channel values it gave. */
size_t pb_can_source_core_frame(pb_can_source_core *c, const pb_can_frame *f, pb_update *out);
/** Report a health change (after tick or counters). */
void pb_can_source_core_report(pb_can_source_core *c);
void pb_can_source_core_close(pb_can_source_core *c);

#endif /* POSE_BRIDGE_CAN_SOURCE_H */
