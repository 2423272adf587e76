/* SPDX-License-Identifier: Apache-2.0 */
/* The calling thread's last error message (see pose_last_error). */
#ifndef POSE_ERROR_H
#define POSE_ERROR_H

#include "pose/pose.h"

#if defined(__GNUC__) || defined(__clang__)
#  define POSE__PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#  define POSE__PRINTF(f, a)
#endif

/** Longest message kept (longer ones are truncated). */
#define POSE__ERROR_SIZE 1024

/** Set the thread's message (printf format). */
void pose__set_error(const char *fmt, ...) POSE__PRINTF(1, 2);
/** Set the message and return `status`, for `return pose__fail(...)`. */
pose_status pose__fail(pose_status status, const char *fmt, ...) POSE__PRINTF(2, 3);
/** Clear the thread's message (start of every fallible public call). */
void pose__clear_error(void);

#endif /* POSE_ERROR_H */
