/* SPDX-License-Identifier: Apache-2.0
 * Two-point calibration of scalar channels (the hid-calibrate command):
 * measure a channel while the joint is held at a known angle, then write
 * {"raw": [r0, r1], "deg": [d0, d1]} into the mapping file's entry. */
#ifndef POSE_BRIDGE_HID_CALIBRATE_H
#define POSE_BRIDGE_HID_CALIBRATE_H

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

#endif /* POSE_BRIDGE_HID_CALIBRATE_H */
