/* SPDX-License-Identifier: Apache-2.0
 *
 * One CAN frame as the bridge handles it, independent of where it came from
 * (a SocketCAN socket, a candump -l log, a test). Classic and FD frames share
 * the struct; error frames keep the kernel's error class and data bytes so
 * can_error.c can decode them the same way for live and replayed buses.
 */
#ifndef POSE_BRIDGE_CAN_FRAME_H
#define POSE_BRIDGE_CAN_FRAME_H

#include <stdint.h>

enum {
    PB_CAN_EXT = 1u << 0, /**< 29-bit identifier */
    PB_CAN_RTR = 1u << 1, /**< remote request: no data */
    PB_CAN_FD = 1u << 2,  /**< CAN FD frame (up to 64 bytes) */
    PB_CAN_BRS = 1u << 3, /**< FD: bit rate switch */
    PB_CAN_ESI = 1u << 4, /**< FD: error state indicator of the sender */
    PB_CAN_ERR = 1u << 5, /**< error frame: id holds the error class (CAN_ERR_*) */
};

#define PB_CAN_MAX_DATA 64

typedef struct pb_can_frame {
    int64_t t_ns;   /**< receive time (recorded time in a replay) */
    uint32_t id;    /**< 11- or 29-bit identifier, or error class; flags removed */
    uint8_t flags;  /**< PB_CAN_* */
    uint8_t len;    /**< data bytes, 0..8 classic, 0..64 FD */
    uint8_t dlc;    /**< classic frames: raw DLC 0..15 (len8_dlc), else len */
    uint8_t data[PB_CAN_MAX_DATA];
} pb_can_frame;

/** Bytes an FD DLC code (0..15) stands for. */
static inline unsigned pb_can_fd_dlc_to_len(unsigned dlc)
{
    static const uint8_t len[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
    return len[dlc & 15];
}

/** 1 when len is a length a CAN FD frame can carry. */
static inline int pb_can_fd_len_valid(unsigned len)
{
    return len <= 8 || len == 12 || len == 16 || len == 20 || len == 24 || len == 32 || len == 48 ||
           len == 64;
}

#endif /* POSE_BRIDGE_CAN_FRAME_H */
