/* SPDX-License-Identifier: Apache-2.0 */
/* Thread-local error messages, status strings and the run-time version. */
#include <stdarg.h>
#include <stdio.h>

#include "error.h"

static _Thread_local char error_message[POSE__ERROR_SIZE];

static void set_error_v(const char *fmt, va_list ap)
{
    vsnprintf(error_message, sizeof error_message, fmt, ap);
}

void pose__set_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    set_error_v(fmt, ap);
    va_end(ap);
}

pose_status pose__fail(pose_status status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    set_error_v(fmt, ap);
    va_end(ap);
    return status;
}

void pose__clear_error(void)
{
    error_message[0] = '\0';
}

const char *pose_last_error(void)
{
    return error_message;
}

void pose_set_last_error(const char *message)
{
    pose__set_error("%s", message ? message : "");
}

const char *pose_status_string(pose_status status)
{
    switch (status) {
    case POSE_OK: return "success";
    case POSE_CLAMPED: return "success; a value was clamped to a joint limit";
    case POSE_ERR_INVALID_ARGUMENT: return "invalid argument";
    case POSE_ERR_OUT_OF_MEMORY: return "out of memory";
    case POSE_ERR_IO: return "input/output error";
    case POSE_ERR_FORMAT: return "malformed data";
    case POSE_ERR_VERSION: return "unsupported format version";
    case POSE_ERR_CHECKSUM: return "checksum mismatch";
    case POSE_ERR_INVALID_DATA: return "inconsistent data";
    case POSE_ERR_UNSUPPORTED: return "not supported by this rig";
    case POSE_ERR_NOT_FOUND: return "not found";
    case POSE_ERR_THREAD: return "worker thread could not be started";
    }
    return "unknown status";
}

#define POSE__STR2(x) #x
#define POSE__STR(x) POSE__STR2(x)

int pose_version(void)
{
    return POSE_VERSION_NUMBER;
}

const char *pose_version_string(void)
{
    return POSE__STR(POSE_VERSION_MAJOR) "." POSE__STR(POSE_VERSION_MINOR) "."
        POSE__STR(POSE_VERSION_PATCH);
}
