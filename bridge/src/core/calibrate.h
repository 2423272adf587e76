/* SPDX-License-Identifier: Apache-2.0
 * Calibration of scalar channels (the hid-calibrate and can-calibrate
 * commands), for any source: measure channels while the joints are held at
 * known angles -- the neutral posture for all of them at once, then one more
 * known angle per channel -- and write {"raw": [r0, r1], "deg": [d0, d1]}
 * into the mapping file's entries. */
#ifndef POSE_BRIDGE_CALIBRATE_H
#define POSE_BRIDGE_CALIBRATE_H

#include "mapping.h"
#include "pb_error.h"
#include "source.h"

/**
 * Mean of `samples` consecutive values of channel `channel` read from src
 * (other channels ignored). POSE_ERR_IO when the source stops delivering
 * (state and message say why) or nothing arrives within timeout_ms.
 */
pose_status pb_calibrate_measure(pb_source *src, uint32_t channel, int samples, int timeout_ms, double *mean,
                                 pb_error *err);

/**
 * Set the two-point calibration of one "channels" entry of a mapping file,
 * found by its "channel" name (or, when name is NULL, by index), leaving the
 * rest of the file as it was. The file is replaced atomically (rename).
 */
pose_status pb_calibrate_write(const char *map_path, const char *name, int index, const double raw[2],
                               const double deg[2], pb_error *err);

/** The "channel" of entry `index` (or the one named) in a mapping file: name, or "usage"/"index". */
pose_status pb_calibrate_entry(const char *map_path, const char *name, int index, char *channel, size_t size,
                               uint32_t *usage, int *usage_index, pb_error *err);

/**
 * The neutral posture of every entry at once: the mean of `samples` values of
 * each channel the mapping's entries bind, read from src, into means[i] for
 * entry i (NaN for an entry whose channel the source lacks).
 */
pose_status pb_calibrate_measure_entries(pb_source *src, const pb_mapping *map, int samples, int timeout_ms,
                                         double *means, pb_error *err);

/**
 * Write neutral offsets: every entry whose neutral_raw[i] is finite gets the
 * two-point calibration that reads neutral_raw[i] as 0 degrees and keeps its
 * gain (degrees per raw unit; 1 without a calibration). `map` must be the
 * parsed `map_path`. *written (may be NULL) counts the entries changed.
 */
pose_status pb_calibrate_write_neutral(const char *map_path, const pb_mapping *map, const double *neutral_raw,
                                       int *written, pb_error *err);

#endif /* POSE_BRIDGE_CALIBRATE_H */
