/* SPDX-License-Identifier: Apache-2.0
 * quickstart.c: load a rig, bend one joint, pose the whole anatomy and see
 * how far each tissue moved.
 * Build: cc quickstart.c $(pkg-config --cflags --libs pose) -Wl,-rpath,$(pkg-config --variable=libdir pose) -lm -o quickstart
 * Run:   ./quickstart patient.rig [JOINT] */
#include <math.h>
#include <stdio.h>

#include <pose/pose.h>

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s RIG [JOINT]\n", argv[0]);
        return 2;
    }
    pose_rig *rig;
    if (pose_rig_load(argv[1], &rig) < 0) {
        fprintf(stderr, "%s\n", pose_last_error()); /* names the file, section and offset */
        return 1;
    }
    pose_state *st;
    if (pose_state_create(rig, &st) < 0) {
        fprintf(stderr, "%s\n", pose_last_error());
        pose_rig_free(rig);
        return 1;
    }
    /* The joint to bend: by name, or the middle of the skeleton. */
    int joint = argc > 2 ? pose_rig_find_joint(rig, argv[2]) : (int)pose_rig_joint_count(rig) / 2;
    pose_joint_info info;
    if (pose_rig_joint_info(rig, joint, &info) < 0) {
        fprintf(stderr, "no joint '%s' in %s\n", argc > 2 ? argv[2] : "(middle)", argv[1]);
        pose_state_free(st);
        pose_rig_free(rig);
        return 1;
    }
    const float bend[3] = {0.0f, 60.0f, 0.0f}; /* degrees about x, y, z */
    if (pose_set_joint_euler(st, joint, bend, POSE_EULER_XYZ) == POSE_CLAMPED)
        printf("clamped: %s\n", pose_last_error());
    if (pose_set_method(st, POSE_COR) == POSE_ERR_UNSUPPORTED) /* rig without CoR data */
        pose_set_method(st, POSE_DQS);
    pose_apply(st);

    int still = 0;
    for (int t = 0; t < (int)pose_rig_tissue_count(rig); t++) {
        pose_tissue_info tissue;
        size_t n;
        pose_rig_tissue_info(rig, t, &tissue);
        const float *xyz = pose_tissue_positions(st, t, &n); /* x0 y0 z0 x1 y1 z1 ... */
        double moved = 0.0;
        for (size_t v = 0; v < 3 * n; v += 3) {
            double dx = xyz[v] - tissue.rest_positions[v], dy = xyz[v + 1] - tissue.rest_positions[v + 1],
                   dz = xyz[v + 2] - tissue.rest_positions[v + 2];
            moved = fmax(moved, sqrt(dx * dx + dy * dy + dz * dz));
        }
        if (moved > 1e-4)
            printf("%s bent 60 deg: tissue %s (%zu vertices) moved up to %.4f\n", info.name, tissue.name, n,
                   moved);
        else
            still++;
    }
    printf("%d other tissues did not move\n", still);
    pose_state_free(st);
    pose_rig_free(rig);
    return 0;
}
