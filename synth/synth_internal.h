/* SPDX-License-Identifier: Apache-2.0 */
/* The rig builder shared by the bar and body generators. */
#ifndef POSE_SYNTH_INTERNAL_H
#define POSE_SYNTH_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "pose_synth.h"

#define PS_NAME_SIZE 64
#define POSE_SYNTH_MAX_K 8

/** One tissue being built; arrays owned by the builder. */
typedef struct ps_tissue {
    char name[PS_NAME_SIZE];
    pose_tissue_kind kind;
    int joint;
    size_t vertex_count, triangle_count;
    float *positions;
    uint32_t *triangles;
    uint32_t *tet;
    float *bary;
} ps_tissue;

struct pose_synth_rig {
    /* joints */
    pose_joint_desc *joints;
    char (*joint_names)[PS_NAME_SIZE];
    size_t joint_count, joint_cap;
    /* tet mesh and weights (influences per vertex) */
    float *tet_positions;
    uint16_t *weight_joints;
    float *weights;
    size_t vertex_count, vertex_cap;
    uint32_t *tets;
    uint16_t *labels;
    size_t tet_count, tet_cap;
    unsigned influences;
    float *cor;
    pose_synth_cor_mode cor_mode;
    /* tissues */
    ps_tissue *tissues;
    pose_tissue_desc *tissue_descs;
    size_t tissue_count, tissue_cap;
    char *metadata;
    pose_rig_desc desc;
    pose_synth_progress_fn progress;
    void *progress_user;
};

/** A bar of bones along the local +X axis, placed by origin + rotation. */
typedef struct ps_bar_spec {
    const char *prefix;      /* joint and tissue name prefix ("" for the bar) */
    float origin[3];         /* model-space position of local (0,0,0) */
    float frame[4];          /* unit quaternion taking local +X to the bar's direction */
    int bones;
    float period;            /* bone + gap along the axis (gap = period / 4) */
    float radius;            /* soft tissue radius; bones have half */
    int rings, sectors, layers_per_period;
    int skin_sectors, skin_layers_per_period;
    int bone_sectors, bone_layers;
    int parent;              /* parent joint of the first joint, -1 for a root */
    float limit_deg;         /* symmetric limit on every axis of non-root joints */
} ps_bar_spec;

pose_synth_rig *ps_rig_new(unsigned influences);
/** Grow capacities ahead of time (optional; avoids copying big arrays). */
bool ps_reserve(pose_synth_rig *r, size_t vertices, size_t tets);
/** Room for n joints / n tissues in total. */
bool ps_grow_joints(pose_synth_rig *r, size_t n);
bool ps_grow_tissues(pose_synth_rig *r, size_t n);
/** Append a bar: joints, tet mesh, labels, weights, skin and bone tissues. */
bool ps_add_bar(pose_synth_rig *r, const ps_bar_spec *s);
/** Compute CoR (mode != NONE), set metadata, fill r->desc. */
pose_status ps_finish(pose_synth_rig *r, pose_synth_cor_mode mode, float sigma,
                      const char *generator);

/** Report progress if a callback was given. */
void ps_progress(const pose_synth_rig *r, const char *stage, double fraction);
/** pose_synth_compute_cor with progress reports through r (may be NULL). */
pose_status ps_compute_cor(const pose_rig_desc *d, float sigma, pose_synth_cor_mode mode,
                           float *cor, const pose_synth_rig *r);

/* Quaternion helpers (x, y, z, w). */
void ps_quat_rotate(const float q[4], const float v[3], float out[3]);
void ps_quat_from_to(const float from[3], const float to[3], float q[4]);

#endif /* POSE_SYNTH_INTERNAL_H */
