/* SPDX-License-Identifier: Apache-2.0 */
/* The issue's postures of the baked body, and how far its bone tissues are
 * from their joints' rigid motion (tests runtime_fem_body*). */
#ifndef POSE_TEST_FEM_POSTURES_H
#define POSE_TEST_FEM_POSTURES_H

#include <stddef.h>

#include "fem_volume.h"
#include "pose/pose.h"

typedef struct fx_posture {
    const char *name;
    const char *joints[2];
    float deg[3];
} fx_posture;

/* Both sides, clinical angles; every other joint stays at rest (the
 * T-pose the body was scanned in). Arms at the sides: the shoulders'
 * neutral posture. */
static const fx_posture fx_postures[] = {
    {"shoulder flexion 150", {"shoulder_r", "shoulder_l"}, {150, 0, 0}},
    {"arms at the sides", {"shoulder_r", "shoulder_l"}, {0, 0, 0}},
    {"hip flexion 90", {"hip_r", "hip_l"}, {90, 0, 0}},
    {"knee flexion 120", {"knee_r", "knee_l"}, {120, 0, 0}},
    {"elbow flexion 120", {"elbow_r", "elbow_l"}, {120, 0, 0}},
};
#define FX_POSTURES (sizeof fx_postures / sizeof fx_postures[0])

/** Largest distance, over every vertex of every bone tissue, from its rest
 *  position moved by its joint's rigid motion (world frame times the inverse
 *  of the rest frame, from the public API); -1 on an API error. */
static inline double fx_bone_deviation(const pose_rig *rig, const pose_state *st)
{
    double worst = 0.0;
    for (size_t t = 0; t < pose_rig_tissue_count(rig); t++) {
        pose_tissue_info info;
        pose_joint_info ji;
        pose_transform w;
        if (pose_rig_tissue_info(rig, (int)t, &info) != POSE_OK)
            return -1.0;
        if (info.kind != POSE_TISSUE_BONE || info.joint < 0)
            continue;
        if (pose_rig_joint_info(rig, info.joint, &ji) != POSE_OK ||
            pose_joint_world(st, info.joint, &w) != POSE_OK)
            return -1.0;
        double d = fx_rigid_deviation(&ji.rest_model, &w, info.rest_positions,
                                      pose_tissue_positions(st, (int)t, NULL), info.vertex_count);
        if (d > worst)
            worst = d;
    }
    return worst;
}

#endif /* POSE_TEST_FEM_POSTURES_H */
