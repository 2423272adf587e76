/* SPDX-License-Identifier: Apache-2.0
 *
 * The reference mannequin: a goniometer box for hardware builders (documented
 * in bridge/devices/README.md). One input report, ID 1, 28 bytes:
 *
 *   byte 0       report ID (1)
 *   bytes 1-24   16 joint angles, 12-bit signed, packed little-endian,
 *                Ordinal usages 1..16, -1800..1800 = -180.0..180.0 degrees
 *                (Unit: English Rotation degrees, Unit Exponent -1)
 *   byte 25      bit 0: "hold pose" button (Button 1); bits 1-7 padding
 *   bytes 26-27  sample counter (vendor page 0xFF00, usage 1), wraps at 65536
 *
 * It also synthesises the motions the bundled recordings were made from
 * (bridge/devices/mannequin_gen.c), so tests can compare decoded angles with
 * the angles that produced them, and benchmarks can make long recordings.
 */
#ifndef POSE_BRIDGE_HID_MANNEQUIN_H
#define POSE_BRIDGE_HID_MANNEQUIN_H

#include <stddef.h>
#include <stdint.h>

#include "hid_recorder.h"
#include "rig_skel.h"

enum {
    PB_MANNEQUIN_AXES = 16,
    PB_MANNEQUIN_REPORT_ID = 1,
    PB_MANNEQUIN_REPORT_BYTES = 28,
    PB_MANNEQUIN_VENDOR = 0x1209, /**< pid.codes open-hardware vendor ID */
    PB_MANNEQUIN_PRODUCT = 0x0001, /**< placeholder: builders request their own product ID */
};

typedef enum pb_mannequin_motion {
    PB_MOTION_SIT_TO_STAND = 0,
    PB_MOTION_ARM_RAISE = 1,
    PB_MOTION_REACH = 2,
    PB_MOTION_COUNT = 3,
} pb_mannequin_motion;

extern const uint8_t pb_mannequin_descriptor[];
extern const size_t pb_mannequin_descriptor_len;

/** What each axis measures ("knee_l.flexion"), in report order. */
extern const char *const pb_mannequin_axis_names[PB_MANNEQUIN_AXES];

/** Motion name ("sit-to-stand", "arm-raise", "reach") and natural length in seconds. */
const char *pb_mannequin_motion_name(pb_mannequin_motion m);
double pb_mannequin_motion_seconds(pb_mannequin_motion m);

/** True anatomical angles (degrees) at time t of a motion, and the hold button. Loops past its end. */
void pb_mannequin_pose(pb_mannequin_motion m, double t, double deg[PB_MANNEQUIN_AXES], int *hold);

/**
 * The simulated sensors' mounting error: reported = gain * true + offset (+ noise).
 * A two-point calibration in the mapping removes it.
 */
void pb_mannequin_sensor(int axis, double *gain, double *offset_deg);

/** Pack one report: sensor error, noise from *rng (NULL = none), 0.1-degree quantisation. */
void pb_mannequin_pack(const double deg[PB_MANNEQUIN_AXES], int hold, uint16_t seq, uint32_t *rng,
                       uint8_t report[PB_MANNEQUIN_REPORT_BYTES]);

/**
 * Make a recording in memory: `seconds` of a motion at rate_hz, with USB
 * timing jitter and sensor noise drawn from `seed`. Free with pb_hid_recording_free.
 */
pose_status pb_mannequin_recording(pb_mannequin_motion m, double rate_hz, double seconds, uint32_t seed,
                                   pb_hid_recording **out, pb_error *err);

#endif /* POSE_BRIDGE_HID_MANNEQUIN_H */
