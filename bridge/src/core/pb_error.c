/* SPDX-License-Identifier: Apache-2.0 */
#include "pb_error.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

pose_status pb_fail(pb_error *err, pose_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
    }
    return status;
}

pose_status pb_read_file(const char *path, size_t max_bytes, char **data, size_t *size, pb_error *err)
{
    *data = NULL;
    *size = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return pb_fail(err, POSE_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    if (fseek(f, 0, SEEK_END) != 0) {
        fclose(f);
        return pb_fail(err, POSE_ERR_IO, "%s: cannot seek: %s", path, strerror(errno));
    }
    long n = ftell(f);
    if (n < 0 || (unsigned long)n > max_bytes) {
        fclose(f);
        return pb_fail(err, POSE_ERR_IO, "%s: size %ld is not readable or above the limit of %zu bytes",
                       path, n, max_bytes);
    }
    rewind(f);
    char *buf = malloc((size_t)n + 1);
    if (!buf) {
        fclose(f);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: cannot allocate %ld bytes", path, n);
    }
    if (n > 0 && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        fclose(f);
        return pb_fail(err, POSE_ERR_IO, "%s: read error", path);
    }
    fclose(f);
    buf[n] = '\0';
    *data = buf;
    *size = (size_t)n;
    return POSE_OK;
}
