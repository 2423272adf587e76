/* SPDX-License-Identifier: Apache-2.0
 * A schematic full body for tests and benchmarks that need no baked rig. */
#include <string.h>

#include "rig_skel.h"

pose_status pb_rig_skel_schematic_body(pb_rig_skel **out, pb_error *err)
{
    /* name, parent, flexion axis, abduction axis (rest frame; rotation is z).
     * The template's frames: y flexes knee and elbow and extends the hip and
     * ankle; x abducts the right limbs and adducts the left ones. */
    static const struct {
        const char *name, *parent;
        float flex, abd; /* signs of +y and +x */
    } J[] = {
        {"pelvis", NULL, 0, 0},         {"lumbar", "pelvis", 1, 1},      {"thorax", "lumbar", 1, 1},
        {"neck", "thorax", 1, 1},       {"head", "neck", 1, 1},          {"clavicle_r", "thorax", 1, 1},
        {"shoulder_r", "clavicle_r", 1, 1}, {"elbow_r", "shoulder_r", 1, 1}, {"wrist_r", "elbow_r", 1, 1},
        {"clavicle_l", "thorax", 1, -1}, {"shoulder_l", "clavicle_l", 1, -1}, {"elbow_l", "shoulder_l", 1, -1},
        {"wrist_l", "elbow_l", 1, -1},  {"hip_r", "pelvis", -1, 1},      {"knee_r", "hip_r", 1, 1},
        {"ankle_r", "knee_r", -1, 1},   {"hip_l", "pelvis", -1, -1},     {"knee_l", "hip_l", 1, -1},
        {"ankle_l", "knee_l", -1, -1},
    };
    enum { N = sizeof J / sizeof J[0] };
    pose_joint_desc d[N];
    memset(d, 0, sizeof d);
    for (int i = 0; i < N; i++) {
        d[i].name = J[i].name;
        d[i].parent = -1;
        for (int k = 0; k < i; k++)
            if (J[i].parent && strcmp(J[k].name, J[i].parent) == 0)
                d[i].parent = k;
        d[i].rest_model.rotation[3] = 1.0f;
        d[i].rest_model.translation[2] = 0.1f * (float)i;
    }
    pose_status s = pb_rig_skel_from_desc(d, N, out, err);
    for (int i = 1; s == POSE_OK && i < N; i++) {
        pb_rig_joint *R = &(*out)->joints[i];
        pose_joint_clinical *c = &R->clinical;
        c->neutral[3] = 1.0f;
        c->axes[0][1] = J[i].flex;
        c->axes[1][0] = J[i].abd;
        c->axes[2][2] = 1.0f;
        static const char *const names[3] = {"flexion", "abduction", "rotation"};
        for (int k = 0; k < 3; k++) {
            strcpy(R->clinical_names[k], names[k]);
            c->names[k] = R->clinical_names[k];
        }
        c->flags = POSE_CLINICAL_DEFINED;
    }
    return s;
}
