/* SPDX-License-Identifier: Apache-2.0 */
#include "j1939_slope.h"

uint32_t pb_j1939_pgn(uint32_t id)
{
    const uint32_t dp_pf = (id >> 16) & 0x3ff; /* EDP, DP, PF */
    const uint32_t pf = dp_pf & 0xff;
    const uint32_t ps = (id >> 8) & 0xff;
    return dp_pf << 8 | (pf >= 240 ? ps : 0);
}

uint32_t pb_j1939_id(uint32_t pgn, uint8_t source, unsigned priority)
{
    return (uint32_t)(priority & 7) << 26 | (pgn & 0x3ffff) << 8 | source;
}

static int angle(const uint8_t *p, double *deg)
{
    const unsigned raw = (unsigned)p[0] | (unsigned)p[1] << 8;
    if (raw >= 0xfb00)
        return 0;
    *deg = raw * 0.002 - 64.0;
    return 1;
}

int pb_j1939_ssi_decode(const uint8_t *data, size_t len, double *pitch_deg, double *roll_deg)
{
    int ok = 0;
    if (len >= 2 && angle(data, pitch_deg))
        ok |= 1;
    if (len >= 4 && angle(data + 2, roll_deg))
        ok |= 2;
    return ok;
}
