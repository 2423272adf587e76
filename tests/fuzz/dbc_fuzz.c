/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for the DBC parser: parse, then decode one frame of
 * every message from the input's own bytes (exercises the derived bit
 * positions and multiplexor chains the parser accepted). */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "dbc_decode.h"
#include "dbc_parse.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pb_dbc *d = NULL;
    pb_dbc_error err;
    if (pb_dbc_parse((const char *)data, size, "fuzz.dbc", &d, &err) != 0)
        return 0;
    uint8_t frame[64];
    memset(frame, 0xA5, sizeof frame);
    memcpy(frame, data, size < sizeof frame ? size : sizeof frame);
    double values[512];
    uint8_t presence[512];
    for (size_t i = 0; i < d->message_count; i++) {
        const pb_dbc_message *m = &d->messages[i];
        if (m->signal_count > 512)
            continue;
        pb_dbc_decode(m, frame, m->size, values, NULL, presence);
        pb_dbc_decode(m, frame, 64, values, NULL, presence);
        (void)pb_dbc_find(d, m->id, m->extended);
        for (size_t j = 0; j < m->signal_count; j++)
            (void)pb_dbc_choice_text(&m->signals[j], (int64_t)j);
    }
    pb_dbc_free(d);
    return 0;
}
