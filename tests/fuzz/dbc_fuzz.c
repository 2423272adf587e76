/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for the DBC parser: parse, then decode one frame of
 * every message from the input's own bytes (exercises the derived bit
 * positions and multiplexor chains the parser accepted). A warning sink is
 * installed so the warning path (repeated pseudo-message signals ...) is
 * formatted too. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dbc_decode.h"
#include "dbc_parse.h"
#include "pb_warn.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static pb_warnings warnings;
    memset(&warnings, 0, sizeof warnings);
    pb_warnings_install(&warnings);
    pb_dbc *d = NULL;
    pb_dbc_error err;
    int rc = pb_dbc_parse((const char *)data, size, "fuzz.dbc", &d, &err);
    for (size_t i = 0; i < warnings.count; i++)
        if (strlen(warnings.text[i]) >= PB_WARN_LEN)
            abort();
    pb_warnings_install(NULL);
    if (rc != 0)
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
