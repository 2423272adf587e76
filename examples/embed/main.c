/* SPDX-License-Identifier: Apache-2.0
 *
 * A minimal third-party host: finds pose as an installed package (CMake
 * find_package or pkg-config), loads a rig, swings one joint back and forth
 * and every N frames writes the deformed skin as a Wavefront OBJ file.
 *
 *   embed RIG OUTDIR [FRAMES] [EVERY] [JOINT]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <pose/pose.h>

/* The skin: the first tissue of kind skin, else the first tissue. */
static int find_skin(const pose_rig *rig)
{
    for (int t = 0; t < (int)pose_rig_tissue_count(rig); t++) {
        pose_tissue_info info;
        if (pose_rig_tissue_info(rig, t, &info) == POSE_OK && info.kind == POSE_TISSUE_SKIN)
            return t;
    }
    return pose_rig_tissue_count(rig) > 0 ? 0 : -1;
}

static int write_obj(const char *path, const pose_state *st, int tissue)
{
    pose_tissue_info info;
    size_t n;
    pose_rig_tissue_info(pose_state_rig(st), tissue, &info);
    const float *xyz = pose_tissue_positions(st, tissue, &n);
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "o %s\n", info.name);
    for (size_t v = 0; v < n; v++)
        fprintf(f, "v %.6f %.6f %.6f\n", xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
    for (size_t k = 0; k < info.triangle_count; k++)
        fprintf(f, "f %u %u %u\n", info.triangles[3 * k] + 1, info.triangles[3 * k + 1] + 1,
                info.triangles[3 * k + 2] + 1);
    return fclose(f);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s RIG OUTDIR [FRAMES=60] [EVERY=20] [JOINT]\n", argv[0]);
        return 2;
    }
    int frames = argc > 3 ? atoi(argv[3]) : 60, every = argc > 4 ? atoi(argv[4]) : 20;
    if (frames < 1 || every < 1) {
        fprintf(stderr, "FRAMES and EVERY must be positive\n");
        return 2;
    }
    printf("pose %s (built against %d.%d.%d)\n", pose_version_string(), POSE_VERSION_MAJOR, POSE_VERSION_MINOR,
           POSE_VERSION_PATCH);

    pose_rig *rig;
    if (pose_rig_load(argv[1], &rig) < 0) {
        fprintf(stderr, "%s\n", pose_last_error());
        return 1;
    }
    pose_state *st;
    if (pose_state_create(rig, &st) < 0) {
        fprintf(stderr, "%s\n", pose_last_error());
        pose_rig_free(rig);
        return 1;
    }
    int joint = argc > 5 ? pose_rig_find_joint(rig, argv[5]) : (int)pose_rig_joint_count(rig) / 2;
    int skin = find_skin(rig);
    if (joint < 0 || skin < 0) {
        fprintf(stderr, "%s: no joint '%s' or no tissue\n", argv[1], argc > 5 ? argv[5] : "(middle)");
        pose_state_free(st);
        pose_rig_free(rig);
        return 1;
    }
    int written = 0, rc = 0;
    for (int f = 0; f < frames; f++) {
        /* The host's frame loop: set joints, pose, read the skin. */
        const float deg[3] = {0.0f, 45.0f * sinf(6.2831853f * (float)f / (float)frames), 0.0f};
        pose_set_joint_euler(st, joint, deg, POSE_EULER_XYZ); /* POSE_CLAMPED is fine here */
        if (pose_apply(st) < 0) {
            fprintf(stderr, "%s\n", pose_last_error());
            rc = 1;
            break;
        }
        if (f % every == 0) {
            char path[4096];
            snprintf(path, sizeof path, "%s/skin_%04d.obj", argv[2], f);
            if (write_obj(path, st, skin) != 0) {
                fprintf(stderr, "%s: cannot write\n", path);
                rc = 1;
                break;
            }
            written++;
        }
    }
    printf("posed %d frames, wrote %d OBJ files to %s\n", frames, written, argv[2]);
    pose_state_free(st);
    pose_rig_free(rig);
    return rc;
}
