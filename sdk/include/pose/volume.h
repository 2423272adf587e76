/* SPDX-License-Identifier: Apache-2.0
 *
 * pose/volume.h: posing volumetric images (a CT or MRI and its labels)
 * with a rig's displacement field (design §2 "Volumes"; Sujar et al. §5).
 *
 * The rest image lives on a grid of voxels whose centres map to the rig's
 * model space by an affine (index -> model, the rig's units). For every
 * posed tet, the voxels of the output grid whose centres lie inside it are
 * mapped back to the rest image through the tet's barycentric (inverse)
 * map: intensities are sampled trilinearly, labels take the nearest voxel.
 * Output voxels inside no posed tet get the background values.
 *
 * When the output grid is the rest grid (the default), the sampler keeps
 * which tets hold each voxel at rest (2 bytes a voxel): the voxels of tets
 * a pose leaves where they rest (most of a patient when a few joints
 * move) are copied from the rest image, not resampled.
 *
 * Threads: a sampler owns a worker pool; pose_volume_sample splits the
 * output grid into slabs of z, one per thread. A voxel inside two posed
 * tets (where the deformation folds, or a centre on a shared face) takes
 * a tet that moved over one that lies where it rests, else the later tet
 * in index order, whatever the slab, so the output is identical for any
 * thread count. pose_volume_sample allocates nothing: everything is
 * allocated by pose_volume_sampler_create. libc, libm and pthreads only,
 * as libpose.
 */
#ifndef POSE_VOLUME_H
#define POSE_VOLUME_H

#include "pose.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A voxel grid: nx * ny * nz voxels, x fastest, and the affine from a
 *  voxel's index (i, j, k) (its centre) to model space:
 *  p = affine[.][0..2] * (i, j, k) + affine[.][3]. */
typedef struct pose_volume_grid {
    uint32_t nx, ny, nz;
    float affine[3][4];
} pose_volume_grid;

/** A rest image: either array may be NULL (not sampled); both caller-owned
 *  and unchanged while a sampler made from them is alive. */
typedef struct pose_volume_desc {
    pose_volume_grid grid;
    const float *intensity;      /**< nx*ny*nz values (e.g. HU), or NULL */
    const uint16_t *labels;      /**< nx*ny*nz label ids, or NULL */
    float intensity_background;  /**< output outside the posed body (e.g. -1000 HU) */
    uint16_t label_background;   /**< output label outside the posed body (usually 0) */
} pose_volume_desc;

typedef struct pose_volume_sampler pose_volume_sampler;

/**
 * A sampler of `rest` posed by states of `rig`, writing on `out_grid`
 * (NULL: the rest grid). threads: workers of its pool (0 = cores, at most
 * 256). allocator NULL = malloc. POSE_ERR_INVALID_ARGUMENT for an empty or
 * over-large grid (more than 2^31 voxels per grid), a singular or
 * non-finite affine, or no array to sample; POSE_ERR_THREAD when a worker
 * could not be started. @since 0.2
 */
POSE_API pose_status pose_volume_sampler_create(const pose_rig *rig, const pose_volume_desc *rest,
                                                const pose_volume_grid *out_grid, int threads,
                                                const pose_allocator *allocator,
                                                pose_volume_sampler **out);

/** Free a sampler and stop its workers; NULL is a no-op. @since 0.2 */
POSE_API void pose_volume_sampler_free(pose_volume_sampler *sampler);

/** The output grid of a sampler. @since 0.2 */
POSE_API const pose_volume_grid *pose_volume_sampler_grid(const pose_volume_sampler *sampler);

/**
 * Resample the rest image as `state` is posed (after pose_apply; the state
 * must come from the sampler's rig and is only read). out_intensity and
 * out_labels hold the output grid's voxel count each; either may be NULL
 * (not written), and each needs the matching rest array. Allocates
 * nothing. @since 0.2
 */
POSE_API pose_status pose_volume_sample(pose_volume_sampler *sampler, const pose_state *state,
                                        float *out_intensity, uint16_t *out_labels);

/** Bytes one pose_volume_sample call moves (outputs written, tet mesh and
 *  rest samples read), for bandwidth figures in benchmarks. @since 0.2 */
POSE_API size_t pose_volume_sample_bytes(const pose_volume_sampler *sampler, int intensity,
                                         int labels);

/* ----------------------------------------------- rest images in the rig */

/** A rest image stored in a rig (pose_rig_desc.volumes; the optional
 *  `volumes` section, docs/rig-format.md): a name, its grid (index ->
 *  model) and either array or both. In a loaded rig the arrays point into
 *  the rig's storage. */
typedef struct pose_rig_volume {
    const char *name;          /**< 1..63 bytes, unique among the rig's volumes */
    pose_volume_grid grid;     /**< at most 2^31 voxels */
    const float *intensity;    /**< nx*ny*nz finite values, or NULL */
    const uint16_t *labels;    /**< nx*ny*nz label ids, or NULL */
} pose_rig_volume;

/** Number of rest images the rig holds (0 for rigs without a volumes section). @since 0.2 */
POSE_API size_t pose_rig_volume_count(const pose_rig *rig);

/** Rest image `index` of the rig (pointers into the rig, valid while it lives);
 *  POSE_ERR_INVALID_ARGUMENT for an index out of range. @since 0.2 */
POSE_API pose_status pose_rig_get_volume(const pose_rig *rig, size_t index, pose_rig_volume *out);

#ifdef __cplusplus
}
#endif

#endif /* POSE_VOLUME_H */
