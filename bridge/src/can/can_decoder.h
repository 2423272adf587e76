/* SPDX-License-Identifier: Apache-2.0
 *
 * The CAN bus decoder shared by the live SocketCAN source and the candump
 * replay: frames in, channel values out, plus the bus's health. It knows
 * three ways sensors talk (DBC signals, CANopen CiA 406/410 PDOs with
 * heartbeats, J1939 slope sensors), watches every node that carries a
 * channel for silence, and follows the controller's error state from error
 * frames. Single-threaded: the thread that reads the source owns it.
 */
#ifndef POSE_BRIDGE_CAN_DECODER_H
#define POSE_BRIDGE_CAN_DECODER_H

#include <stddef.h>
#include <stdint.h>

#include "can_error.h"
#include "can_frame.h"
#include "dbc_parse.h"
#include "pb_error.h"
#include "source.h"

/** A CANopen node on the bus (channels "<name>.angle" or "<name>.slope_long" / ".slope_lat"). */
typedef struct pb_canopen_node_config {
    uint8_t node;           /**< node id 1..127 */
    uint16_t profile;       /**< 406 (encoder) or 410 (inclinometer) */
    const char *name;       /**< channel prefix; NULL: "node<N>" */
    uint32_t steps_per_rev; /**< CiA 406 object 0x6001; 0: 4096 */
    double resolution_deg;  /**< CiA 410 object 0x6000 in degrees; 0: 0.01 */
    uint32_t heartbeat_ms;  /**< producer heartbeat time (0x1017); 0: none expected */
} pb_canopen_node_config;

/** A J1939 slope sensor (channels "<name>.pitch", "<name>.roll"). */
typedef struct pb_j1939_sensor_config {
    uint8_t address;   /**< source address */
    const char *name;  /**< channel prefix; NULL: "sa<ADDR>" */
    uint32_t cycle_ms; /**< transmission period; 0: unknown */
} pb_j1939_sensor_config;

/** Everything a CAN source decodes. Zero means default throughout. */
typedef struct pb_can_config {
    const pb_dbc *dbc; /**< borrowed; must outlive the decoder; may be NULL */
    const pb_canopen_node_config *canopen;
    size_t canopen_count;
    const pb_j1939_sensor_config *j1939;
    size_t j1939_count;
    /** Only these channels ("MSG.SIGNAL", "<name>.angle" ...); NULL: every channel. */
    const char *const *channels;
    size_t channel_count;
    /** Silence after which a node with no known cycle time counts as lost; 0: 100 ms.
     * Nodes with a DBC GenMsgCycleTime or a heartbeat use 3x that period. */
    uint32_t timeout_ms;
} pb_can_config;

/** A kernel receive filter: match when (frame id & mask) == (id & mask). */
typedef struct pb_can_filter {
    uint32_t id, mask;
    uint8_t extended;
} pb_can_filter;

typedef struct pb_can_stats {
    uint64_t frames;        /**< every frame fed, error frames included */
    uint64_t decoded;       /**< frames that gave at least one channel value */
    uint64_t unknown;       /**< frames no configured message or node matches */
    uint64_t short_frames;  /**< frames shorter than their DBC message or PDO */
    uint64_t error_frames;
    uint64_t remote_frames;
    uint64_t dropped;       /**< frames the receiver lost (SO_RXQ_OVFL, controller overflow) */
    uint64_t bad_lines;     /**< replay: malformed log lines */
    pb_can_bus_state bus;
    uint8_t tx_errors, rx_errors; /**< controller error counters from the latest error frame with them */
} pb_can_stats;

typedef enum pb_can_node_state {
    PB_CAN_NODE_NEVER = 0,  /**< not heard from yet */
    PB_CAN_NODE_ALIVE = 1,
    PB_CAN_NODE_SILENT = 2, /**< quiet beyond its timeout; its channels hold */
} pb_can_node_state;

/** One monitored node, for can-monitor and tests. */
typedef struct pb_can_node_info {
    const char *name;
    uint32_t id;           /**< message id, CANopen node id or J1939 address */
    pb_can_node_state state;
    uint64_t frames;
    int64_t last_ns;       /**< time of its last frame, INT64_MIN if never */
    int nmt;               /**< CANopen: last heartbeat state, -1 if none */
    uint32_t timeout_ms;
} pb_can_node_info;

typedef struct pb_can_decoder pb_can_decoder;

/** Build a decoder. POSE_ERR_* with err filled on failure (unknown channel names ...). */
pose_status pb_can_decoder_create(const pb_can_config *cfg, pb_can_decoder **out, pb_error *err);
void pb_can_decoder_free(pb_can_decoder *dec);

/** The channels the decoder delivers, in index order. */
const pb_channel *pb_can_decoder_channels(const pb_can_decoder *dec, size_t *count);
/** Receive filters covering exactly the frames the channels need. */
const pb_can_filter *pb_can_decoder_filters(const pb_can_decoder *dec, size_t *count);

/**
 * Feed one frame (data, remote or error). Fills *out with the values it
 * carries (arrays owned by the decoder, valid until the next feed) and
 * returns their count; 0 when it carries none. Never allocates.
 */
size_t pb_can_decoder_feed(pb_can_decoder *dec, const pb_can_frame *f, pb_update *out);

/** Check node silence at now_ns (the frames' clock). Feed does this too. */
void pb_can_decoder_tick(pb_can_decoder *dec, int64_t now_ns);

/** Count frames the receiver lost (drop counters, overflow). */
void pb_can_decoder_add_dropped(pb_can_decoder *dec, uint64_t n);
/** Count n malformed log lines; what describes the latest. */
void pb_can_decoder_add_bad_lines(pb_can_decoder *dec, uint64_t n, const char *what);

/**
 * The bus's health as a source state: FAULT when error-passive or bus-off,
 * STALE when a node is silent, WAITING before any data, else OK; message
 * says why (or carries the latest notice: a short frame, an NMT change).
 * Returns 1 when state or message changed since the previous call.
 */
int pb_can_decoder_health(pb_can_decoder *dec, pb_source_state *state, char *message, size_t size);

const pb_can_stats *pb_can_decoder_stats(const pb_can_decoder *dec);
size_t pb_can_decoder_node_count(const pb_can_decoder *dec);
void pb_can_decoder_node(const pb_can_decoder *dec, size_t i, pb_can_node_info *info);

/** Forget node and bus history (a replay that loops or seeks). Statistics stay. */
void pb_can_decoder_reset(pb_can_decoder *dec);

#endif /* POSE_BRIDGE_CAN_DECODER_H */
