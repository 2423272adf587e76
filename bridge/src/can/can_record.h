/* SPDX-License-Identifier: Apache-2.0
 *
 * Recording a CAN descriptor (a raw SocketCAN socket, or a socketpair in
 * tests) to a candump -l log: pose-bridge can-record's loop. Every frame is
 * flushed as it is written, so a kill loses at most the frame in flight.
 */
#ifndef POSE_BRIDGE_CAN_RECORD_H
#define POSE_BRIDGE_CAN_RECORD_H

#include <signal.h>
#include <stdio.h>

#include "pb_error.h"

typedef struct pb_can_record_options {
    double seconds;                   /**< stop after this long; 0 = no limit */
    unsigned long long count;         /**< stop after this many frames; 0 = no limit */
    volatile sig_atomic_t *stop;      /**< stop when it becomes nonzero (a signal handler's flag); may be NULL */
    int progress;                     /**< a count on stderr every second */
} pb_can_record_options;

typedef struct pb_can_record_result {
    unsigned long long frames; /**< written */
    unsigned long long drops;  /**< frames the kernel dropped for the socket */
} pb_can_record_result;

/**
 * Read frames from fd and write each, stamped with its wall-clock receive
 * time, to out as a candump -l line naming iface. Returns 0 at a limit or a
 * stop request, -1 with err on a read or write error.
 */
int pb_can_record_run(int fd, const char *iface, FILE *out, const pb_can_record_options *opt,
                      pb_can_record_result *res, pb_error *err);

#endif /* POSE_BRIDGE_CAN_RECORD_H */
