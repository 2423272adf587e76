/* SPDX-License-Identifier: Apache-2.0
 *
 * A CAN bus description that owns what a pb_can_config borrows: the DBC,
 * the CANopen node and J1939 sensor lists, the channel selection. Built in
 * code or from JSON (a mapping file's "can" object, or a file holding just
 * that object):
 *
 *   "can": {
 *     "dbc": "goniometer_rig.dbc",          relative to the JSON file
 *     "timeout_ms": 100,                    silence limit without a known cycle
 *     "canopen": [{"node": 33, "profile": 406, "name": "WRIST_L",
 *                  "steps_per_rev": 4096, "heartbeat_ms": 100}],
 *     "j1939": [{"address": 144, "name": "HEAD", "cycle_ms": 10}],
 *     "channels": ["KNEE_L.angle", ...]     optional: only these
 *   }
 *
 * Sources take ownership of the pb_can_bus they are opened with.
 */
#ifndef POSE_BRIDGE_CAN_BUS_H
#define POSE_BRIDGE_CAN_BUS_H

#include "can_decoder.h"

typedef struct pb_can_bus pb_can_bus;

/** Empty description; dbc_path may be NULL. */
pose_status pb_can_bus_create(const char *dbc_path, pb_can_bus **out, pb_error *err);
/** From a JSON file (see above). */
pose_status pb_can_bus_load(const char *json_path, pb_can_bus **out, pb_error *err);
/** From JSON text; base_dir resolves a relative "dbc" (NULL: current directory). */
pose_status pb_can_bus_parse(const char *json, size_t len, const char *name, const char *base_dir,
                             pb_can_bus **out, pb_error *err);

/** Add a CANopen node (name copied). */
pose_status pb_can_bus_add_canopen(pb_can_bus *bus, const pb_canopen_node_config *node);
/** Add a J1939 slope sensor (name copied). */
pose_status pb_can_bus_add_j1939(pb_can_bus *bus, const pb_j1939_sensor_config *sensor);
/** Deliver only these channels (copied); count 0 restores "every channel". */
pose_status pb_can_bus_select(pb_can_bus *bus, const char *const *channels, size_t count);
void pb_can_bus_set_timeout(pb_can_bus *bus, uint32_t timeout_ms);

/** The configuration, valid while the bus lives and is not modified. */
const pb_can_config *pb_can_bus_config(pb_can_bus *bus);
const pb_dbc *pb_can_bus_dbc(const pb_can_bus *bus);

void pb_can_bus_free(pb_can_bus *bus);

#endif /* POSE_BRIDGE_CAN_BUS_H */
