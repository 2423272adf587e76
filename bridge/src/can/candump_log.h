/* SPDX-License-Identifier: Apache-2.0
 *
 * candump -l log files: "(1436509052.249713) can0 123#DEADBEEF", one frame a
 * line, in the syntax of can-utils' lib.c: 3-digit standard and 8-digit
 * extended identifiers, "R" remote frames with optional length, "_<dlc>"
 * length codes of classic frames, "##<flags>" FD frames, and error frames
 * (8-digit identifiers with the CAN_ERR_FLAG bit 0x20000000 set).
 */
#ifndef POSE_BRIDGE_CANDUMP_LOG_H
#define POSE_BRIDGE_CANDUMP_LOG_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "can_frame.h"

#define PB_CANDUMP_ERR_FLAG 0x20000000u
#define PB_CANDUMP_LINE_MAX 300 /* 64-byte FD frame with dots plus a long interface name */

/**
 * Parse one line (no newline needed; a trailing one is ignored).
 * Returns 1 with *f filled (t_ns = the stamp in ns since the epoch) and the
 * interface copied into iface (iface_size bytes, may be 0), 0 for a blank or
 * '#'-comment line, -1 for a malformed line with *why set to a fixed text.
 */
int pb_candump_parse_line(const char *line, size_t len, pb_can_frame *f, char *iface,
                          size_t iface_size, const char **why);

/** Format f as a candump -l line with newline. Returns the length, or -1 if size is too small. */
int pb_candump_format(const pb_can_frame *f, const char *iface, char *buf, size_t size);

/**
 * Write f as a candump -l line and flush it, so that a crash or a kill loses
 * at most this frame (recorders call it once per frame). Returns 0, or -1
 * on a write error (errno set).
 */
int pb_candump_write(FILE *out, const pb_can_frame *f, const char *iface);

/** Sequential reader over a log file. */
typedef struct pb_candump_reader {
    FILE *file;
    char *path;
    size_t line;        /**< number of the line last read (1-based) */
    size_t frames;      /**< frames returned so far */
    size_t bad_lines;   /**< malformed lines skipped */
    char last_error[256]; /**< "FILE:LINE: why" of the latest malformed line */
    char iface[32];     /**< interface of the last frame */
} pb_candump_reader;

/** Open a log for reading. Returns 0, or -1 with err (may be NULL) filled. */
int pb_candump_open(pb_candump_reader *r, const char *path, char *err, size_t err_size);

/**
 * Next frame. Lines are read by length (a NUL byte spoils its own line
 * only). Malformed lines, and a last line without its newline (cut by a
 * killed recorder), are counted, described in last_error, reported with
 * pb_warn naming the file and line, and skipped. Returns 1 with *f, 0 at the
 * end of the file, -1 on a read error.
 */
int pb_candump_next(pb_candump_reader *r, pb_can_frame *f);

/** Back to the start of the file (counters reset). */
int pb_candump_rewind(pb_candump_reader *r);

void pb_candump_close(pb_candump_reader *r);

#endif /* POSE_BRIDGE_CANDUMP_LOG_H */
