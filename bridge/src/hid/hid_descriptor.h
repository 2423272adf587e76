/* SPDX-License-Identifier: Apache-2.0
 *
 * HID report-descriptor parser (HID 1.11, section 6.2.2). Turns the item
 * stream of a device into a flat list of fields (one per value in a report,
 * with its bit position, size, sign, ranges and units) and a list of input
 * channels the bridge can map. Live devices (hid_hidraw.c) and recordings
 * (hid_recorder.c) share this parser and the decoder in hid_report.h.
 *
 * Example:
 *     pb_hid_desc *d;
 *     pb_error err;
 *     if (pb_hid_desc_parse(bytes, len, "mannequin.hid", &d, &err) != POSE_OK)
 *         fprintf(stderr, "%s\n", err.message);   // names the origin and byte offset
 *     ...
 *     pb_hid_desc_free(d);
 */
#ifndef POSE_BRIDGE_HID_DESCRIPTOR_H
#define POSE_BRIDGE_HID_DESCRIPTOR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "pb_error.h"
#include "source.h"

/** Limits that bound what a descriptor may ask for (a hostile one cannot exhaust memory). */
enum {
    PB_HID_MAX_DESC_BYTES = 65536,  /**< larger descriptors are refused */
    PB_HID_MAX_FIELDS = 4096,       /**< values over all reports */
    PB_HID_MAX_REPORT_BYTES = 4096, /**< one report, without its ID byte (hidraw's buffer) */
    PB_HID_MAX_USAGES = 1024,       /**< local usages before one main item */
    PB_HID_MAX_DEPTH = 32,          /**< collection nesting and Push depth */
    PB_HID_MAX_COLLECTIONS = 1024,
};

typedef enum pb_hid_report_kind {
    PB_HID_INPUT = 0,
    PB_HID_OUTPUT = 1,
    PB_HID_FEATURE = 2,
} pb_hid_report_kind;

/** Main-item data bits (HID 1.11, 6.2.2.5). */
enum {
    PB_HID_CONSTANT = 1u << 0,
    PB_HID_VARIABLE = 1u << 1,
    PB_HID_RELATIVE = 1u << 2,
    PB_HID_WRAP = 1u << 3,
    PB_HID_NONLINEAR = 1u << 4,
    PB_HID_NO_PREFERRED = 1u << 5,
    PB_HID_NULL_STATE = 1u << 6,
    PB_HID_VOLATILE = 1u << 7,
    PB_HID_BUFFERED_BYTES = 1u << 8,
};

/** One value slot in a report. */
typedef struct pb_hid_field {
    uint8_t kind;          /**< pb_hid_report_kind */
    uint8_t report_id;     /**< 0 when the device uses no report IDs */
    uint16_t flags;        /**< PB_HID_CONSTANT ... */
    uint32_t bit_offset;   /**< from the first payload byte (after the ID byte) */
    uint32_t bit_size;     /**< Report Size; values wider than 32 bits are not decoded */
    uint32_t usage;        /**< page << 16 | id; for arrays the first usage of the list */
    uint32_t usage_last;   /**< arrays: last usage of a Usage Min/Max range, else = usage */
    uint32_t array_index;  /**< slot number inside an array item, else 0 */
    int32_t logical_min, logical_max;
    int32_t physical_min, physical_max; /**< as in the descriptor; both 0 = same as logical */
    uint32_t unit;         /**< raw HID unit code */
    int8_t unit_exponent;  /**< power of ten applied to physical values */
    bool is_signed;        /**< logical minimum < 0: sign-extend the raw bits */
    int32_t collection;    /**< innermost collection index, -1 at top level */
    double scale, offset;  /**< value = logical * scale + offset, in `unit_name` */
    char unit_name[16];    /**< "deg", "rad", "cm", "in", "s", "g", "" ... */
    const uint32_t *usages;/**< array items: (first, last) usage ranges the index selects in (owned by desc) */
    uint32_t usage_count;  /**< number of ranges in usages */
    uint32_t usage_pool_index; /**< where usages starts in pb_hid_desc.usage_pool */
} pb_hid_field;

/** One collection (Application, Physical, Logical ...). */
typedef struct pb_hid_collection {
    uint32_t usage;
    uint8_t type;          /**< 0 Physical, 1 Application, 2 Logical, ... */
    int32_t parent;        /**< index, -1 at top level */
} pb_hid_collection;

/** A parsed descriptor: immutable after parsing, freed with pb_hid_desc_free. */
typedef struct pb_hid_desc {
    pb_hid_field *fields;
    size_t field_count;
    pb_hid_collection *collections;
    size_t collection_count;
    bool uses_report_ids;
    /** Payload length in bytes (without the ID byte) of each input report, by ID (0..255). */
    uint16_t input_bytes[256];
    uint16_t output_bytes[256];
    uint16_t feature_bytes[256];
    /** Input channels: one per non-constant input field the bridge can decode. */
    pb_channel *channels;
    uint32_t *channel_field;  /**< channel -> index in fields */
    size_t channel_count;
    /** Channels of each input report ID, as a contiguous run of channel indices. */
    uint32_t report_first[256], report_count[256];
    uint32_t *usage_pool;     /**< storage behind pb_hid_field.usages */
} pb_hid_desc;

/**
 * Parse a report descriptor. On success returns POSE_OK and hands out *out
 * (free it with pb_hid_desc_free). On failure returns POSE_ERR_FORMAT (or
 * POSE_ERR_OUT_OF_MEMORY), *out is NULL and err (may be NULL) names `origin`
 * (a file or device, may be NULL), the byte offset and what is wrong.
 */
pose_status pb_hid_desc_parse(const uint8_t *bytes, size_t len, const char *origin, pb_hid_desc **out,
                              pb_error *err);

/** Free a descriptor; NULL is allowed. */
void pb_hid_desc_free(pb_hid_desc *d);

/** Human names of a usage page and usage ("GenericDesktop", "X"); writes into buf. */
const char *pb_hid_usage_name(uint32_t usage, char *buf, size_t size);

/** Expected total report length in bytes, including the ID byte when the device uses IDs; 0 when the ID is unknown. */
size_t pb_hid_desc_input_length(const pb_hid_desc *d, uint8_t report_id);

#endif /* POSE_BRIDGE_HID_DESCRIPTOR_H */
