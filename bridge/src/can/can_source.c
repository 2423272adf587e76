/* SPDX-License-Identifier: Apache-2.0 */
#include "can_source.h"

#include <stdlib.h>
#include <string.h>

pose_status pb_can_source_core_init(pb_can_source_core *c, const pb_source_ops *ops, pb_can_bus *bus,
                                    pb_error *err)
{
    memset(c, 0, sizeof *c);
    c->base.ops = ops;
    c->base.state = PB_SOURCE_WAITING;
    c->bus = bus;
    pose_status st = pb_can_decoder_create(pb_can_bus_config(bus), &c->dec, err);
    if (st != POSE_OK)
        return st;
    size_t n;
    const pb_channel *ch = pb_can_decoder_channels(c->dec, &n);
    c->base.channels = malloc((n ? n : 1) * sizeof *ch);
    if (!c->base.channels)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "CAN: out of memory");
    memcpy(c->base.channels, ch, n * sizeof *ch);
    c->base.channel_count = n;
    snprintf(c->base.message, sizeof c->base.message, "no data yet");
    return POSE_OK;
}

void pb_can_source_core_report(pb_can_source_core *c)
{
    pb_source_state s;
    char msg[256];
    if (pb_can_decoder_health(c->dec, &s, msg, sizeof msg))
        pb_source_set_state(&c->base, s, "%s", msg);
}

size_t pb_can_source_core_frame(pb_can_source_core *c, const pb_can_frame *f, pb_update *out)
{
    size_t n = pb_can_decoder_feed(c->dec, f, out);
    pb_can_source_core_report(c);
    return n;
}

void pb_can_source_core_close(pb_can_source_core *c)
{
    pb_can_decoder_free(c->dec);
    c->dec = NULL;
    pb_can_bus_free(c->bus);
    c->bus = NULL;
    free(c->base.channels);
    c->base.channels = NULL;
    c->base.channel_count = 0;
}

pb_can_decoder *pb_can_source_decoder(pb_source *src)
{
    if (!src || !src->ops || !src->ops->kind)
        return NULL;
    if (strcmp(src->ops->kind, "can") != 0 && strcmp(src->ops->kind, "candump-replay") != 0)
        return NULL;
    return ((pb_can_source_core *)src)->dec;
}
