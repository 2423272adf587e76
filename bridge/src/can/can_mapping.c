/* SPDX-License-Identifier: Apache-2.0 */
#include "can_mapping.h"

#include <stdlib.h>
#include <string.h>

pose_status pb_can_bus_select_mapped(pb_can_bus *bus, const pb_mapping *map, pb_error *err)
{
    const char **names = calloc((size_t)map->channel_count + 1, sizeof *names);
    if (!names)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "CAN: out of memory");
    size_t n = 0;
    for (int i = 0; i < map->channel_count; i++) {
        const char *c = map->channels[i].channel;
        if (!c[0])
            continue;
        int seen = 0; /* one joint axis per entry, but a channel may drive several */
        for (size_t k = 0; k < n && !seen; k++)
            seen = strcmp(names[k], c) == 0;
        if (!seen)
            names[n++] = c;
    }
    pose_status st = n ? pb_can_bus_select(bus, names, n)
                       : pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no \"channels\" entry names a CAN channel", map->path);
    if (st == POSE_ERR_OUT_OF_MEMORY)
        pb_fail(err, st, "CAN: out of memory");
    free(names);
    return st;
}
