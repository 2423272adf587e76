/* SPDX-License-Identifier: Apache-2.0 */
#include "pb_warn.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>

static _Thread_local pb_warnings *sink;

pb_warnings *pb_warnings_install(pb_warnings *w)
{
    pb_warnings *prev = sink;
    sink = w;
    return prev;
}

pb_warnings *pb_warnings_current(void) { return sink; }

void pb_warn(const char *fmt, ...)
{
    pb_warnings *w = sink;
    if (!w)
        return;
    const size_t n = atomic_load_explicit(&w->count, memory_order_relaxed); /* we are the only writer */
    if (n >= PB_WARN_MAX) {
        atomic_fetch_add_explicit(&w->dropped, 1, memory_order_relaxed);
        return;
    }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->text[n], PB_WARN_LEN, fmt, ap);
    va_end(ap);
    if (w->echo)
        fprintf(stderr, "warning: %s\n", w->text[n]);
    atomic_store_explicit(&w->count, n + 1, memory_order_release); /* publishes text[n] */
}
