/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for the candump -l reader: every line through the
 * parser, every parsed frame back through the writer and parsed again
 * (the two must agree), and error frames through the error decoder. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "can_error.h"
#include "candump_log.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *p = (const char *)data, *end = p + size;
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const size_t len = nl ? (size_t)(nl - p) : (size_t)(end - p);
        pb_can_frame f, g;
        char iface[32], iface2[32];
        const char *why;
        if (pb_candump_parse_line(p, len, &f, iface, sizeof iface, &why) == 1) {
            char out[PB_CANDUMP_LINE_MAX];
            int n = pb_candump_format(&f, iface, out, sizeof out);
            if (n > 0) {
                if (pb_candump_parse_line(out, (size_t)n, &g, iface2, sizeof iface2, &why) != 1)
                    abort();
                /* the writer keeps microseconds: compare what survives it */
                if (g.id != f.id || g.flags != f.flags || g.len != f.len || g.dlc != f.dlc ||
                    memcmp(g.data, f.data, f.len) != 0 || g.t_ns / 1000 != f.t_ns / 1000)
                    abort();
            }
            pb_can_error_info e;
            pb_can_error_decode(&f, &e);
            char text[256];
            pb_can_error_describe(&f, text, sizeof text);
        }
        p += len + 1;
    }
    return 0;
}
