/* SPDX-License-Identifier: Apache-2.0 */
#include "canopen_decode.h"

int pb_canopen_406_angle(const uint8_t *data, size_t len, uint32_t steps_per_rev, double *deg)
{
    if (len < 4 || steps_per_rev == 0)
        return 0;
    /* CANopen is little-endian on the wire. */
    const uint32_t pos = (uint32_t)data[0] | (uint32_t)data[1] << 8 | (uint32_t)data[2] << 16 |
                         (uint32_t)data[3] << 24;
    const uint32_t r = pos % steps_per_rev;
    double a = (double)r * 360.0 / (double)steps_per_rev;
    if (a >= 180.0)
        a -= 360.0;
    *deg = a;
    return 1;
}

int pb_canopen_410_slopes(const uint8_t *data, size_t len, double resolution_deg, double *longitudinal,
                          double *lateral)
{
    int n = 0;
    if (len >= 2) {
        *longitudinal = (int16_t)(uint16_t)(data[0] | data[1] << 8) * resolution_deg;
        n++;
    }
    if (len >= 4) {
        *lateral = (int16_t)(uint16_t)(data[2] | data[3] << 8) * resolution_deg;
        n++;
    }
    return n;
}

const char *pb_canopen_nmt_name(unsigned state)
{
    switch (state) {
    case PB_CANOPEN_BOOTUP: return "boot-up";
    case PB_CANOPEN_STOPPED: return "stopped";
    case PB_CANOPEN_OPERATIONAL: return "operational";
    case PB_CANOPEN_PRE_OPERATIONAL: return "pre-operational";
    }
    return "unknown";
}
