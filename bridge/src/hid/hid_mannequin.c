/* SPDX-License-Identifier: Apache-2.0 */
#include "hid_mannequin.h"

#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#define TWO_PI 6.283185307179586

/* Report descriptor of the mannequin; bridge/devices/README.md explains it line by line. */
const uint8_t pb_mannequin_descriptor[] = {
    0x05, 0x01,       /* Usage Page (Generic Desktop)                  */
    0x09, 0x08,       /* Usage (Multi-axis Controller)                 */
    0xA1, 0x01,       /* Collection (Application)                      */
    0x85, 0x01,       /*   Report ID (1)                               */
    0xA4,             /*   Push                                        */
    0x05, 0x0A,       /*   Usage Page (Ordinal)                        */
    0x19, 0x01,       /*   Usage Minimum (1)                           */
    0x29, 0x10,       /*   Usage Maximum (16)                          */
    0x16, 0xF8, 0xF8, /*   Logical Minimum (-1800)                     */
    0x26, 0x08, 0x07, /*   Logical Maximum (1800)                      */
    0x36, 0xF8, 0xF8, /*   Physical Minimum (-1800)                    */
    0x46, 0x08, 0x07, /*   Physical Maximum (1800)                     */
    0x65, 0x14,       /*   Unit (English Rotation: degrees)            */
    0x55, 0x0F,       /*   Unit Exponent (-1): 0.1 degree per count    */
    0x75, 0x0C,       /*   Report Size (12)                            */
    0x95, 0x10,       /*   Report Count (16)                           */
    0x81, 0x02,       /*   Input (Data, Variable, Absolute)            */
    0xB4,             /*   Pop: back to no unit, no physical range     */
    0x05, 0x09,       /*   Usage Page (Button)                         */
    0x09, 0x01,       /*   Usage (Button 1: hold pose)                 */
    0x15, 0x00,       /*   Logical Minimum (0)                         */
    0x25, 0x01,       /*   Logical Maximum (1)                         */
    0x75, 0x01,       /*   Report Size (1)                             */
    0x95, 0x01,       /*   Report Count (1)                            */
    0x81, 0x02,       /*   Input (Data, Variable, Absolute)            */
    0x75, 0x07,       /*   Report Size (7)                             */
    0x81, 0x03,       /*   Input (Constant, Variable): padding          */
    0x06, 0x00, 0xFF, /*   Usage Page (Vendor 0xFF00)                  */
    0x09, 0x01,       /*   Usage (1: sample counter)                   */
    0x15, 0x00,       /*   Logical Minimum (0)                         */
    0x27, 0xFF, 0xFF, 0x00, 0x00, /* Logical Maximum (65535)           */
    0x75, 0x10,       /*   Report Size (16)                            */
    0x81, 0x02,       /*   Input (Data, Variable, Absolute)            */
    0xC0,             /* End Collection                                */
};
const size_t pb_mannequin_descriptor_len = sizeof pb_mannequin_descriptor;

const char *const pb_mannequin_axis_names[PB_MANNEQUIN_AXES] = {
    "lumbar.flexion",       "neck.flexion",     "shoulder_l.flexion",   "shoulder_l.abduction",
    "shoulder_r.flexion",   "shoulder_r.abduction", "elbow_l.flexion",  "elbow_r.flexion",
    "hip_l.flexion",        "hip_l.abduction",  "hip_r.flexion",        "hip_r.abduction",
    "knee_l.flexion",       "knee_r.flexion",   "ankle_l.dorsiflexion", "ankle_r.dorsiflexion",
};

enum {
    LUMBAR, NECK, SHO_L_FLEX, SHO_L_ABD, SHO_R_FLEX, SHO_R_ABD, ELB_L, ELB_R,
    HIP_L_FLEX, HIP_L_ABD, HIP_R_FLEX, HIP_R_ABD, KNEE_L, KNEE_R, ANK_L, ANK_R,
};

const char *pb_mannequin_motion_name(pb_mannequin_motion m)
{
    static const char *const names[] = {"sit-to-stand", "arm-raise", "reach"};
    return (unsigned)m < PB_MOTION_COUNT ? names[m] : "unknown";
}

double pb_mannequin_motion_seconds(pb_mannequin_motion m)
{
    static const double secs[] = {8.0, 10.0, 4.0};
    return (unsigned)m < PB_MOTION_COUNT ? secs[m] : 1.0;
}

/* Minimum-jerk transition 0 -> 1 between t0 and t1 (Flash & Hogan 1985). */
static double ramp(double t, double t0, double t1)
{
    if (t <= t0)
        return 0.0;
    if (t >= t1)
        return 1.0;
    double u = (t - t0) / (t1 - t0);
    return u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
}

static double lerp(double a, double b, double s)
{
    return a + (b - a) * s;
}

/* Sit to stand: flexion-momentum phase (trunk leans, hips flex), seat-off,
 * extension phase, then quiet standing with a small postural sway. */
static void sit_to_stand(double t, double *d, int *hold)
{
    double lean = ramp(t, 1.5, 2.7), rise = ramp(t, 2.7, 4.5), rise_r = ramp(t, 2.65, 4.4);
    double sway = sin(TWO_PI * 0.3 * t) * ramp(t, 4.5, 5.5);
    d[LUMBAR] = lerp(lerp(10, 35, lean), 4, rise) + 0.8 * sway;
    d[NECK] = lerp(lerp(0, -12, lean), 2, rise);
    d[SHO_L_FLEX] = lerp(lerp(10, 35, lean), 5, rise);
    d[SHO_R_FLEX] = lerp(lerp(12, 38, lean), 6, rise);
    d[SHO_L_ABD] = lerp(8, 12, lean) - 4 * rise;
    d[SHO_R_ABD] = lerp(9, 13, lean) - 4 * rise;
    d[ELB_L] = lerp(lerp(65, 25, lean), 15, rise);
    d[ELB_R] = lerp(lerp(62, 22, lean), 14, rise);
    d[HIP_L_FLEX] = lerp(lerp(90, 108, lean), 4, rise) + 0.5 * sway;
    d[HIP_R_FLEX] = lerp(lerp(92, 111, lean), 5, rise_r) + 0.5 * sway;
    d[HIP_L_ABD] = lerp(6, 3, rise);
    d[HIP_R_ABD] = lerp(7, 3, rise_r);
    d[KNEE_L] = lerp(90, 4, rise);
    d[KNEE_R] = lerp(93, 5, rise_r);
    d[ANK_L] = lerp(lerp(4, 16, lean), 2, rise) + 0.7 * sway;
    d[ANK_R] = lerp(lerp(5, 17, lean), 2, rise_r) + 0.7 * sway;
    *hold = t >= 6.5 && t < 7.0;
}

/* Arm raise: bilateral abduction to overhead, hold (button pressed), lower;
 * then right forward flexion and back. */
static void arm_raise(double t, double *d, int *hold)
{
    double up = ramp(t, 1.0, 3.0) - ramp(t, 4.0, 6.0);
    double flex = ramp(t, 6.0, 8.0) - ramp(t, 8.5, 9.8);
    d[LUMBAR] = 2 - 5 * up - 3 * flex;
    d[NECK] = 3 - 8 * up;
    d[SHO_L_FLEX] = 4 + 10 * up;
    d[SHO_R_FLEX] = 5 + 10 * up + 145 * flex;
    d[SHO_L_ABD] = 6 + 154 * up;
    d[SHO_R_ABD] = 7 + 152 * ramp(t, 1.05, 3.05) - 152 * ramp(t, 4.0, 6.0) + 4 * flex;
    d[ELB_L] = 12 - 6 * up;
    d[ELB_R] = 11 - 5 * up - 3 * flex;
    d[HIP_L_FLEX] = 2;
    d[HIP_R_FLEX] = 3;
    d[HIP_L_ABD] = 4;
    d[HIP_R_ABD] = 4;
    d[KNEE_L] = 3;
    d[KNEE_R] = 4;
    d[ANK_L] = 1 + 0.5 * sin(TWO_PI * 0.25 * t);
    d[ANK_R] = 1 + 0.5 * sin(TWO_PI * 0.25 * t + 1.0);
    *hold = t >= 3.2 && t < 3.8;
}

/* Seated reach: the right arm reaches forward (shoulder flexes, elbow
 * extends) with the trunk following, then returns. */
static void reach(double t, double *d, int *hold)
{
    double out = ramp(t, 0.5, 1.7) - ramp(t, 2.3, 3.5);
    d[LUMBAR] = 8 + 18 * out;
    d[NECK] = -2 - 6 * out;
    d[SHO_L_FLEX] = 10;
    d[SHO_L_ABD] = 8;
    d[SHO_R_FLEX] = 12 + 80 * out;
    d[SHO_R_ABD] = 9 + 6 * out;
    d[ELB_L] = 70;
    d[ELB_R] = 85 - 75 * out;
    d[HIP_L_FLEX] = 90 + 10 * out;
    d[HIP_R_FLEX] = 91 + 12 * out;
    d[HIP_L_ABD] = 6;
    d[HIP_R_ABD] = 7;
    d[KNEE_L] = 88;
    d[KNEE_R] = 90;
    d[ANK_L] = 4;
    d[ANK_R] = 5;
    *hold = 0;
}

void pb_mannequin_pose(pb_mannequin_motion m, double t, double deg[PB_MANNEQUIN_AXES], int *hold)
{
    double len = pb_mannequin_motion_seconds(m);
    t = fmod(t, len);
    if (t < 0)
        t += len;
    int h = 0;
    switch (m) {
    case PB_MOTION_SIT_TO_STAND:
        sit_to_stand(t, deg, &h);
        break;
    case PB_MOTION_ARM_RAISE:
        arm_raise(t, deg, &h);
        break;
    default:
        reach(t, deg, &h);
        break;
    }
    if (hold)
        *hold = h;
}

/* Mounting error of each potentiometer: gain within 3 %, offset within 5 degrees. */
static const double sensor_gain[PB_MANNEQUIN_AXES] = {
    1.012, 0.985, 1.021, 0.977, 0.993, 1.028, 1.004, 0.972,
    1.017, 0.989, 0.981, 1.009, 1.025, 0.996, 0.978, 1.013,
};
static const double sensor_offset[PB_MANNEQUIN_AXES] = {
    2.4, -3.1, 1.2, 4.6, -0.8, -2.2, 3.7, -4.4,
    0.6, 2.9, -1.7, -3.8, 4.1, -0.3, 1.9, -2.6,
};

void pb_mannequin_sensor(int axis, double *gain, double *offset_deg)
{
    *gain = sensor_gain[axis];
    *offset_deg = sensor_offset[axis];
}

static double uniform(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return ((*s >> 8) + 0.5) / 16777216.0;
}

static double gaussian(uint32_t *s)
{
    double u = uniform(s), v = uniform(s);
    return sqrt(-2.0 * log(u)) * cos(TWO_PI * v);
}

void pb_mannequin_pack(const double deg[PB_MANNEQUIN_AXES], int hold, uint16_t seq, uint32_t *rng,
                       uint8_t report[PB_MANNEQUIN_REPORT_BYTES])
{
    memset(report, 0, PB_MANNEQUIN_REPORT_BYTES);
    report[0] = PB_MANNEQUIN_REPORT_ID;
    for (int i = 0; i < PB_MANNEQUIN_AXES; i++) {
        double v = sensor_gain[i] * deg[i] + sensor_offset[i] + (rng ? 0.12 * gaussian(rng) : 0.0);
        long c = lround(v * 10.0);
        c = c < -1800 ? -1800 : c > 1800 ? 1800 : c;
        uint32_t bits = (uint32_t)c & 0xFFF, at = 12u * (uint32_t)i;
        for (int b = 0; b < 12; b++, at++)
            if (bits >> b & 1)
                report[1 + at / 8] |= (uint8_t)(1u << (at % 8));
    }
    report[25] = hold ? 1 : 0;
    report[26] = (uint8_t)(seq & 0xFF);
    report[27] = (uint8_t)(seq >> 8);
}

pose_status pb_mannequin_recording(pb_mannequin_motion m, double rate_hz, double seconds, uint32_t seed,
                                   pb_hid_recording **out, pb_error *err)
{
    *out = NULL;
    if (!(rate_hz > 0 && rate_hz <= 10000) || !(seconds > 0 && seconds <= 3600))
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "mannequin: rate %g Hz or length %g s out of range",
                       rate_hz, seconds);
    size_t n = (size_t)(seconds * rate_hz);
    pb_hid_recording *rec = calloc(1, sizeof *rec);
    if (!rec)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "mannequin: out of memory");
    rec->devices = calloc(1, sizeof *rec->devices);
    rec->events = calloc(n ? n : 1, sizeof *rec->events);
    rec->data = malloc((n ? n : 1) * PB_MANNEQUIN_REPORT_BYTES);
    if (rec->devices)
        rec->devices[0].desc = malloc(pb_mannequin_descriptor_len);
    if (!rec->devices || !rec->events || !rec->data || !rec->devices[0].desc) {
        pb_hid_recording_free(rec);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "mannequin: out of memory");
    }
    rec->device_count = 1;
    pb_hid_rec_device *d = &rec->devices[0];
    memcpy(d->desc, pb_mannequin_descriptor, pb_mannequin_descriptor_len);
    d->desc_len = pb_mannequin_descriptor_len;
    snprintf(d->name, sizeof d->name, "pose reference mannequin (simulated)");
    snprintf(d->phys, sizeof d->phys, "usb-0000:00:14.0-2/input0");
    d->bus = 3;
    d->vendor = PB_MANNEQUIN_VENDOR;
    d->product = PB_MANNEQUIN_PRODUCT;
    uint32_t rng = seed ? seed : 1;
    double period = 1.0 / rate_hz;
    int64_t last = -1;
    for (size_t k = 0; k < n; k++) {
        double t = (double)k * period;
        /* The device samples on its own clock; the host stamps reports with USB frame jitter. */
        double jitter = (uniform(&rng) - 0.5) * 0.08 * period;
        int64_t t_ns = llround((t + jitter) * 1e9);
        if (t_ns <= last)
            t_ns = last + 1;
        last = t_ns;
        double deg[PB_MANNEQUIN_AXES];
        int hold;
        pb_mannequin_pose(m, t, deg, &hold);
        pb_mannequin_pack(deg, hold, (uint16_t)k, &rng, rec->data + k * PB_MANNEQUIN_REPORT_BYTES);
        rec->events[k] = (pb_hid_rec_event){t_ns, 0, 0, k * PB_MANNEQUIN_REPORT_BYTES, PB_MANNEQUIN_REPORT_BYTES};
    }
    rec->event_count = n;
    rec->data_len = n * PB_MANNEQUIN_REPORT_BYTES;
    d->event_count = n;
    *out = rec;
    return POSE_OK;
}
