/* SPDX-License-Identifier: Apache-2.0
 *
 * Glue between a mapping file and a CAN bus: deliver (and let the kernel
 * pass, and watch for silence) only what the mapping's "channels" use.
 */
#ifndef POSE_BRIDGE_CAN_MAPPING_H
#define POSE_BRIDGE_CAN_MAPPING_H

#include "can_bus.h"
#include "mapping.h"

/**
 * Restrict bus to the channels map's "channels" entries name (entries
 * matched by HID usage are ignored). POSE_ERR_NOT_FOUND when the mapping
 * names no channel at all.
 */
pose_status pb_can_bus_select_mapped(pb_can_bus *bus, const pb_mapping *map, pb_error *err);

#endif /* POSE_BRIDGE_CAN_MAPPING_H */
