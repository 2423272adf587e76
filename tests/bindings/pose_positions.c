/* SPDX-License-Identifier: Apache-2.0
 * The C side of the Python bindings' test: pose a rig through the C API
 * exactly as test_bindings.py does through the package, and write every
 * tissue's posed positions (float32, tissue after tissue) to OUT, so the two
 * can be compared bit for bit.
 *   pose_positions RIG OUT [CLIP MAP TIME]
 * The pose: with a clip, the clip's pose at TIME through the bridge
 * (MANUAL); then joint (joint count / 2) at Euler XYZ (10, 40, 0); DQS. */
#include <stdio.h>
#include <stdlib.h>

#include <pose/pose.h>
#ifdef POSE_POSITIONS_BRIDGE
#include <pose/bridge.h>
#endif

static int fail(const char *what)
{
    fprintf(stderr, "pose_positions: %s: %s\n", what, pose_last_error());
    return 1;
}

int main(int argc, char **argv)
{
    if (argc != 3 && argc != 6) {
        fprintf(stderr, "usage: %s RIG OUT [CLIP MAP TIME]\n", argv[0]);
        return 2;
    }
    pose_rig *rig;
    pose_state *st;
    if (pose_rig_load(argv[1], &rig) < 0)
        return fail("load");
    pose_state_options so = {.size = sizeof so, .method = POSE_DQS};
    if (pose_state_create_ex(rig, &so, &st) < 0)
        return fail("state");
    if (argc == 6) {
#ifdef POSE_POSITIONS_BRIDGE
        pose_bridge *br;
        pose_bridge_options bo = {.size = sizeof bo, .map_path = argv[4], .play = POSE_BRIDGE_MANUAL};
        if (pose_bridge_open(argv[3], rig, &bo, &br) < 0 || pose_bridge_pose_at(br, atof(argv[5]), st, NULL) < 0)
            return fail("bridge");
        pose_bridge_close(br);
#else
        fprintf(stderr, "pose_positions: built without the bridge\n");
        return 2;
#endif
    }
    const float bend[3] = {10.0f, 40.0f, 0.0f};
    if (pose_set_joint_euler(st, (int)pose_rig_joint_count(rig) / 2, bend, POSE_EULER_XYZ) < 0 || pose_apply(st) < 0)
        return fail("pose");
    FILE *f = fopen(argv[2], "wb");
    if (!f)
        return fail("open OUT");
    for (int t = 0; t < (int)pose_rig_tissue_count(rig); t++) {
        size_t n;
        const float *xyz = pose_tissue_positions(st, t, &n);
        if (fwrite(xyz, sizeof(float), 3 * n, f) != 3 * n)
            return fail("write");
    }
    if (fclose(f) != 0)
        return fail("close OUT");
    pose_state_free(st);
    pose_rig_free(rig);
    return 0;
}
