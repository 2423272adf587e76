/* SPDX-License-Identifier: Apache-2.0
 *
 * Data passed between pose-bake's stages. Each stage owns one file (or a
 * few) and talks to the others through these plain structs only.
 */
#ifndef POSE_PP_TYPES_H
#define POSE_PP_TYPES_H

#include <stddef.h>
#include <stdint.h>

/** A triangle mesh as loaded from disk (Assimp), welded, in metres. */
typedef struct pp_mesh {
    char name[64];
    size_t vertex_count;
    float *positions;      /**< 3 * vertex_count */
    size_t triangle_count;
    uint32_t *triangles;   /**< 3 * triangle_count */
} pp_mesh;

/** A labelled voxel image of the body: 0 outside, 1 soft tissue, 2 + j bone of joint j. */
typedef struct pp_voxels {
    int nx, ny, nz;
    float origin[3];       /**< centre of voxel (0,0,0) */
    float spacing;         /**< edge length, metres */
    uint16_t *labels;      /**< nx*ny*nz, x fastest */
} pp_voxels;

/** A labelled tet mesh: label 0 soft tissue, j + 1 bone of joint j (as in the rig). */
typedef struct pp_tetmesh {
    size_t vertex_count;
    float *positions;      /**< 3 * vertex_count */
    size_t tet_count;
    uint32_t *tets;        /**< 4 * tet_count, positively oriented */
    uint16_t *labels;      /**< tet_count */
} pp_tetmesh;

/** Quality figures of a tet mesh (see tet_quality.h). */
typedef struct pp_tet_quality {
    double min_dihedral_deg, max_dihedral_deg;
    double max_radius_edge;    /**< circumradius / shortest edge; 0.612 for a regular tet */
    double min_volume;         /**< m^3, signed: negative when a tet is inverted */
    double total_volume;       /**< m^3, sum of signed volumes */
    size_t inverted_count;     /**< tets with volume <= 0 */
    size_t vertex_count, tet_count;
    size_t labels_lost;        /**< bone labels of the voxel image no tet carries (a bone
                                    smaller than a cell, sharing it with another bone) */
    double seconds;            /**< wall time of the stage that built the mesh */
} pp_tet_quality;

/** Seconds on CLOCK_MONOTONIC, for stage timings. */
double pp_now_s(void);

/** Write a printf-style message into err[n] (when err is not NULL) and return status. */
int pp_fail(char *err, size_t n, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

void pp_mesh_free(pp_mesh *m);
void pp_voxels_free(pp_voxels *v);
void pp_tetmesh_free(pp_tetmesh *t);

#endif /* POSE_PP_TYPES_H */
