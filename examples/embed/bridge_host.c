/* SPDX-License-Identifier: Apache-2.0
 *
 * A third-party host driving a patient from a device through the installed
 * bridge (pose/bridge.h, libpose_bridge): open a source by its string, apply
 * the newest pose every frame of the host's loop (never waits), close. The
 * same code runs a recording or a live device:
 *
 *   bridge_host RIG SOURCE MAP [FRAMES]
 *   bridge_host body.rig data/hid/mannequin_sit_to_stand.hid hid_mannequin_full_body.json
 *   bridge_host body.rig hid:1209:0001 hid_mannequin_full_body.json      # the mannequin, plugged in
 *   bridge_host body.rig can0 can_rig_fullbody.json                       # the CAN rig
 *
 * It runs FRAMES host frames at 60 Hz (default 100), then prints how many
 * fresh poses arrived and how far the joints moved; exit status 1 when no
 * pose arrived or nothing moved.
 */
#define _POSIX_C_SOURCE 200809L /* nanosleep */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <pose/bridge.h>

static void sleep_s(double s)
{
    struct timespec ts = {(time_t)s, (long)((s - floor(s)) * 1e9)};
    nanosleep(&ts, NULL);
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: bridge_host RIG SOURCE MAP [FRAMES]\n");
        return 2;
    }
    int frames = argc > 4 ? atoi(argv[4]) : 100;
    pose_rig *rig = NULL;
    pose_state *state = NULL;
    if (pose_rig_load(argv[1], &rig) < 0 || pose_state_create(rig, &state) < 0) {
        fprintf(stderr, "bridge_host: %s\n", pose_last_error());
        return 1;
    }
    size_t joints = pose_rig_joint_count(rig);
    float (*first)[3] = calloc(joints ? joints : 1, sizeof *first);
    if (!first)
        return 1;

    /* --- the device quickstart: open, update each frame, close --- */
    pose_bridge *bridge;
    pose_bridge_options opt = {.size = sizeof opt, .map_path = argv[3]};
    if (pose_bridge_open(argv[2], rig, &opt, &bridge) < 0) {
        fprintf(stderr, "bridge_host: %s\n", pose_last_error());
        return 1;
    }
    int fresh = 0, held = 0, seen = 0;
    double moved = 0.0;
    for (int frame = 0; frame < frames; frame++) {
        pose_bridge_frame f;
        if (pose_bridge_apply(bridge, state, &f) < 0 || pose_apply(state) < 0) {
            fprintf(stderr, "bridge_host: %s\n", pose_last_error());
            return 1;
        }
        fresh += f.fresh != 0;
        held += f.held != 0;
        for (size_t j = 0; j < joints && f.seq > 0; j++) { /* how far each joint went from the first pose */
            pose_transform w;
            pose_joint_world(state, (int)j, &w);
            for (int k = 0; k < 3 && !seen; k++)
                first[j][k] = w.translation[k];
            double dx = w.translation[0] - first[j][0], dy = w.translation[1] - first[j][1],
                   dz = w.translation[2] - first[j][2];
            double d = sqrt(dx * dx + dy * dy + dz * dz);
            moved = d > moved ? d : moved;
        }
        seen = seen || f.seq > 0;
        sleep_s(1.0 / 60.0); /* the rest of the host's frame: render, input ... */
    }
    pose_bridge_status st = {.size = sizeof st};
    pose_bridge_status_get(bridge, &st);
    pose_bridge_close(bridge);
    /* --- */

    printf("bridge_host: %d fresh poses in %d frames (%d held), %llu samples, source %s (%s); joints moved up "
           "to %.3f\n",
           fresh, frames, held, (unsigned long long)st.samples, st.kind, pose_bridge_state_name(st.state), moved);
    free(first);
    pose_state_free(state);
    pose_rig_free(rig);
    return fresh > 0 && moved > 1e-3 ? 0 : 1;
}
