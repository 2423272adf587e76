/* SPDX-License-Identifier: Apache-2.0 */
/* A small hand-made rig description exercising every section: 3 joints, two
 * unit cubes of 6 tets each, K = 2 weights, CoR centres, two tissues and
 * metadata. Values are chosen so that every array is distinguishable. */
#ifndef POSE_TEST_TINY_RIG_H
#define POSE_TEST_TINY_RIG_H

#include "pose/pose.h"

typedef struct tiny_rig {
    pose_joint_desc joints[3];
    float tet_positions[12 * 3];
    uint32_t tets[12 * 4];
    uint16_t labels[12];
    uint16_t weight_joints[12 * 2];
    float weights[12 * 2];
    float cor[12 * 3];
    pose_tissue_desc tissues[2];
    float skin_positions[4 * 3];
    uint32_t skin_triangles[4 * 3];
    uint32_t skin_tet[4];
    float skin_bary[4 * 4];
    float bone_positions[3 * 3];
    uint32_t bone_triangles[3];
    uint32_t bone_tet[3];
    float bone_bary[3 * 4];
    pose_joint_clinical clinical[3];
    pose_fem_material fem;
    pose_fem_coupling couplings[2];
    pose_fem_soft_coupling soft_couplings[2];
    pose_rig_desc desc;
} tiny_rig;

/** Fill `t`; `with_cor` / `with_metadata` select the optional sections. */
void tiny_rig_init(tiny_rig *t, int with_cor, int with_metadata);
/** Add the optional clinical section: root without clinical data, elbow with
 *  a 30-degree neutral, right-handed axes, default names and two limited
 *  angles, wrist with left-handed axes, its own names and three limits. */
void tiny_rig_add_clinical(tiny_rig *t);

/** Add the optional fem and couplings sections: two soft nodes (vertices 9
 *  and 10, of cube 1) tied to the elbow and the wrist. */
void tiny_rig_add_couplings(tiny_rig *t);
/** Add the optional fem and soft_couplings sections: vertex 8 tied to
 *  vertex 11, vertex 9 to a point of 10, 11 and 8 (cube 1's free nodes). */
void tiny_rig_add_soft_couplings(tiny_rig *t);

#endif /* POSE_TEST_TINY_RIG_H */
