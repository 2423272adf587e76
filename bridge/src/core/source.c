/* SPDX-License-Identifier: Apache-2.0
 * The part of the source interface every backend shares: state changes. */
#include "source.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void pb_source_set_state(pb_source *src, pb_source_state state, const char *fmt, ...)
{
    if (!src)
        return;
    if (fmt) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(src->message, sizeof src->message, fmt, ap);
        va_end(ap);
    } else {
        src->message[0] = '\0';
    }
    src->state = state;
    if (src->on_status)
        src->on_status(src, state, src->message, src->on_status_user);
}

const char *pb_source_state_name(pb_source_state state)
{
    switch (state) {
    case PB_SOURCE_OK: return "ok";
    case PB_SOURCE_WAITING: return "waiting";
    case PB_SOURCE_STALE: return "stale";
    case PB_SOURCE_DISCONNECTED: return "disconnected";
    case PB_SOURCE_FAULT: return "fault";
    case PB_SOURCE_ENDED: return "ended";
    }
    return "unknown";
}

int pb_source_read(pb_source *src, pb_update *out, int timeout_ms)
{
    if (!src || !src->ops || !src->ops->read || !out)
        return -1;
    return src->ops->read(src, out, timeout_ms);
}

int pb_source_seek(pb_source *src, int64_t t_ns)
{
    if (!src || !src->ops || !src->ops->seek)
        return -1;
    return src->ops->seek(src, t_ns);
}

void pb_source_close(pb_source *src)
{
    if (src && src->ops && src->ops->close)
        src->ops->close(src);
}

void pb_source_destroy(pb_source *src)
{
    if (!src)
        return;
    pb_source_close(src);
    free(src);
}

long pb_source_find_channel(const pb_source *src, const char *name)
{
    if (!src || !name)
        return -1;
    for (size_t i = 0; i < src->channel_count; i++)
        if (strncmp(src->channels[i].name, name, sizeof src->channels[i].name) == 0)
            return (long)i;
    return -1;
}
