/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for CAN bus descriptions (JSON): parse, then build the
 * decoder from it (node ids, duplicates, channel selection) and feed it a
 * frame made of the input's bytes. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "can_bus.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* Paths in "dbc" resolve against a folder that does not exist, so the
     * harness never reads files the input names. */
    pb_can_bus *bus = NULL;
    pb_error err;
    if (pb_can_bus_parse((const char *)data, size, "fuzz.json", "/nonexistent-fuzz-dir", &bus, &err) != POSE_OK)
        return 0;
    pb_can_decoder *dec = NULL;
    if (pb_can_decoder_create(pb_can_bus_config(bus), &dec, &err) == POSE_OK) {
        pb_can_frame f;
        memset(&f, 0, sizeof f);
        for (size_t i = 0; i + 12 <= size && i < 12 * 64; i += 12) {
            memcpy(&f.id, data + i, 4);
            f.flags = data[i + 4] & (PB_CAN_EXT | PB_CAN_RTR | PB_CAN_ERR);
            f.id &= (f.flags & PB_CAN_EXT) ? 0x1fffffffu : 0x7ffu;
            f.len = 7;
            memcpy(f.data, data + i + 5, 7);
            f.t_ns += 1000000;
            pb_update u;
            pb_can_decoder_feed(dec, &f, &u);
            pb_source_state st;
            char msg[256];
            pb_can_decoder_health(dec, &st, msg, sizeof msg);
        }
        pb_can_decoder_free(dec);
    }
    pb_can_bus_free(bus);
    return 0;
}
