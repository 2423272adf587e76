/* SPDX-License-Identifier: Apache-2.0 */
/* The in-memory rig. Every array is read-only and lives either in one block
 * the rig owns (pose_rig_create, pose_rig_load_ex with POSE_LOAD_NO_MMAP,
 * pose_rig_load_memory without POSE_LOAD_BORROW), in a read-only mapping of
 * the rig file (pose_rig_load), or in a caller's buffer (POSE_LOAD_BORROW).
 * Arrays that come from the file point straight into it; only data derived at
 * load time (rest_local, the tissue table) is allocated separately. */
#ifndef POSE_RIG_INTERNAL_H
#define POSE_RIG_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "pose/pose.h"

/** Names are stored in fixed 64-byte slots, NUL-terminated (1..63 bytes). */
#define POSE__NAME_SIZE 64
/** Most weights a tet vertex may carry. */
#define POSE__MAX_INFLUENCES 8
/** Joints are indexed by uint16 in weights and by label - 1 in tet labels. */
#define POSE__MAX_JOINTS 65534u

/** A joint's limits, as stored in the file (32 bytes, little-endian). */
typedef struct pose__joint_limit {
    uint32_t flags;       /* POSE_LIMIT_* */
    uint32_t order;       /* pose_euler_order */
    float min_deg[3];
    float max_deg[3];
} pose__joint_limit;

/** Clinical angle names are stored in fixed 32-byte slots (1..31 bytes, NUL). */
#define POSE__CLINICAL_NAME_SIZE 32

/** A joint's neutral posture, clinical axes and range of motion, as stored in
 *  the optional `clinical` section (192 bytes, little-endian; see
 *  docs/rig-format.md). A record with flags 0 is all zero. */
typedef struct pose__clinical_record {
    uint32_t flags;          /* POSE_CLINICAL_* */
    uint32_t limit_flags;    /* POSE_LIMIT_X/_Y/_Z: deg[0]/[1]/[2] limited */
    float neutral[4];        /* local rotation of the neutral posture */
    float axes[3][3];        /* flexion, abduction, rotation axes in the rest frame */
    float limit_min_deg[3];
    float limit_max_deg[3];
    uint8_t reserved[12];    /* zero */
    char names[3][POSE__CLINICAL_NAME_SIZE];
} pose__clinical_record;
_Static_assert(sizeof(pose__clinical_record) == 192, "clinical record is 192 bytes on disk");

/** The soft tissue's material as stored in the optional `fem` section (64
 *  bytes, little-endian; docs/rig-format.md). */
typedef struct pose__fem_record {
    float young;          /* Pa, finite, > 0 */
    float poisson;        /* [0, 0.5) */
    float density;        /* kg per cubic rig unit, finite, >= 0 */
    uint32_t flags;       /* 0 */
    uint8_t reserved[48]; /* zero */
} pose__fem_record;
_Static_assert(sizeof(pose__fem_record) == 64, "fem record is 64 bytes on disk");

/** One coupling as stored in the optional `couplings` section (32 bytes,
 *  little-endian; docs/rig-format.md). */
typedef struct pose__coupling_record {
    uint32_t node;        /* < tet vertices, strictly increasing */
    uint32_t joint;       /* < joints */
    float stiffness;      /* finite, > 0 */
    uint32_t flags;       /* 0 */
    float anchor[3];      /* finite */
    uint32_t reserved;    /* 0 */
} pose__coupling_record;
_Static_assert(sizeof(pose__coupling_record) == 32, "coupling record is 32 bytes on disk");

/** One soft-soft coupling as stored in the optional `soft_couplings`
 *  section (40 bytes, little-endian; docs/rig-format.md): the layout of
 *  pose.h's pose_fem_soft_coupling of 0.2. */
typedef struct pose__soft_coupling_record {
    uint32_t node;        /* < tet vertices */
    uint32_t other[4];    /* < tet vertices where weighted, distinct, none `node` */
    float weight[4];      /* finite, summing to 1 */
    float stiffness;      /* finite, > 0 */
} pose__soft_coupling_record;
_Static_assert(sizeof(pose__soft_coupling_record) == 40, "soft coupling record is 40 bytes on disk");

/** Why a soft coupling record is malformed for a mesh of `tet_vertices`
 *  (into why, at most `cap` bytes), with the byte offset of the field at
 *  fault in *at; 0 when it is well formed (rig_soft_couplings.c). */
int pose__soft_coupling_fault(const pose__soft_coupling_record *r, size_t tet_vertices, char *why,
                              size_t cap, size_t *at);

/** One tissue surface; arrays point into the rig's storage. */
typedef struct pose__tissue {
    const char *name;         /* NUL-terminated, < POSE__NAME_SIZE bytes */
    pose_tissue_kind kind;
    int32_t joint;            /* -1 unless a bone of that joint */
    size_t vertex_count;
    size_t triangle_count;
    const float *positions;   /* 3 * vertex_count rest positions */
    const uint32_t *triangles;/* 3 * triangle_count vertex indices */
    const uint32_t *tet;      /* vertex_count embedding tet indices */
    const float *bary;        /* 4 * vertex_count barycentric coordinates */
} pose__tissue;

/** Where the rig's bytes came from, so pose_rig_free releases the right thing. */
typedef enum pose__rig_storage {
    POSE__STORAGE_OWNED = 0,  /* `block` allocated with `allocator` */
    POSE__STORAGE_MAPPED = 1, /* `block` is an mmap of `block_size` bytes */
    POSE__STORAGE_BORROWED = 2/* `block` belongs to the caller */
} pose__rig_storage;

struct pose__rig_runtime; /* owned by the runtime (rig_prepare.c) */

struct pose_rig {
    /* ---- skeleton: structure of arrays, parents before children */
    size_t joint_count;
    const char *joint_names;               /* joint_count * POSE__NAME_SIZE bytes */
    const int32_t *joint_parents;          /* -1 for roots, else < own index */
    const pose_transform *joint_rest_model;/* joint frame at rest, model space */
    const pose_transform *joint_rest_local;/* relative to parent (= rest_model for roots) */
    const pose__joint_limit *joint_limits;
    const pose__clinical_record *clinical; /* joint_count records, or NULL (no section) */
    const pose__fem_record *fem;           /* soft tissue material, or NULL (no POSE_FEM) */
    const pose__coupling_record *couplings;/* coupling_count records, or NULL (no section) */
    size_t coupling_count;
    const pose__soft_coupling_record *soft_couplings; /* soft_coupling_count, or NULL */
    size_t soft_coupling_count;
    const uint8_t *volumes;                /* the volumes section (checked), or NULL */
    uint32_t volume_count;

    /* ---- tet mesh */
    size_t tet_vertex_count;
    const float *tet_positions;            /* 3 * tet_vertex_count */
    size_t tet_count;
    const uint32_t *tets;                  /* 4 * tet_count */
    const uint16_t *tet_labels;            /* 0 soft tissue, j + 1 bone of joint j */

    /* ---- skinning weights (K per tet vertex, >= 0, summing to 1) */
    unsigned influences;                   /* K, 1..POSE__MAX_INFLUENCES */
    const uint16_t *weight_joints;         /* K * tet_vertex_count */
    const float *weights;                  /* K * tet_vertex_count */
    const float *cor;                      /* 3 * tet_vertex_count, or NULL */

    /* ---- tissues */
    size_t tissue_count;
    const pose__tissue *tissues;           /* allocated table, arrays point into storage */

    const char *metadata;                  /* NUL-terminated, "" when none */

    /* ---- ownership */
    pose_allocator allocator;              /* always filled (defaults resolved) */
    pose__rig_storage storage;
    void *block;                           /* file bytes / serialized description */
    size_t block_size;
    void *derived;                         /* one allocation: rest_local + tissue table */

    /* ---- runtime-derived data (compact weights, ...); opaque here */
    struct pose__rig_runtime *rt;
};

/** Name of joint `j` (NUL-terminated). */
static inline const char *pose__joint_name(const pose_rig *rig, size_t j)
{
    return rig->joint_names + j * POSE__NAME_SIZE;
}

/** Joint j's clinical record when it has clinical data, else NULL. */
static inline const pose__clinical_record *pose__joint_clinical(const pose_rig *rig, size_t j)
{
    return rig->clinical && (rig->clinical[j].flags & POSE_CLINICAL_DEFINED) ? &rig->clinical[j] : NULL;
}

/**
 * Build runtime-derived data (rig->rt). Called once at the end of every
 * successful create/load, after full validation. On failure the rig is freed
 * by the caller; pose__set_error has been called.
 */
pose_status pose__rig_prepare(pose_rig *rig);
/** POSE_FEM's simulation mesh (rig->rt->fem), built by the first call
 *  (under the rig's lock: any thread); POSE_ERR_UNSUPPORTED without a fem
 *  section, POSE_ERR_OUT_OF_MEMORY naming `fn`. */
pose_status pose__rig_fem_mesh(const pose_rig *rig, const char *fn);
/** Release what pose__rig_prepare built; tolerates rig->rt == NULL. */
void pose__rig_release(pose_rig *rig);

#endif /* POSE_RIG_INTERNAL_H */
