/* SPDX-License-Identifier: Apache-2.0
 * Error detail for bridge calls: functions return a pose_status and, on
 * failure, fill a caller-owned pb_error whose message names the file and the
 * line (or byte offset) and says what was expected there. */
#ifndef POSE_BRIDGE_ERROR_H
#define POSE_BRIDGE_ERROR_H

#include "pose/pose.h"

typedef struct pb_error {
    char message[512];
} pb_error;

/** Format into err (NULL err is allowed and ignored); returns `status`. */
pose_status pb_fail(pb_error *err, pose_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/**
 * Read a whole file into a NUL-terminated buffer (caller frees). Refuses
 * files above max_bytes. POSE_ERR_IO with the path and errno text on failure.
 */
pose_status pb_read_file(const char *path, size_t max_bytes, char **data, size_t *size, pb_error *err);

#endif /* POSE_BRIDGE_ERROR_H */
