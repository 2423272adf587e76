/* SPDX-License-Identifier: Apache-2.0
 *
 * Vector DBC files: messages, signals, value tables, multiplexing.
 * Debian has no maintained C DBC library, so this is our own parser: it
 * reads what a signal decoder needs (BO_, SG_, VAL_, SIG_VALTYPE_,
 * SG_MUL_VAL_), skips every other statement, and reports the first error
 * with file name and line. A loaded pb_dbc is immutable.
 */
#ifndef POSE_BRIDGE_DBC_PARSE_H
#define POSE_BRIDGE_DBC_PARSE_H

#include <stddef.h>
#include <stdint.h>

typedef enum pb_dbc_value_type {
    PB_DBC_INTEGER = 0, /**< raw bits as (un)signed integer */
    PB_DBC_FLOAT32 = 1, /**< SIG_VALTYPE_ 1: IEEE single, 32 bits */
    PB_DBC_FLOAT64 = 2, /**< SIG_VALTYPE_ 2: IEEE double, 64 bits */
} pb_dbc_value_type;

/** One VAL_ entry: raw value -> text. */
typedef struct pb_dbc_choice {
    int64_t value;
    const char *text;
} pb_dbc_choice;

/** An inclusive range of multiplexor values that selects a signal (SG_MUL_VAL_). */
typedef struct pb_dbc_mux_range {
    uint64_t lo, hi;
} pb_dbc_mux_range;

typedef struct pb_dbc_signal {
    const char *name;
    const char *unit;
    uint16_t start;     /**< start bit as written in the file */
    uint16_t length;    /**< 1..64 bits */
    uint8_t intel;      /**< 1: @1 little-endian (Intel), 0: @0 big-endian (Motorola) */
    uint8_t is_signed;  /**< '-' */
    uint8_t value_type; /**< pb_dbc_value_type */
    uint8_t is_multiplexor; /**< 'M' or 'mNM' */
    double factor, offset, min, max;
    /* Multiplexing: when muxed_by >= 0 the signal is present only when signal
     * muxed_by of the same message is present and its raw value lies in one
     * of mux_ranges (simple multiplexing: one range N..N from "mN"). */
    int muxed_by;
    const pb_dbc_mux_range *mux_ranges;
    size_t mux_range_count;
    const pb_dbc_choice *choices; /**< VAL_ table, sorted by value */
    size_t choice_count;
    /* Derived at load: first bit in a linear numbering (Intel: LSB index;
     * Motorola: MSB index counting bit 7 of byte 0 as 0) and the bytes a
     * frame must have for the signal to be complete. */
    uint16_t linear_start;
    uint8_t bytes_needed;
    uint8_t has_mux_value; /**< "mN" was given */
    uint64_t mux_value;    /**< N of "mN" */
    size_t line;           /**< where SG_ was */
} pb_dbc_signal;

typedef struct pb_dbc_message {
    uint32_t id;       /**< identifier without the extended flag */
    uint8_t extended;  /**< bit 31 was set in the file */
    uint8_t size;      /**< bytes as declared (0..64) */
    const char *name;
    const char *sender;
    pb_dbc_signal *signals;
    size_t signal_count;
    uint32_t cycle_ms; /**< BA_ "GenMsgCycleTime", 0 when not given */
    size_t line;       /**< where BO_ was, for messages */
} pb_dbc_message;

typedef struct pb_dbc pb_dbc;

struct pb_dbc {
    char *path;
    pb_dbc_message *messages;
    size_t message_count;
    size_t warning_count; /**< statements that were suspicious but skipped (see warning) */
    char warning[256];    /**< the first of them, "FILE:LINE: what" */
    /* private */
    struct pb_dbc_index_entry *index; /**< sorted (extended, id) for lookup */
    struct pb_dbc_arena *arena;
};

/** Error detail filled by the loaders. */
typedef struct pb_dbc_error {
    char message[256]; /**< "FILE:LINE: what" */
    size_t line;
} pb_dbc_error;

/** Load a DBC file. Returns 0 and *out, or -1 with err filled (err may be NULL). */
int pb_dbc_load(const char *path, pb_dbc **out, pb_dbc_error *err);

/** Parse DBC text of len bytes; name is used in messages. */
int pb_dbc_parse(const char *text, size_t len, const char *name, pb_dbc **out, pb_dbc_error *err);

/** Free a DBC (NULL is fine). */
void pb_dbc_free(pb_dbc *dbc);

/** The message with this identifier, or NULL. */
const pb_dbc_message *pb_dbc_find(const pb_dbc *dbc, uint32_t id, int extended);

/** Message and signal by name ("MSG", "SIG"); returns the signal's index or -1. */
int pb_dbc_find_signal(const pb_dbc *dbc, const char *msg, const char *sig, const pb_dbc_message **out_msg);

/** Choice text for a raw value, or NULL. */
const char *pb_dbc_choice_text(const pb_dbc_signal *s, int64_t raw);

#endif /* POSE_BRIDGE_DBC_PARSE_H */
