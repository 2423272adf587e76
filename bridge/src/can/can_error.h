/* SPDX-License-Identifier: Apache-2.0
 *
 * Decoding of CAN error frames (the kernel's CAN_ERR_* classes, which
 * candump -l also records) into bus states the bridge reports. The values
 * below are the Linux ABI; can_socketcan.c checks them against the kernel
 * header, and this file stays portable so replays decode on any system.
 */
#ifndef POSE_BRIDGE_CAN_ERROR_H
#define POSE_BRIDGE_CAN_ERROR_H

#include <stddef.h>
#include <stdint.h>

#include "can_frame.h"

/* Error classes (pb_can_frame.id of an error frame). */
#define PB_CAN_ERR_TX_TIMEOUT 0x001u
#define PB_CAN_ERR_LOSTARB 0x002u
#define PB_CAN_ERR_CRTL 0x004u
#define PB_CAN_ERR_PROT 0x008u
#define PB_CAN_ERR_TRX 0x010u
#define PB_CAN_ERR_ACK 0x020u
#define PB_CAN_ERR_BUSOFF 0x040u
#define PB_CAN_ERR_BUSERROR 0x080u
#define PB_CAN_ERR_RESTARTED 0x100u
#define PB_CAN_ERR_CNT 0x200u
/* Controller status bits (data[1] when PB_CAN_ERR_CRTL). */
#define PB_CAN_ERR_CRTL_RX_OVERFLOW 0x01u
#define PB_CAN_ERR_CRTL_TX_OVERFLOW 0x02u
#define PB_CAN_ERR_CRTL_RX_WARNING 0x04u
#define PB_CAN_ERR_CRTL_TX_WARNING 0x08u
#define PB_CAN_ERR_CRTL_RX_PASSIVE 0x10u
#define PB_CAN_ERR_CRTL_TX_PASSIVE 0x20u
#define PB_CAN_ERR_CRTL_ACTIVE 0x40u

/** Fault confinement state of the controller (ISO 11898-1). */
typedef enum pb_can_bus_state {
    PB_CAN_BUS_ACTIVE = 0,  /**< error active: normal operation */
    PB_CAN_BUS_WARNING = 1, /**< an error counter passed 96 */
    PB_CAN_BUS_PASSIVE = 2, /**< an error counter passed 127 */
    PB_CAN_BUS_OFF = 3,     /**< transmit counter passed 255: off the bus until restarted */
} pb_can_bus_state;

/** What one error frame says. */
typedef struct pb_can_error_info {
    int has_state;          /**< 1 when the frame changes the bus state */
    pb_can_bus_state state; /**< the new state when has_state */
    int rx_overflow;        /**< controller lost received frames */
    int tx_overflow;
    int protocol;           /**< protocol violation / bus error seen */
    int restarted;          /**< controller restarted after bus-off */
    uint8_t tx_errors, rx_errors; /**< error counters when the frame carries them, else 0 */
} pb_can_error_info;

/** Decode an error frame (flags & PB_CAN_ERR). Non-error frames give an empty info. */
void pb_can_error_decode(const pb_can_frame *f, pb_can_error_info *info);

/** Human-readable description, e.g. "bus-off" or "error-passive (rx 130, tx 8)". */
void pb_can_error_describe(const pb_can_frame *f, char *buf, size_t size);

/** "active", "warning", "passive", "bus-off". */
const char *pb_can_bus_state_name(pb_can_bus_state s);

#endif /* POSE_BRIDGE_CAN_ERROR_H */
