/* SPDX-License-Identifier: Apache-2.0
 *
 * CANopen pieces a goniometer rig uses, decoded from raw frames:
 *   - CiA 406 encoders: position value (object 0x6004, UNSIGNED32) in the
 *     first four bytes of TPDO1 (COB-ID 0x180 + node), the default mapping;
 *   - CiA 410 inclinometers: slope long16 (0x6010) and slope lateral16
 *     (0x6020), INTEGER16 in bytes 0-1 and 2-3 of TPDO1, in units of the
 *     resolution object 0x6000 (default 0.01 degree);
 *   - heartbeat / boot-up (COB-ID 0x700 + node): one byte of NMT state.
 */
#ifndef POSE_BRIDGE_CANOPEN_DECODE_H
#define POSE_BRIDGE_CANOPEN_DECODE_H

#include <stddef.h>
#include <stdint.h>

#define PB_CANOPEN_TPDO1 0x180u
#define PB_CANOPEN_HEARTBEAT 0x700u

/** NMT states as heartbeats carry them. */
typedef enum pb_canopen_nmt {
    PB_CANOPEN_BOOTUP = 0x00,
    PB_CANOPEN_STOPPED = 0x04,
    PB_CANOPEN_OPERATIONAL = 0x05,
    PB_CANOPEN_PRE_OPERATIONAL = 0x7f,
} pb_canopen_nmt;

typedef enum pb_canopen_profile {
    PB_CANOPEN_CIA406 = 406, /**< rotary encoder */
    PB_CANOPEN_CIA410 = 410, /**< inclinometer */
} pb_canopen_profile;

/**
 * CiA 406 position -> degrees in [-180, 180): position modulo steps_per_rev
 * (object 0x6001), so a multi-turn count and a singleturn one preset to 0 at
 * the joint's neutral give the same angle. Returns 0 when the frame is short.
 */
int pb_canopen_406_angle(const uint8_t *data, size_t len, uint32_t steps_per_rev, double *deg);

/** CiA 410 slopes -> degrees (resolution_deg per unit). Returns the number of slopes present (0..2). */
int pb_canopen_410_slopes(const uint8_t *data, size_t len, double resolution_deg, double *longitudinal,
                          double *lateral);

/** "operational", "pre-operational", "stopped", "boot-up" or "unknown". */
const char *pb_canopen_nmt_name(unsigned state);

#endif /* POSE_BRIDGE_CANOPEN_DECODE_H */
