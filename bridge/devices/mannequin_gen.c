/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-hid-mannequin-gen: writes the reference mannequin recordings bundled
 * in data/hid/ (hid-recorder format) from the motions in hid_mannequin.c, so
 * they can be regenerated bit for bit:
 *
 *     pose-hid-mannequin-gen data/hid
 */
#include <stdio.h>
#include <string.h>

#include "hid_mannequin.h"

typedef struct recording_plan {
    const char *file;
    pb_mannequin_motion motion;
    double rate_hz, seconds;
    uint32_t seed;
} recording_plan;

static const recording_plan plans[] = {
    {"mannequin_sit_to_stand.hid", PB_MOTION_SIT_TO_STAND, 500.0, 8.0, 101},
    {"mannequin_arm_raise.hid", PB_MOTION_ARM_RAISE, 250.0, 10.0, 202},
    {"mannequin_reach_1khz.hid", PB_MOTION_REACH, 1000.0, 4.0, 303},
};

static int write_one(const char *dir, const recording_plan *p)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, p->file);
    pb_hid_recording *rec;
    pb_error err;
    if (pb_mannequin_recording(p->motion, p->rate_hz, p->seconds, p->seed, &rec, &err) != POSE_OK) {
        fprintf(stderr, "pose-hid-mannequin-gen: %s\n", err.message);
        return 1;
    }
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        pb_hid_recording_free(rec);
        return 1;
    }
    fprintf(f, "# pose reference mannequin (bridge/devices/README.md), simulated\n");
    fprintf(f, "# motion %s, %.0f Hz, %.1f s, noise seed %u; made by pose-hid-mannequin-gen\n",
            pb_mannequin_motion_name(p->motion), p->rate_hz, p->seconds, p->seed);
    fprintf(f, "# report 1: 16 x 12-bit signed angles (0.1 deg, Ordinal 1..16), hold button, 16-bit counter\n");
    for (int i = 0; i < PB_MANNEQUIN_AXES; i++) {
        double g, o;
        pb_mannequin_sensor(i, &g, &o);
        fprintf(f, "# axis %2d %-22s sensor gain %.3f offset %+.1f deg\n", i + 1, pb_mannequin_axis_names[i], g, o);
    }
    int bad = pb_hid_recorder_write_device(f, -1, &rec->devices[0]);
    for (size_t i = 0; !bad && i < rec->event_count; i++) {
        const pb_hid_rec_event *e = &rec->events[i];
        bad = pb_hid_recorder_write_event(f, e->t_ns, rec->data + e->offset, e->len);
    }
    bad |= fclose(f) != 0;
    fprintf(stderr, "%s: %zu reports%s\n", path, rec->event_count, bad ? " (write error)" : "");
    pb_hid_recording_free(rec);
    return bad ? 1 : 0;
}

int main(int argc, char **argv)
{
    if (argc != 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        fprintf(argc == 2 ? stdout : stderr,
                "usage: pose-hid-mannequin-gen OUTPUT_DIR\n"
                "Writes the reference mannequin recordings (hid-recorder format) into OUTPUT_DIR.\n");
        return argc == 2 ? 0 : 2;
    }
    int rc = 0;
    for (size_t i = 0; i < sizeof plans / sizeof plans[0]; i++)
        rc |= write_one(argv[1], &plans[i]);
    return rc;
}
