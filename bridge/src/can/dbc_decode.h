/* SPDX-License-Identifier: Apache-2.0
 *
 * Signal extraction from frame bytes, shared by the live and the replayed
 * bus. No allocation: values go into caller arrays sized by signal_count.
 */
#ifndef POSE_BRIDGE_DBC_DECODE_H
#define POSE_BRIDGE_DBC_DECODE_H

#include <stddef.h>
#include <stdint.h>

#include "dbc_parse.h"

/** Raw bits of a signal (unsigned, not sign-extended). 0 when the frame is too short. */
int pb_dbc_extract_raw(const pb_dbc_signal *s, const uint8_t *data, size_t len, uint64_t *raw);

/** Physical value of raw bits: sign extension or float reinterpretation, then factor/offset. */
double pb_dbc_physical(const pb_dbc_signal *s, uint64_t raw);

/** Raw value as a signed integer (for VAL_ lookup), sign-extended when the signal is signed. */
int64_t pb_dbc_raw_signed(const pb_dbc_signal *s, uint64_t raw);

/** Why a signal of a frame has no value. */
typedef enum pb_dbc_presence {
    PB_DBC_PRESENT = 0,
    PB_DBC_SHORT = 1,    /**< the frame ends before the signal */
    PB_DBC_MUX_OFF = 2,  /**< its multiplexor selects other signals */
} pb_dbc_presence;

/**
 * Decode every signal of msg from data[0..len). values[i], raws[i] (raws
 * may be NULL) and presence[i] are written for each signal i. Returns the
 * number of signals present.
 */
size_t pb_dbc_decode(const pb_dbc_message *msg, const uint8_t *data, size_t len, double *values,
                     uint64_t *raws, uint8_t *presence);

#endif /* POSE_BRIDGE_DBC_DECODE_H */
