/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-bake's pipeline: meshes + skeleton template -> rig file.
 *   load -> rig fit -> voxelize + label -> tetrahedralize -> weights ->
 *   mapping -> CoR -> write (temporary file, then rename: never half-written)
 * Every stage is timed and reported; a progress callback sees each stage
 * start and finish with the overall fraction done.
 */
#ifndef POSE_PP_BAKE_PIPELINE_H
#define POSE_PP_BAKE_PIPELINE_H

#include "clinical_fit.h"
#include "cor_fast.h"
#include "embed_hash.h"
#include "rig_fit.h"
#include "template_json.h"
#include "tetmesh.h"
#include "voxelize.h"
#include "weights_fem.h"

/** Stages, in order. */
typedef enum pp_bake_stage {
    PP_STAGE_LOAD = 0,
    PP_STAGE_RIG,
    PP_STAGE_VOXELIZE,
    PP_STAGE_TETRAHEDRALIZE,
    PP_STAGE_WEIGHTS,
    PP_STAGE_MAPPING,
    PP_STAGE_COR,
    PP_STAGE_WRITE,
    PP_STAGE_COUNT
} pp_bake_stage;

const char *pp_bake_stage_name(pp_bake_stage s);

/** Default voxel edge when neither resolution nor a vertex budget is given. */
#define PP_BAKE_DEFAULT_RESOLUTION_MM 6.0

/** Soft tissue of the fem section (POSE_FEM). Without gravity the
 *  quasi-static refinement does not depend on Young's modulus, only on
 *  Poisson's ratio: near 0.5 keeps volume, but slows CG (conditioning goes
 *  with lambda / mu = 2 nu / (1 - 2 nu)). Young's modulus and density are
 *  those of relaxed muscle and fat (~10 kPa, water's density). */
#define PP_BAKE_FEM_YOUNG 10e3
#define PP_BAKE_FEM_POISSON 0.48
#define PP_BAKE_FEM_DENSITY 1000.0

typedef struct pp_bake_options {
    const char *skin_path;
    const char *const *bone_paths; /**< bone mesh files; each mesh's name is its file stem */
    size_t bone_count;
    const char *const *organ_paths; /**< extra tissues (soft; embedded only) */
    size_t organ_count;
    const char *template_path;
    const char *output_path;
    const char *vtu_path;           /**< optional: tet mesh with labels and weights */
    double resolution_mm;           /**< voxel edge; 0: default (or from the budget) */
    size_t target_vertices;         /**< tet vertex budget; 0: one lattice cell per voxel */
    pp_tet_backend backend;
    unsigned influences;            /**< K; 0 = 4 */
    int threads;                    /**< 0 = 1 */
    int no_cor;                     /**< skip CoR (rig without the CoR method) */
    double cor_step;                /**< CoR weight-bin step (pp_cor_options.tolerance) */
    int no_fem;                     /**< write no fem section (rig without POSE_FEM) */
    double fem_poisson;             /**< soft tissue's Poisson ratio; 0: PP_BAKE_FEM_POISSON */
    /** Rest images stored in the rig's volumes section (pose-bake --labels), or 0 / NULL. */
    size_t volume_count;
    const struct pose_rig_volume *volumes;
    /** Called at each stage's start (fraction_done of the whole bake) and end. */
    void (*progress)(pp_bake_stage stage, int finished, double fraction_done, void *user);
    void *user;
} pp_bake_options;

/** Per-tissue mapping figures. */
typedef struct pp_bake_tissue {
    char name[PP_NAME_MAX];
    pose_tissue_kind kind;
    int joint;
    size_t vertices, outside;
    double max_distance;
    size_t label_fallback;
} pp_bake_tissue;

typedef struct pp_bake_report {
    double seconds[PP_STAGE_COUNT];
    double total_seconds;
    double peak_rss_mb;
    pp_template tmpl;              /**< the template used (names, rules) */
    pp_fit_joint *fits;            /**< tmpl.joint_count */
    pp_clinical_joint *clinical;   /**< tmpl.joint_count: neutral posture and clinical axes */
    pp_voxel_report voxels;
    float voxel_mm;
    pp_tet_quality quality;
    pp_weight_report weights;
    pp_embed_report mapping;       /**< totals */
    pp_bake_tissue *tissues;
    size_t tissue_count;
    pp_cor_report cor;
    size_t soft_bones;             /**< bone files not in the template (kept as soft tissue) */
    size_t coupled_nodes;          /**< simulation nodes the template's couplings tie to bones */
    size_t soft_coupled_nodes;     /**< springs its soft-soft couplings tie between parts */
    size_t rig_bytes;
} pp_bake_report;

/**
 * Run the whole bake. On failure returns a negative pose_status, removes
 * any partial output and writes a message naming the file, joint or stage
 * into err. The report is filled as far as the bake got; free it with
 * pp_bake_report_free in any case.
 */
int pp_bake(const pp_bake_options *opt, pp_bake_report *report, char *err, size_t err_size);
void pp_bake_report_free(pp_bake_report *r);

/**
 * The template's "couplings" resolved on the tet mesh (bake_couplings.c):
 * every soft node (in a soft tet and in no bone tet) within an entry's
 * reach_mm of its bone meshes' surface (bone_joint: each mesh's joint or
 * -1), anchored at its rest position; the nearest bone wins. *out sorted by
 * node (malloc'd; NULL when none). An entry whose bone meshes were not
 * given is an error naming it.
 */
int pp_bake_couplings(const pp_template *t, const pp_mesh *bones, const int *bone_joint,
                      size_t bone_count, const pp_tetmesh *tet, pose_fem_coupling **out,
                      size_t *count, char *err, size_t err_size);

/**
 * The template's soft-soft "couplings" resolved on the tet mesh
 * (bake_soft_couplings.c): per entry, every free soft node of the soft tets
 * that embed `tissue` (and of none that embed `to` or a bone) within
 * reach_mm of a soft tet that embeds `to`, tied to that tet's nearest point
 * (corners and barycentric weights); entry after entry, nodes ascending.
 * *out malloc'd (NULL when none). An entry naming a tissue the bake does
 * not have is an error naming it.
 */
int pp_bake_soft_couplings(const pp_template *t, const pose_tissue_desc *tissues,
                           size_t tissue_count, const pp_tetmesh *tet,
                           pose_fem_soft_coupling **out, size_t *count, char *err, size_t err_size);

/** The report as JSON text (cJSON; caller frees with free()), or NULL. */
char *pp_bake_report_json(const pp_bake_report *r, const pp_bake_options *opt);

/** Write the tet mesh, labels and per-joint weights as a VTK XML
 *  unstructured grid (.vtu, ASCII). */
int pp_write_vtu(const char *path, const pp_tetmesh *mesh, const pp_weights *w,
                 const pp_template *t, char *err, size_t err_size);

#endif /* POSE_PP_BAKE_PIPELINE_H */
