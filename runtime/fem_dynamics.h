/* SPDX-License-Identifier: Apache-2.0 */
/* Dynamics of the co-rotational FEM (design §2, Otaduy et al. §5.1-5.2):
 * backward Euler with linearized forces. Each step solves
 *
 *   A v' = b,  A = (1 + dt alpha) M + (dt beta + dt^2) (K + K_s),
 *              b = M v + dt (f(x) + M g + f_s + beta K_s v_bone)
 *
 * for the new velocities v' (x' = x + dt v'), with f and K the forces and
 * warped stiffness R K0 R^T of plain co-rotated linear elasticity
 * (rotations taken at x; fem_dyn_tets.h says why not the det F volume
 * term of the quasi-static solver; fem_dyn_twist.h adds R's derivative to K
 * for the tets where it is large) plus the skin's
 * volume term, Rayleigh damping
 * D = alpha M + beta (K + K_s), and K_s the zero-length springs that couple
 * every bone node (a vertex of a bone tet that is also a soft tet's) to its
 * bone: a kinematic rigid body at the skinned position. Vertices of bone
 * tets only are moved with their bone.
 *
 * Bones being kinematic, coupling islands are the connected parts of the
 * soft tissue (tets sharing vertices; the skin's volume term joins every
 * vertex it touches, a soft-soft coupling its ends). Each island runs its
 * own block-Jacobi preconditioned CG (its own step lengths and stopping
 * test), warm-started from the last
 * velocities, in Chronopoulos and Gear's form (one product, one vertex
 * pass and one reduction per iteration). Reductions are summed per segment
 * (a run of one island's vertices inside a POSE__FEM_CHUNK) and then
 * segment after segment, the tets' u^T K u per group of POSE__FEM_GROUP
 * blocks and then group after group, so the result is the same for any
 * thread count. Steps allocate nothing. */
#ifndef POSE_FEM_DYNAMICS_H
#define POSE_FEM_DYNAMICS_H

#include <stddef.h>
#include <stdint.h>

#include "fem_dyn_tets.h"
#include "fem_dyn_twist.h"
#include "fem_mesh.h"
#include "fem_solve.h"
#include "rt_pool.h"

/** Island of a vertex the solver does not move (bone interior, massless). */
#define POSE__FEM_KINEMATIC UINT32_MAX

/** Resting contacts (the contact response's, sdk/src/contact_dyn.c)
 *  inside the solve: at a vertex that rests on bone, a force linear in
 *  its position, f(x') = g - S (x' - x) with S symmetric positive
 *  semi-definite (the sum of its contacts' k n n^T): the contacts'
 *  multipliers and springs toward their planes, as an augmented
 *  Lagrangian. A node held on bone so stays at rest in the solve instead
 *  of being pushed in by it and out after it. */
typedef struct pose__fem_dyn_contact {
    const uint8_t *on;   /**< per vertex: nonzero where it rests on bone */
    const float *stiff;  /**< per vertex (6: xx xy xz yy yz zz): S, N/m */
    const float *force;  /**< per vertex (3): g, the force at x (damping included), N */
} pose__fem_dyn_contact;

typedef struct pose__fem_dyn_params {
    float dt;             /**< seconds, > 0 */
    float alpha;          /**< Rayleigh mass damping, 1/s */
    float beta;           /**< Rayleigh stiffness damping, s */
    float coupling;       /**< bone springs: multiple of each node's own elastic stiffness */
    /** Couplings (pose.h pose_fem_coupling), or NULL: per vertex the
     *  stiffness of a zero-length spring tying a simulated vertex to its
     *  entry in `bones` (the coupling's target), damped as the bone nodes'. */
    const float *spring;
    /** Soft-soft couplings (fem_links.h), or NULL; every end a vertex the
     *  solver moves, the islands linked with them (pose__fem_dyn_link). */
    const pose__fem_links *links;
    float tolerance;      /**< per island: stop at r^T P r <= tolerance^2 max(b^T P b, mm) */
    int cg_iterations;    /**< most CG iterations per island and step */
    float gravity[3];     /**< rig units / s^2 */
    /** Called after the CG solve, before x' = x + dt v' (the contact
     *  response: it may change the simulated vertices' v); NULL: none. */
    void (*constrain)(void *ctx);
    void *constrain_ctx;
    const pose__fem_dyn_contact *contact; /**< resting contacts' springs, or NULL */
    const float *joint_q; /**< the joints' rotations at the step's end, for skeletal tets
                               (pose__fem_dyn_rotate); NULL when there are none */
} pose__fem_dyn_params;

typedef struct pose__fem_dyn_stats {
    int cg_iterations;          /**< most over the islands */
    double residual;            /**< largest sqrt(r^T P r / max(b^T P b, mm)) over the islands */
    double kinetic_energy;      /**< 1/2 v'^T M v' after the step */
    double seconds_assembly;    /**< rotations, forces, right-hand side, preconditioner */
    double seconds_cg;          /**< CG iterations */
    double seconds_constrain;   /**< params.constrain */
} pose__fem_dyn_stats;

/** Sums a vertex pass forms per segment. */
#define POSE__FEM_SUMS 5
/** Blocks of tets whose u^T K u a product pass sums together (one part
 *  takes whole groups, so the sums do not depend on the thread count). */
#define POSE__FEM_GROUP 16u

/** One coupling island's CG scalars (u = P r: the preconditioned residual). */
typedef struct pose__fem_island {
    double sum[POSE__FEM_SUMS]; /**< the last vertex pass's sums over the island */
    double rz, rr;          /**< r . u and r . r */
    double bb;              /**< b^T P b (P: the block-Jacobi preconditioner) */
    double mm;              /**< 3 sum(m) (1e-2)^2: twice its kinetic energy at 1e-2 units/s */
    double stop;            /**< tolerance^2 max(b^T P b, mm) */
    double dm;              /**< u^T D u, D = (1 + dt alpha) M + kscale K_s: A's diagonal part */
    double gu;              /**< the volume gradient . u (. v before the residual pass) */
    double tet;             /**< the tets' u^T K u, summed by the last product pass */
    double link;            /**< the soft-soft couplings' u^T K_l u, of the same product */
    double alpha;           /**< the last step length */
    int iterations;
    int active;             /**< still iterating */
} pose__fem_island;

/** A state's simulation: topology (islands, segments) and the dynamic
 *  state, in one block of pose__fem_dyn_size bytes. */
typedef struct pose__fem_dyn {
    size_t island_count;
    size_t segment_count;
    uint32_t *island;       /**< per vertex: island, or POSE__FEM_KINEMATIC */
    uint32_t *tet_island;   /**< per simulated tet, padded to whole blocks (island 0) */
    uint32_t *seg_offset;   /**< chunk_count + 1: segments of each chunk */
    uint32_t *seg_first;    /**< segment_count: first vertex; a segment ends at the
                                 next one's first or at its chunk's end */
    uint32_t *seg_island;   /**< segment_count */
    float *x, *v;           /**< 3 per vertex: simulated positions and velocities */
    float *bone_prev;       /**< 3 per vertex: skinned positions of the last step */
    float *stiff;           /**< per vertex: elastic stiffness (trace / 3 of its rest block) */
    pose__fem_dyn_tets *tets;  /**< the simulated tets in blocks of 8 (fem_dyn_tets.h) */
    pose__fem_dyn_rot *rot;    /**< per block: rotations */
    float *f;               /**< per block, 12 rows: elastic forces, then the CG's products */
    float *kv;              /**< per block, 12 rows: K v of the rotate pass */
    float *blk;             /**< per block, 24 rows: the corners' stiffness blocks */
    uint32_t *flag;         /**< per tet (whole blocks): its twists are added (fem_dyn_twist.h) */
    uint32_t *twist_count;  /**< per group: how many of its tets are in twist */
    pose__fem_twist *twist; /**< per group, POSE__FEM_GROUP * POSE__FEM_LANES: its flagged tets */
    uint32_t *corner;       /**< per mesh corner entry (mesh->corners' order): its offset
                                 in a 12-row output (pose__fem_dyn_corner) */
    float *energy;          /**< per tet (whole blocks): u^T K u of the last product */
    double *group_sum;      /**< per group of POSE__FEM_GROUP blocks: the sum of its energies */
    uint32_t *group_island; /**< per group: its tets' island, or POSE__FEM_KINEMATIC if mixed */
    double *seg_sum;        /**< POSE__FEM_SUMS per segment */
    pose__fem_island *isl;  /**< island_count */
    float *alpha, *beta;    /**< per island (at least one): step length, direction update */
} pose__fem_dyn;

/** Groups of POSE__FEM_GROUP tet blocks. */
static inline size_t pose__fem_dyn_groups(const pose__fem_mesh *m)
{
    return (pose__fem_dyn_blocks(m) + POSE__FEM_GROUP - 1) / POSE__FEM_GROUP;
}

/**
 * Coupling islands of the mesh into `island` (per vertex, numbered in
 * vertex order; POSE__FEM_KINEMATIC for vertices without mass or soft tet)
 * and the counts pose__fem_dyn_size needs. Walks the mesh once.
 */
void pose__fem_dyn_islands(const pose__fem_mesh *mesh, uint32_t *island, size_t *island_count,
                           size_t *segment_count);
/**
 * The islands again with the soft-soft couplings `links` (NULL: none)
 * joining what they tie (Otaduy §5.2), rewritten in place: fewer islands
 * and segments than the block was laid out for from pose__fem_dyn_islands.
 * `scratch`: a vertex count of uint32_t. Velocities and positions stay.
 */
void pose__fem_dyn_link(const pose__fem_mesh *mesh, const pose__fem_links *links,
                        uint32_t *scratch, pose__fem_dyn *dyn);
/** Bytes of pose__fem_dyn_init's block. */
size_t pose__fem_dyn_size(const pose__fem_mesh *mesh, size_t island_count, size_t segment_count);
/** Lay the block out from pose__fem_dyn_islands' result; velocities zero,
 *  x and bone_prev at rest (pose__fem_dyn_reset before stepping). */
void pose__fem_dyn_init(const pose__fem_mesh *mesh, const uint32_t *island, size_t island_count,
                        size_t segment_count, void *memory, pose__fem_dyn *out);
/** Restart at rest at the positions `bones` (3 per vertex, e.g. skinned). */
void pose__fem_dyn_reset(const pose__fem_mesh *mesh, pose__fem_dyn *dyn, const float *bones);
/**
 * One step toward the skinned positions `bones` (where every bone is at the
 * end of the step). Updates dyn->x and dyn->v; pool may be NULL.
 */
void pose__fem_dyn_step(const pose__fem_mesh *mesh, pose__fem_work *work, pose__fem_dyn *dyn,
                        pose__pool *pool, const pose__fem_dyn_params *params, const float *bones,
                        pose__fem_dyn_stats *stats);

/** Bytes a step streams with `cg_iterations` iterations (benchmarks): every
 *  array the passes read or write counted once per pass, the vertex
 *  gathers of the tet passes included (an upper bound: neighbours share
 *  vertices in cache). */
double pose__fem_dyn_bytes(const pose__fem_mesh *mesh, double cg_iterations);

#endif /* POSE_FEM_DYNAMICS_H */
