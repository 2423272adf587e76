/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for the candump -l file reader (pb_candump_next; the
 * line parser has its own target, fuzz_candump). The reader must account
 * for every line: each one either gives a frame or is counted as rejected
 * (the NUL-byte bug of issue 15 lost a good line and counted nothing), and
 * it gives exactly the frames that the line parser accepts line by line. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "candump_log.h"
#include "pb_warn.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Frames the reader should give: lines that end with a newline, hold no NUL,
 * fit PB_CANDUMP_LINE_MAX and parse. */
static size_t expected_frames(const char *p, size_t size, size_t *lines)
{
    const char *end = p + size;
    size_t frames = 0;
    *lines = 0;
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const size_t len = nl ? (size_t)(nl - p) : (size_t)(end - p);
        pb_can_frame f;
        char iface[32];
        const char *why;
        (*lines)++;
        if (nl && len <= PB_CANDUMP_LINE_MAX && !memchr(p, '\0', len) &&
            pb_candump_parse_line(p, len, &f, iface, sizeof iface, &why) == 1)
            frames++;
        p += len + 1;
    }
    return frames;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static pb_warnings warnings;
    pb_candump_reader r;
    memset(&r, 0, sizeof r);
    /* The reader is a FILE and a name; fmemopen spares the file system. */
    r.file = fmemopen((void *)data, size ? size : 1, "rb");
    r.path = strdup("fuzz.log");
    if (!r.file || !r.path) {
        pb_candump_close(&r);
        return 0;
    }
    if (!size) { /* fmemopen refuses a zero-size buffer: an empty file reads as one byte here */
        pb_candump_close(&r);
        return 0;
    }
    memset(&warnings, 0, sizeof warnings);
    pb_warnings_install(&warnings);
    pb_can_frame f;
    while (pb_candump_next(&r, &f) == 1) {
        char line[PB_CANDUMP_LINE_MAX];
        if (pb_candump_format(&f, r.iface, line, sizeof line) < 0)
            abort();
    }
    pb_warnings_install(NULL);
    size_t lines;
    const size_t want = expected_frames((const char *)data, size, &lines);
    if (r.line != lines || r.frames != want || r.frames + r.bad_lines > r.line ||
        warnings.count + warnings.dropped != r.bad_lines)
        abort();
    pb_candump_close(&r);
    return 0;
}
