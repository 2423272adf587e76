/* SPDX-License-Identifier: Apache-2.0 */
#include "dbc_decode.h"

#include <string.h>

int pb_dbc_extract_raw(const pb_dbc_signal *s, const uint8_t *data, size_t len, uint64_t *raw)
{
    if (s->bytes_needed > len)
        return 0;
    uint64_t v = 0;
    unsigned got = 0, pos = s->linear_start;
    const unsigned n = s->length;
    if (s->intel) {
        /* LSB first: each byte contributes its bits from 'pos % 8' upwards. */
        while (got < n) {
            const unsigned bit = pos % 8, take = (8 - bit) < (n - got) ? 8 - bit : n - got;
            const uint64_t chunk = ((uint64_t)data[pos / 8] >> bit) & ((1u << take) - 1);
            v |= chunk << got;
            got += take;
            pos += take;
        }
    } else {
        /* MSB first in the linear numbering: bit 0 of a byte is its MSB. */
        while (got < n) {
            const unsigned bit = pos % 8, take = (8 - bit) < (n - got) ? 8 - bit : n - got;
            const uint64_t chunk = ((uint64_t)data[pos / 8] >> (8 - bit - take)) & ((1u << take) - 1);
            v = (v << take) | chunk;
            got += take;
            pos += take;
        }
    }
    *raw = v;
    return 1;
}

int64_t pb_dbc_raw_signed(const pb_dbc_signal *s, uint64_t raw)
{
    if (!s->is_signed || s->length >= 64)
        return (int64_t)raw;
    const uint64_t sign = (uint64_t)1 << (s->length - 1);
    if (raw & sign)
        raw |= ~((sign << 1) - 1);
    return (int64_t)raw;
}

double pb_dbc_physical(const pb_dbc_signal *s, uint64_t raw)
{
    double v;
    if (s->value_type == PB_DBC_FLOAT32) {
        uint32_t bits = (uint32_t)raw;
        float f;
        memcpy(&f, &bits, sizeof f);
        v = f;
    } else if (s->value_type == PB_DBC_FLOAT64) {
        memcpy(&v, &raw, sizeof v);
    } else if (s->is_signed) {
        v = (double)pb_dbc_raw_signed(s, raw);
    } else {
        v = (double)raw;
    }
    return v * s->factor + s->offset;
}

static int mux_selects(const pb_dbc_signal *s, uint64_t muxer_raw)
{
    for (size_t i = 0; i < s->mux_range_count; i++)
        if (muxer_raw >= s->mux_ranges[i].lo && muxer_raw <= s->mux_ranges[i].hi)
            return 1;
    return 0;
}

size_t pb_dbc_decode(const pb_dbc_message *msg, const uint8_t *data, size_t len, double *values,
                     uint64_t *raws, uint8_t *presence)
{
    size_t present = 0;
    /* Multiplexors come before what they select in the chain, but not
     * necessarily in file order: extract everything, then resolve presence
     * by walking each signal's chain (short: depth is the mux nesting). */
    for (size_t i = 0; i < msg->signal_count; i++) {
        const pb_dbc_signal *s = &msg->signals[i];
        uint64_t raw = 0;
        if (!pb_dbc_extract_raw(s, data, len, &raw)) {
            presence[i] = PB_DBC_SHORT;
            values[i] = 0.0;
        } else {
            presence[i] = PB_DBC_PRESENT;
            values[i] = pb_dbc_physical(s, raw);
        }
        if (raws)
            raws[i] = raw;
    }
    for (size_t i = 0; i < msg->signal_count; i++) {
        if (presence[i] != PB_DBC_PRESENT)
            continue;
        const pb_dbc_signal *s = &msg->signals[i];
        while (s->muxed_by >= 0) {
            const pb_dbc_signal *mux = &msg->signals[s->muxed_by];
            uint64_t mraw;
            if (presence[s->muxed_by] == PB_DBC_SHORT || !pb_dbc_extract_raw(mux, data, len, &mraw)) {
                presence[i] = PB_DBC_SHORT;
                break;
            }
            if (!mux_selects(s, mraw)) {
                presence[i] = PB_DBC_MUX_OFF;
                break;
            }
            s = mux;
        }
        if (presence[i] == PB_DBC_PRESENT)
            present++;
    }
    return present;
}
