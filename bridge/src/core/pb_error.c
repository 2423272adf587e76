/* SPDX-License-Identifier: Apache-2.0 */
#include "pb_error.h"

#include <errno.h>
#include <stdint.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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
    /* fopen succeeds on a directory, whose "size" from fseek/ftell is LONG_MAX:
     * say what the path is instead. */
    struct stat st;
    const int have = fstat(fileno(f), &st) == 0;
    if (!have || !S_ISREG(st.st_mode)) {
        const int dir = have && S_ISDIR(st.st_mode);
        fclose(f);
        return pb_fail(err, POSE_ERR_IO, "%s: %s", path, dir ? "is a directory, not a file" : "is not a regular file");
    }
    if ((uintmax_t)st.st_size > max_bytes) {
        fclose(f);
        return pb_fail(err, POSE_ERR_IO, "%s: %jd bytes is above the limit of %zu bytes", path,
                       (intmax_t)st.st_size, max_bytes);
    }
    const long n = (long)st.st_size;
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
