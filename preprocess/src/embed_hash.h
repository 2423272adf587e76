/* SPDX-License-Identifier: Apache-2.0
 *
 * Mapping: embed tissue vertices in the tet mesh (design §2). Tets are
 * filed by their bounding boxes in a uniform spatial hash (Teschner et al.
 * 2003: cell = mean tet box size, hash (73856093 i ^ 19349663 j ^ 83492791 k)
 * mod a prime table size, stored as compressed buckets). A vertex takes the
 * candidate tet that contains it, with exact barycentric coordinates. A
 * vertex outside the mesh takes the nearest tet (ring search over hash
 * cells, exact point-tet distances) with extrapolated coordinates; how many
 * and how far is reported.
 *
 * Bone tissues ask for their own bone's tets (prefer_label = joint + 1):
 * then a bone vertex follows its bone exactly (rigidly), even where the
 * voxelized bone boundary does not coincide with the bone surface.
 */
#ifndef POSE_PP_EMBED_HASH_H
#define POSE_PP_EMBED_HASH_H

#include "pp_types.h"

#include <pose/pose.h>

typedef struct pp_tet_hash pp_tet_hash;

typedef struct pp_embed_report {
    size_t vertices;
    size_t outside;          /**< more than 1 µm outside every tet: nearest tet, extrapolated */
    double max_distance;     /**< metres, largest distance of an outside vertex */
    size_t label_fallback;   /**< prefer_label asked but no such tet near: any tet used */
    double seconds;
} pp_embed_report;

/** Build the hash; cell <= 0 picks the mean tet bounding-box edge. */
int pp_tet_hash_build(const pp_tetmesh *mesh, double cell, pp_tet_hash **out, char *err,
                      size_t err_size);
void pp_tet_hash_free(pp_tet_hash *h);
/** Buckets and filed entries (for reports). */
void pp_tet_hash_stats(const pp_tet_hash *h, size_t *buckets, size_t *entries, double *cell);

/**
 * Embed n points (xyz floats). prefer_label >= 0: use only tets with that
 * label when one lies within `label_reach` metres (<= 0: two hash cells),
 * else any tet. tet[i] and bary[4i..4i+3] receive the result; report
 * counts are accumulated into *rep (zero it first). threads <= 1 runs
 * inline.
 */
int pp_embed_points(const pp_tet_hash *h, const float *pts, size_t n, int prefer_label,
                    double label_reach, int threads, uint32_t *tet, float *bary,
                    pp_embed_report *rep);

/** Brute-force reference (every tet for every point) for tests. */
void pp_embed_points_naive(const pp_tetmesh *mesh, const float *pts, size_t n, uint32_t *tet,
                           float *bary);

#endif /* POSE_PP_EMBED_HASH_H */
