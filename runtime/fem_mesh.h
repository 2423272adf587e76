/* SPDX-License-Identifier: Apache-2.0 */
/* The simulation mesh of the physically based layer (design §2): linear
 * co-rotational FEM on the rig's own tet mesh. Built once per rig from the
 * rest positions, the tets, their labels and the soft tissue's material;
 * read by every state's solver (fem_solve.h).
 *
 * Bone tets (label > 0) are rigid: their vertices are held at their skinned
 * positions and they carry no elastic energy, so only soft tets with at
 * least one free vertex are kept. Everything a solver iteration streams is
 * laid out for one pass: a 64-byte record per tet, a vertex -> tet-corner
 * table for gathering corner forces in a fixed order (so results do not
 * depend on how tets are split between threads), and per-vertex Jacobi
 * weights. */
#ifndef POSE_FEM_MESH_H
#define POSE_FEM_MESH_H

#include <stddef.h>
#include <stdint.h>

/** Vertices per chunk of the vertex passes: reductions are summed per chunk
 *  and then chunk after chunk, whatever the thread count. */
#define POSE__FEM_CHUNK 1024u

/** One simulated tet: 64 bytes. */
typedef struct pose__fem_tet {
    uint32_t v[4];  /**< vertex indices */
    float b[9];     /**< inverse of the rest edge matrix [x1-x0 x2-x0 x3-x0], row-major:
                         row i-1 is the gradient of vertex i's shape function */
    float vmu;      /**< rest volume * Lame mu */
    float vkappa;   /**< rest volume * bulk modulus (lambda + 2 mu / 3) */
    float pad;
} pose__fem_tet;
_Static_assert(sizeof(pose__fem_tet) == 64, "one cache line per tet");

/** Soft tissue's linear isotropic material. */
typedef struct pose__fem_material {
    float young;    /**< Young's modulus, Pa */
    float poisson;  /**< Poisson's ratio, [0, 0.5) */
    float density;  /**< kg per cubic rig unit */
} pose__fem_material;

/**
 * The closed skin, embedded in the tets (the rig's tissue arrays): the
 * volume it encloses is held as a whole, by a penalty whose Hessian is one
 * rank-one term (CG needs about one more iteration for it). Soft tissue is
 * near incompressible, so the body keeps its volume; per-tet volume terms
 * alone cannot (tets squeezed between two bones' held vertices lose volume
 * nothing free can give back, and a coarse bake's tets reach outside the
 * skin): the tissue they lose bulges out elsewhere, as in a body.
 */
typedef struct pose__fem_surface {
    size_t vertex_count;         /**< 0: no volume term */
    size_t triangle_count;
    const uint32_t *tets;        /**< the rig's tets, 4 per tet */
    const uint32_t *tet;         /**< per vertex: embedding tet */
    const float *bary;           /**< 4 per vertex */
    const uint32_t *triangles;   /**< 3 per triangle, outward */
    double rest_volume;
    double stiffness;            /**< penalty on (V - V0)^2 / 2 */
} pose__fem_surface;

typedef struct pose__fem_mesh {
    size_t vertex_count;
    size_t tet_count;          /**< simulated (soft) tets */
    size_t chunk_count;        /**< ceil(vertex_count / POSE__FEM_CHUNK) */
    size_t free_count;         /**< vertices not held by a bone */
    const pose__fem_tet *tets;
    const uint32_t *corner_offset; /**< vertex_count + 1 */
    const uint32_t *corners;   /**< tet * 4 + corner, per vertex in tet order */
    const float *inv_diag;     /**< Jacobi weight per vertex; 0 = held */
    const float *mass;         /**< lumped mass per vertex (soft tets' density) */
    double bulk;               /**< soft tissue's bulk modulus, Pa */
    pose__fem_surface surface;
} pose__fem_mesh;

/**
 * Bytes pose__fem_mesh_build needs for this mesh (0 when a count overflows
 * 32-bit corner indices). Counting pass only.
 */
size_t pose__fem_mesh_size(size_t vertex_count, size_t tet_count, const uint32_t *tets,
                           const uint16_t *labels);
/**
 * Build the mesh in `memory` (pose__fem_mesh_size bytes, 64-byte aligned).
 * Returns the number of soft tets that were degenerate (zero or negative
 * rest volume; left out).
 */
size_t pose__fem_mesh_build(size_t vertex_count, const float *positions, size_t tet_count,
                            const uint32_t *tets, const uint16_t *labels,
                            const pose__fem_material *soft, void *memory, pose__fem_mesh *out);

/** Volume enclosed by a surface embedded in tets, at tet positions x. */
double pose__fem_surface_volume(const pose__fem_surface *s, const float *x);
/** Hold the volume of the closed surface (rest volume from rest positions
 *  `x`); a surface enclosing no volume is ignored. */
void pose__fem_mesh_set_surface(pose__fem_mesh *m, const pose__fem_surface *s, const float *x);

#endif /* POSE_FEM_MESH_H */
