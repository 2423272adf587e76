/* SPDX-License-Identifier: Apache-2.0 */
#include "can_error.h"

#include <stdio.h>
#include <string.h>

void pb_can_error_decode(const pb_can_frame *f, pb_can_error_info *info)
{
    memset(info, 0, sizeof *info);
    if (!(f->flags & PB_CAN_ERR))
        return;
    const uint32_t cls = f->id;
    const uint8_t ctrl = f->len > 1 ? f->data[1] : 0;
    if (cls & PB_CAN_ERR_CNT || f->len >= 8) {
        info->tx_errors = f->len > 6 ? f->data[6] : 0;
        info->rx_errors = f->len > 7 ? f->data[7] : 0;
    }
    if (cls & PB_CAN_ERR_CRTL) {
        info->rx_overflow = (ctrl & PB_CAN_ERR_CRTL_RX_OVERFLOW) != 0;
        info->tx_overflow = (ctrl & PB_CAN_ERR_CRTL_TX_OVERFLOW) != 0;
        /* The worst state the frame announces wins; "active" only when it is all it says. */
        if (ctrl & (PB_CAN_ERR_CRTL_RX_PASSIVE | PB_CAN_ERR_CRTL_TX_PASSIVE)) {
            info->has_state = 1;
            info->state = PB_CAN_BUS_PASSIVE;
        } else if (ctrl & (PB_CAN_ERR_CRTL_RX_WARNING | PB_CAN_ERR_CRTL_TX_WARNING)) {
            info->has_state = 1;
            info->state = PB_CAN_BUS_WARNING;
        } else if (ctrl & PB_CAN_ERR_CRTL_ACTIVE) {
            info->has_state = 1;
            info->state = PB_CAN_BUS_ACTIVE;
        }
    }
    if (cls & (PB_CAN_ERR_PROT | PB_CAN_ERR_BUSERROR))
        info->protocol = 1;
    if (cls & PB_CAN_ERR_RESTARTED) {
        info->restarted = 1;
        info->has_state = 1;
        info->state = PB_CAN_BUS_ACTIVE;
    }
    if (cls & PB_CAN_ERR_BUSOFF) { /* checked last: bus-off outranks everything in the same frame */
        info->has_state = 1;
        info->state = PB_CAN_BUS_OFF;
    }
}

const char *pb_can_bus_state_name(pb_can_bus_state s)
{
    switch (s) {
    case PB_CAN_BUS_ACTIVE: return "error-active";
    case PB_CAN_BUS_WARNING: return "error-warning";
    case PB_CAN_BUS_PASSIVE: return "error-passive";
    case PB_CAN_BUS_OFF: return "bus-off";
    }
    return "unknown";
}

void pb_can_error_describe(const pb_can_frame *f, char *buf, size_t size)
{
    pb_can_error_info e;
    pb_can_error_decode(f, &e);
    size_t n = 0;
    buf[0] = '\0';
#define PB_ADD(...)                                                                                \
    do {                                                                                           \
        if (n < size) {                                                                            \
            int w = snprintf(buf + n, size - n, "%s", n ? ", " : "");                              \
            n += w > 0 ? (size_t)w : 0;                                                            \
        }                                                                                          \
        if (n < size) {                                                                            \
            int w = snprintf(buf + n, size - n, __VA_ARGS__);                                      \
            n += w > 0 ? (size_t)w : 0;                                                            \
        }                                                                                          \
    } while (0)
    if (e.has_state)
        PB_ADD("%s", pb_can_bus_state_name(e.state));
    if (e.restarted)
        PB_ADD("controller restarted");
    if (e.rx_overflow)
        PB_ADD("controller rx overflow");
    if (e.tx_overflow)
        PB_ADD("controller tx overflow");
    if (e.protocol)
        PB_ADD("protocol violation");
    if (f->id & PB_CAN_ERR_ACK)
        PB_ADD("no ack");
    if (f->id & PB_CAN_ERR_TX_TIMEOUT)
        PB_ADD("tx timeout");
    if (f->id & PB_CAN_ERR_LOSTARB)
        PB_ADD("lost arbitration");
    if (f->id & PB_CAN_ERR_TRX)
        PB_ADD("transceiver fault");
    if (e.tx_errors || e.rx_errors)
        PB_ADD("tx errors %u, rx errors %u", e.tx_errors, e.rx_errors);
    if (n == 0)
        PB_ADD("error frame 0x%03x", (unsigned)f->id);
#undef PB_ADD
}
