/* SPDX-License-Identifier: Apache-2.0 */
#include "pb_warn.h"

#include <stdarg.h>
#include <stdio.h>

static _Thread_local pb_warnings *sink;

pb_warnings *pb_warnings_install(pb_warnings *w)
{
    pb_warnings *prev = sink;
    sink = w;
    return prev;
}

void pb_warn(const char *fmt, ...)
{
    pb_warnings *w = sink;
    if (!w)
        return;
    if (w->count >= PB_WARN_MAX) {
        w->dropped++;
        return;
    }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->text[w->count], PB_WARN_LEN, fmt, ap);
    va_end(ap);
    if (w->echo)
        fprintf(stderr, "warning: %s\n", w->text[w->count]);
    w->count++;
}
