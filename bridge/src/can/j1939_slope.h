/* SPDX-License-Identifier: Apache-2.0
 *
 * J1939 slope sensors: PGN 61459 (0xF013) "Slope Sensor Information" (SSI).
 * Bytes 1-2 pitch angle (SPN 3318) and bytes 3-4 roll angle (SPN 3319),
 * little-endian, 0.002 deg/bit, offset -64 deg; raw values from 0xFB00 up
 * mean error or not available.
 */
#ifndef POSE_BRIDGE_J1939_SLOPE_H
#define POSE_BRIDGE_J1939_SLOPE_H

#include <stddef.h>
#include <stdint.h>

#define PB_J1939_PGN_SSI 61459u

/** PGN of a 29-bit identifier (PDU1 destination-specific PGNs have PS = 0). */
uint32_t pb_j1939_pgn(uint32_t id);
/** Source address: the identifier's low byte. */
static inline uint8_t pb_j1939_source(uint32_t id) { return (uint8_t)(id & 0xff); }
/** Identifier for a PGN sent by a source at a priority (0..7). */
uint32_t pb_j1939_id(uint32_t pgn, uint8_t source, unsigned priority);

/** Decode SSI pitch and roll in degrees. Bit 0 of the result: pitch valid; bit 1: roll valid. */
int pb_j1939_ssi_decode(const uint8_t *data, size_t len, double *pitch_deg, double *roll_deg);

#endif /* POSE_BRIDGE_J1939_SLOPE_H */
