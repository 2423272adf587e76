/* SPDX-License-Identifier: Apache-2.0 */
#include <string.h>

#include "tiny_rig.h"

/* Kuhn split of the unit cube: one tet per axis permutation, all sharing
 * the main diagonal 000-111. Corner index = x + 2y + 4z. */
static const int kuhn[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

static uint32_t vertex_of(int slice, int corner)
{
    return (uint32_t)(slice * 4 + corner);
}

static void embed(const tiny_rig *t, uint32_t tet, const float bary[4], float out[3])
{
    for (int i = 0; i < 3; i++) {
        out[i] = 0.0f;
        for (int k = 0; k < 4; k++)
            out[i] += bary[k] * t->tet_positions[3 * t->tets[4 * tet + k] + i];
    }
}

void tiny_rig_init(tiny_rig *t, int with_cor, int with_metadata)
{
    memset(t, 0, sizeof *t);
    static const char *const names[3] = {"root", "elbow", "wrist"};
    /* elbow is turned 90 degrees about Z relative to root */
    const float s = 0.70710678f;
    for (int j = 0; j < 3; j++) {
        pose_joint_desc *jd = &t->joints[j];
        jd->name = names[j];
        jd->parent = j - 1;
        jd->rest_model.rotation[3] = 1.0f;
        jd->rest_model.translation[0] = (float)j;
        jd->rest_model.translation[2] = 0.5f;
    }
    t->joints[1].rest_model.rotation[2] = s;
    t->joints[1].rest_model.rotation[3] = s;
    t->joints[2].rest_model.rotation[2] = s;
    t->joints[2].rest_model.rotation[3] = s;
    t->joints[1].limit_flags = POSE_LIMIT_Y;
    t->joints[1].limit_order = POSE_EULER_ZXY;
    t->joints[1].limit_min_deg[1] = -10.0f;
    t->joints[1].limit_max_deg[1] = 140.0f;

    /* 3 slices at x = 0, 1, 2 with corners (y, z) in {0,1}^2. */
    for (int sl = 0; sl < 3; sl++)
        for (int c = 0; c < 4; c++) {
            float *p = &t->tet_positions[3 * vertex_of(sl, c)];
            p[0] = (float)sl;
            p[1] = (float)(c & 1);
            p[2] = (float)((c >> 1) & 1);
        }
    /* cube corner (dx, dy, dz) -> mesh vertex */
    for (int cube = 0; cube < 2; cube++)
        for (int k = 0; k < 6; k++) {
            int at[3] = {0, 0, 0};
            uint32_t *tv = &t->tets[4 * (cube * 6 + k)];
            for (int step = 0; step < 4; step++) {
                if (step)
                    at[kuhn[k][step - 1]] = 1;
                tv[step] = vertex_of(cube + at[0], at[1] + 2 * at[2]);
            }
            t->labels[cube * 6 + k] = cube == 0 ? 1 : 0; /* cube 0 is root's bone */
        }
    for (uint32_t v = 0; v < 12; v++) {
        int sl = (int)v / 4;
        t->weight_joints[2 * v] = (uint16_t)(sl == 2 ? 1 : 0);
        t->weight_joints[2 * v + 1] = (uint16_t)(sl == 2 ? 2 : 1);
        t->weights[2 * v] = sl == 0 ? 1.0f : (sl == 1 ? 0.5f : 0.75f);
        t->weights[2 * v + 1] = 1.0f - t->weights[2 * v];
        for (int i = 0; i < 3; i++)
            t->cor[3 * v + i] = t->tet_positions[3 * v + i] * 0.5f + 0.125f * (float)i;
    }

    static const float skin_b[4][4] = {{0.25f, 0.25f, 0.25f, 0.25f}, {0.5f, 0.25f, 0.125f, 0.125f},
                                       {0.1f, 0.2f, 0.3f, 0.4f}, {0.7f, 0.1f, 0.1f, 0.1f}};
    static const uint32_t skin_tet[4] = {0, 5, 7, 11};
    static const uint32_t skin_tri[12] = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};
    for (int v = 0; v < 4; v++) {
        t->skin_tet[v] = skin_tet[v];
        memcpy(&t->skin_bary[4 * v], skin_b[v], sizeof skin_b[v]);
        embed(t, skin_tet[v], skin_b[v], &t->skin_positions[3 * v]);
    }
    memcpy(t->skin_triangles, skin_tri, sizeof skin_tri);
    static const float bone_b[3][4] = {{0.4f, 0.3f, 0.2f, 0.1f}, {0.2f, 0.2f, 0.3f, 0.3f},
                                       {0.6f, 0.2f, 0.1f, 0.1f}};
    for (int v = 0; v < 3; v++) {
        t->bone_tet[v] = (uint32_t)(v + 1);
        memcpy(&t->bone_bary[4 * v], bone_b[v], sizeof bone_b[v]);
        embed(t, t->bone_tet[v], bone_b[v], &t->bone_positions[3 * v]);
        t->bone_triangles[v] = (uint32_t)v;
    }
    t->tissues[0] = (pose_tissue_desc){"skin", POSE_TISSUE_SKIN, -1, 4, t->skin_positions, 4,
                                       t->skin_triangles, t->skin_tet, t->skin_bary};
    t->tissues[1] = (pose_tissue_desc){"root_bone", POSE_TISSUE_BONE, 0, 3, t->bone_positions, 1,
                                       t->bone_triangles, t->bone_tet, t->bone_bary};
    t->desc = (pose_rig_desc){
        .joint_count = 3, .joints = t->joints,
        .tet_vertex_count = 12, .tet_positions = t->tet_positions,
        .tet_count = 12, .tets = t->tets, .tet_labels = t->labels,
        .influences = 2, .weight_joints = t->weight_joints, .weights = t->weights,
        .cor = with_cor ? t->cor : NULL,
        .tissue_count = 2, .tissues = t->tissues,
        .metadata = with_metadata ? "tiny test rig\nwritten by tests/rigfile" : NULL,
    };
}

void tiny_rig_add_clinical(tiny_rig *t)
{
    memset(t->clinical, 0, sizeof t->clinical);
    pose_joint_clinical *e = &t->clinical[1];
    e->flags = POSE_CLINICAL_DEFINED;
    e->neutral[0] = 0.25881905f; /* 30 degrees about x */
    e->neutral[3] = 0.96592583f;
    static const float elbow_axes[3][3] = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
    memcpy(e->axes, elbow_axes, sizeof elbow_axes);
    e->limit_flags = POSE_LIMIT_X | POSE_LIMIT_Z;
    e->limit_min_deg[0] = 0.0f;
    e->limit_max_deg[0] = 150.0f;
    e->limit_min_deg[2] = -80.0f;
    e->limit_max_deg[2] = 80.0f;
    pose_joint_clinical *w = &t->clinical[2];
    w->flags = POSE_CLINICAL_DEFINED;
    w->neutral[3] = 1.0f;
    static const float wrist_axes[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}};
    memcpy(w->axes, wrist_axes, sizeof wrist_axes);
    w->names[0] = "flexion";
    w->names[1] = "radial_deviation";
    w->names[2] = "pronation";
    w->limit_flags = POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z;
    static const float lo[3] = {-70, -20, -80}, hi[3] = {80, 30, 85};
    memcpy(w->limit_min_deg, lo, sizeof lo);
    memcpy(w->limit_max_deg, hi, sizeof hi);
    /* Ignored: a joint without clinical data is written as zeros. */
    t->clinical[0].limit_max_deg[0] = 99.0f;
    t->desc.clinical = t->clinical;
}

void tiny_rig_add_couplings(tiny_rig *t)
{
    t->fem = (pose_fem_material){1e4f, 0.45f, 1000.0f};
    t->couplings[0] = (pose_fem_coupling){.node = 9, .joint = 1, .stiffness = 100.0f};
    t->couplings[1] = (pose_fem_coupling){.node = 10, .joint = 2, .stiffness = 2.5f};
    for (int k = 0; k < 2; k++)
        memcpy(t->couplings[k].anchor, t->tet_positions + 3 * t->couplings[k].node,
               sizeof t->couplings[k].anchor);
    t->couplings[1].anchor[2] += 0.25f; /* an anchor off the node's rest position */
    t->desc.fem = &t->fem;
    t->desc.fem_coupling_count = 2;
    t->desc.fem_couplings = t->couplings;
}

void tiny_rig_add_soft_couplings(tiny_rig *t)
{
    t->fem = (pose_fem_material){1e4f, 0.45f, 1000.0f};
    t->soft_couplings[0] = (pose_fem_soft_coupling){
        .node = 8, .other = {11}, .weight = {1.0f}, .stiffness = 50.0f};
    t->soft_couplings[1] = (pose_fem_soft_coupling){
        .node = 9, .other = {10, 11, 8}, .weight = {0.25f, 0.25f, 0.5f}, .stiffness = 2.5f};
    t->desc.fem = &t->fem;
    t->desc.fem_soft_coupling_count = 2;
    t->desc.fem_soft_couplings = t->soft_couplings;
}
