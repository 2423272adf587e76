/* SPDX-License-Identifier: Apache-2.0
 *
 * Simulated HID device: replays one device of a hid-recorder file through
 * the same source state machine and decoder as a live device, at recorded
 * timing (scaled by speed) or as fast as possible, optionally looping, and
 * optionally injecting faults (unplug, silence, garbage, wrong report IDs,
 * short reports) for tests and demos.
 */
#ifndef POSE_BRIDGE_HID_REPLAY_H
#define POSE_BRIDGE_HID_REPLAY_H

#include "hid_recorder.h"
#include "hid_source.h"

typedef enum pb_hid_fault_kind {
    PB_HID_FAULT_DISCONNECT = 1, /**< read fails, device absent for duration_ms, then returns */
    PB_HID_FAULT_SILENCE = 2,    /**< no reports for duration_ms */
    PB_HID_FAULT_GARBAGE = 3,    /**< one report of random bytes and length */
    PB_HID_FAULT_WRONG_ID = 4,   /**< one full-length report with an undeclared ID */
    PB_HID_FAULT_SHORT = 5,      /**< one report cut to half its length */
} pb_hid_fault_kind;

/** A fault that happens once, just before the device's event number at_event (0-based). */
typedef struct pb_hid_fault {
    size_t at_event;
    pb_hid_fault_kind kind;
    int duration_ms;
} pb_hid_fault;

/** Options; zero means default. */
typedef struct pb_hid_replay_options {
    pb_hid_source_options source;
    double speed;             /**< 1 (default) = recorded timing, 2 = twice as fast ... */
    int as_fast_as_possible;  /**< ignore timing: each read returns the next report */
    int loop;                 /**< restart at the end; times keep increasing */
    unsigned device;          /**< device index in the file (D: n) */
    int absent_ms;            /**< the device is plugged in only this long after the source is made */
    const pb_hid_fault *faults; /**< copied */
    size_t fault_count;
} pb_hid_replay_options;

/** Open a recording file as a source. Errors name the file and line. */
pose_status pb_hid_replay_open(const char *path, const pb_hid_replay_options *opt, pb_source **out, pb_error *err);

/** Same over a parsed recording, whose ownership passes to the source (even on failure). */
pose_status pb_hid_replay_create(pb_hid_recording *rec, const char *origin, const pb_hid_replay_options *opt,
                                 pb_source **out, pb_error *err);

#endif /* POSE_BRIDGE_HID_REPLAY_H */
