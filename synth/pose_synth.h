/* SPDX-License-Identifier: Apache-2.0 */
/*
 * pose_synth — synthetic rigs for tests and benchmarks.
 *
 * Builds complete rig descriptions (pose_rig_desc) without any input data:
 *  - pose_synth_bar: the test object of Sujar et al. 2018 — a bar of N bones
 *    in a line along +X inside a cylinder of soft tissue, one joint at the
 *    start of each bone (joint 0 is the root at x = 0), a closed skin surface
 *    and one closed surface per bone, all embedded in the tet mesh;
 *  - pose_synth_body: bars arranged like a body (spine, head, arms, legs) at
 *    any size, by default the paper's full-body scale (~800 k tet vertices,
 *    ~3.5 M tets, ~1.3 M tissue vertices);
 *  - pose_synth_medium: the body layout at ~50 k tets.
 *
 * Weights come from a smooth compact falloff of the distance to each bone
 * (not harmonic weights): >= 0, exactly 1 on a bone's own vertices, the K
 * largest kept and renormalized. Centres of rotation follow Le & Hodgins
 * (2016) over tets (design §2); see pose_synth_cor_mode. Vertices with a
 * single non-zero weight get their own rest position as centre (the CoR
 * method does not use it for them).
 *
 * Objects are owned by the caller and freed with pose_synth_free; the
 * description and every array it points to live until then. Functions print
 * nothing and are safe to call from several threads on different objects.
 */
#ifndef POSE_SYNTH_H
#define POSE_SYNTH_H

#include <stddef.h>

#include "pose/pose.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How centres of rotation are computed. */
typedef enum pose_synth_cor_mode {
    /** Default: exact for bar and medium, clustered for body. */
    POSE_SYNTH_COR_AUTO = 0,
    /** The O(vertices x tets) sum of design §2, skipping only terms that are 0. */
    POSE_SYNTH_COR_EXACT = 1,
    /** Approximation: tets grouped by their mean weights quantized to 1/64;
     *  each group contributes its volume-weighted centroid once. */
    POSE_SYNTH_COR_CLUSTERED = 2,
    /** No CoR data (the rig then has no POSE_COR method). */
    POSE_SYNTH_COR_NONE = 3,
} pose_synth_cor_mode;

/**
 * Progress report: `stage` is "mesh" or "cor", `fraction` in [0, 1]. Called
 * from the generating thread, a few hundred times at most.
 */
typedef void (*pose_synth_progress_fn)(const char *stage, double fraction, void *user);

/** Options for pose_synth_bar; a zeroed struct gives the defaults. */
typedef struct pose_synth_bar_options {
    int bones;                /**< number of bones, 1..64; 0 = 4 */
    float bone_length;        /**< one bone plus the soft gap after it; 0 = 1.0
                                   (the gap is a quarter of it) */
    float radius;             /**< soft tissue radius; 0 = 0.25 (bones: half of it) */
    int layers_per_bone;      /**< tet layers along X per bone, multiple of 8; 0 = 16 */
    int rings;                /**< tet rings across the radius, even; 0 = 4 */
    int sectors;              /**< tet sectors around the axis, >= 6; 0 = 16 */
    int skin_sectors;         /**< skin vertices around; 0 = 24 */
    int skin_layers_per_bone; /**< skin vertex rings per bone; 0 = 12 */
    unsigned influences;      /**< K weights per vertex, 1..8; 0 = 4 */
    float sigma;              /**< CoR similarity width, (0, 0.1]; 0 = 0.1 */
    pose_synth_cor_mode cor;  /**< AUTO = exact */
    pose_synth_progress_fn progress; /**< optional */
    void *progress_user;
} pose_synth_bar_options;

/** Options for pose_synth_body; a zeroed struct gives the defaults. */
typedef struct pose_synth_body_options {
    size_t target_tets;       /**< approximate tet count; 0 = 3,500,000 */
    size_t target_tissue_vertices; /**< approximate; 0 = target_tets * 0.37 */
    unsigned influences;      /**< 0 = 4 */
    float sigma;              /**< 0 = 0.1 */
    pose_synth_cor_mode cor;  /**< AUTO = clustered */
    pose_synth_progress_fn progress; /**< optional */
    void *progress_user;
} pose_synth_body_options;

typedef struct pose_synth_rig pose_synth_rig;

/** Make the bar test object. Returns POSE_ERR_INVALID_ARGUMENT for bad options. */
pose_status pose_synth_bar(const pose_synth_bar_options *options, pose_synth_rig **out);
/** Make a body-shaped rig (NULL options = full body scale, clustered CoR). */
pose_status pose_synth_body(const pose_synth_body_options *options, pose_synth_rig **out);
/** The body layout at ~50 k tets with exact CoR. */
pose_status pose_synth_medium(pose_synth_rig **out);

/** The rig description; valid until pose_synth_free. */
const pose_rig_desc *pose_synth_desc(const pose_synth_rig *rig);
/** How this rig's CoR centres were computed (never AUTO). */
pose_synth_cor_mode pose_synth_cor(const pose_synth_rig *rig);
/** Free; NULL is a no-op. */
void pose_synth_free(pose_synth_rig *rig);

/**
 * Fill cor[3 * vertex_count] for an existing description (its cor field is
 * ignored) by the formula of design §2 with the given mode (EXACT or
 * CLUSTERED). Exposed for tests and for tools that bring their own weights.
 */
pose_status pose_synth_compute_cor(const pose_rig_desc *desc, float sigma,
                                   pose_synth_cor_mode mode, float *cor);

#ifdef __cplusplus
}
#endif
#endif /* POSE_SYNTH_H */
