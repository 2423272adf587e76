/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-usb-gonio-gen: writes the reference USB goniometer box's captures
 * bundled in data/usb/ (usbmon "u" text) and their truth files (the true
 * angles every 50 ms) from the HID mannequin's motions, so they can be
 * regenerated bit for bit:
 *
 *     pose-usb-gonio-gen data/usb
 */
#include <stdio.h>
#include <string.h>

#include "usb_gonio.h"

/* The faulty capture's faults, by frame index (bridge/devices/README.md lists them; tests/usb checks the counts). */
static const uint32_t lost[] = {500, 501, 1700};
static const uint32_t late[] = {800, 2300};
static const uint32_t repeated[] = {1200};
static const uint32_t stall[] = {1000};
static const uint32_t babble[] = {1500};
static const uint32_t wire[] = {2000};
static const uint32_t short_xfer[] = {2500};
static const uint32_t bad_crc[] = {2600, 2601};

#define N(a) (sizeof a / sizeof a[0])

static const pb_gonio_faults faults = {
    1, lost, N(lost), late, N(late), repeated, N(repeated), stall, babble, wire, short_xfer, bad_crc,
    N(stall), N(babble), N(wire), N(short_xfer), N(bad_crc), 3000, 200,
};

typedef struct plan {
    const char *stem;
    pb_mannequin_motion motion;
    double rate_hz, seconds;
    uint32_t seed;
    int faulty;
} plan;

static const plan plans[] = {
    {"gonio_sit_to_stand", PB_MOTION_SIT_TO_STAND, 500.0, 8.0, 111, 0},
    {"gonio_arm_raise", PB_MOTION_ARM_RAISE, 250.0, 10.0, 222, 0},
    {"gonio_reach_faults", PB_MOTION_REACH, 1000.0, 4.0, 333, 1},
};

static int write_one(const char *dir, const plan *p)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.usbmon", dir, p->stem);
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        return 1;
    }
    fprintf(f, "# pose reference USB goniometer box (bridge/devices/README.md), simulated; usbmon text, u format\n");
    fprintf(f, "# motion %s, %.0f Hz, %.1f s, noise seed %u%s; made by pose-usb-gonio-gen\n",
            pb_mannequin_motion_name(p->motion), p->rate_hz, p->seconds, p->seed,
            p->faulty ? ", with injected faults" : "");
    long sent = pb_gonio_write_capture(f, p->motion, p->rate_hz, p->seconds, p->seed, p->faulty ? &faults : NULL);
    int bad = sent < 0;
    bad |= fclose(f) != 0;
    fprintf(stderr, "%s: %ld frames%s\n", path, sent, bad ? " (write error)" : "");
    if (bad)
        return 1;
    snprintf(path, sizeof path, "%s/%s_truth.csv", dir, p->stem);
    f = fopen(path, "w");
    if (!f) {
        perror(path);
        return 1;
    }
    fprintf(f, "t");
    for (int i = 0; i < PB_MANNEQUIN_AXES; i++)
        fprintf(f, ",%s", pb_mannequin_axis_names[i]);
    fprintf(f, ",hold\n");
    for (int k = 1; k * 0.05 < p->seconds - 0.01; k++) {
        double t = k * 0.05, deg[PB_MANNEQUIN_AXES];
        int hold;
        pb_mannequin_pose(p->motion, t, deg, &hold);
        fprintf(f, "%.2f", t);
        for (int i = 0; i < PB_MANNEQUIN_AXES; i++)
            fprintf(f, ",%.4f", deg[i]);
        fprintf(f, ",%d\n", hold);
    }
    return fclose(f) != 0;
}

int main(int argc, char **argv)
{
    if (argc != 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        fprintf(argc == 2 ? stdout : stderr,
                "usage: pose-usb-gonio-gen OUTPUT_DIR\n"
                "Writes the reference USB goniometer captures (usbmon text) and truth files into OUTPUT_DIR.\n");
        return argc == 2 ? 0 : 2;
    }
    int rc = 0;
    for (size_t i = 0; i < sizeof plans / sizeof plans[0]; i++)
        rc |= write_one(argv[1], &plans[i]);
    return rc;
}
