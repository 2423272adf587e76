/*
 * pose — put a virtual patient's whole anatomy into any pose in real time.
 * SPDX-License-Identifier: Apache-2.0
 *
 * This header is the contract: what is not declared here is not API.
 *
 * Quick start
 * -----------
 *     pose_rig *rig;
 *     if (pose_rig_load("patient.rig", &rig) < 0) {
 *         fprintf(stderr, "%s\n", pose_last_error());
 *         return 1;
 *     }
 *     pose_state *st;
 *     pose_state_create(rig, &st);
 *     int knee = pose_rig_find_joint(rig, "knee_r");
 *     const float bend[3] = {0.0f, 90.0f, 0.0f};
 *     pose_set_joint_euler(st, knee, bend, POSE_EULER_XYZ); // POSE_CLAMPED if past limits
 *     pose_set_method(st, POSE_COR);
 *     pose_apply(st);
 *     size_t n;
 *     const float *xyz = pose_tissue_positions(st, 0, &n);  // n vertices, xyz interleaved
 *     pose_state_free(st);
 *     pose_rig_free(rig);
 *
 * Objects and threads
 * -------------------
 * A pose_rig is immutable once loaded: any number of threads may read it and
 * create states from it at the same time. A pose_state is one posed patient;
 * it must be used by one thread at a time (pose_apply itself fans work out to
 * the state's own worker pool). A rig must outlive every state created from it.
 *
 * Errors
 * ------
 * Functions return a pose_status: POSE_OK (0) on success, POSE_CLAMPED (1) for
 * a success that changed the request, a negative code on failure. After a
 * failure, pose_last_error() returns a message that names what went wrong
 * (file, section, offset, line). The message is thread-local: it belongs to
 * the calling thread and stays valid until that thread's next pose call.
 *
 * Units and conventions
 * ---------------------
 * Lengths are in the rig's units (pose-bake writes metres). Quaternions are
 * {x, y, z, w}. Matrices do not appear in the API: transforms are a rotation
 * quaternion plus a translation, applied as p' = R p + t. Positions and normals
 * are float triples interleaved (x0 y0 z0 x1 y1 z1 ...).
 */
#ifndef POSE_POSE_H
#define POSE_POSE_H

#include <stddef.h>
#include <stdint.h>

#include "pose/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------- version */

#define POSE_VERSION_MAJOR 0
#define POSE_VERSION_MINOR 2
#define POSE_VERSION_PATCH 0
/** Encoded as MAJOR*10000 + MINOR*100 + PATCH. Same major = same ABI. */
#define POSE_VERSION_NUMBER \
    (POSE_VERSION_MAJOR * 10000 + POSE_VERSION_MINOR * 100 + POSE_VERSION_PATCH)

/** Run-time version of the library, encoded as POSE_VERSION_NUMBER. @since 0.1 */
POSE_API int pose_version(void);
/** Run-time version as "MAJOR.MINOR.PATCH"; static storage. @since 0.1 */
POSE_API const char *pose_version_string(void);

/** Version of the rig file format this library writes (docs/rig-format.md);
 *  it reads this version only. A file's version is in its header at byte 8.
 *  At run time: pose_rig_format_version. @since 0.2 */
#define POSE_RIG_FORMAT_VERSION 1u

/* ----------------------------------------------------------------- status */

/** Result codes. Codes are only ever appended, never renumbered. */
typedef enum pose_status {
    POSE_OK = 0,                 /**< success */
    POSE_CLAMPED = 1,            /**< success; a value was clamped to a joint limit */
    POSE_ERR_INVALID_ARGUMENT = -1, /**< NULL pointer, index out of range, bad enum */
    POSE_ERR_OUT_OF_MEMORY = -2, /**< an allocation failed */
    POSE_ERR_IO = -3,            /**< a file could not be opened, read, mapped or written */
    POSE_ERR_FORMAT = -4,        /**< malformed data (bad magic, truncation, bad section) */
    POSE_ERR_VERSION = -5,       /**< the data's format version is not supported */
    POSE_ERR_CHECKSUM = -6,      /**< a section's CRC32 does not match its bytes */
    POSE_ERR_INVALID_DATA = -7,  /**< well-formed but inconsistent (index range, weights, hierarchy) */
    POSE_ERR_UNSUPPORTED = -8,   /**< the rig lacks what was asked (e.g. CoR centres) */
    POSE_ERR_NOT_FOUND = -9,     /**< a named joint, tissue or file entry does not exist */
    POSE_ERR_THREAD = -10,       /**< a worker thread could not be started */
} pose_status;

/** Fixed English text for a status code; never NULL; static storage. @since 0.1 */
POSE_API const char *pose_status_string(pose_status status);

/**
 * Detailed message for the calling thread's most recent failure (or clamp):
 * never NULL, "" when there is none. Valid until the thread's next pose call.
 * @since 0.1
 */
POSE_API const char *pose_last_error(void);
/**
 * Set the message pose_last_error() returns on this thread (plain text, not
 * a format). For libraries layered on libpose, such as libpose_bridge, so a
 * host reads one error channel. @since 0.2
 */
POSE_API void pose_set_last_error(const char *message);

/* ----------------------------------------------------------------- values */

/** A rigid transform: p' = R(rotation) p + translation. */
typedef struct pose_transform {
    float rotation[4];    /**< unit quaternion {x, y, z, w} */
    float translation[3];
} pose_transform;

/**
 * Euler angle orders. Angles are always given per axis as {x, y, z} degrees;
 * the order says how they compose: POSE_EULER_ZXY means R = Rz * Rx * Ry,
 * i.e. intrinsic rotations about Z, then the new X, then the new Y — the
 * convention of BVH channel lists ("Zrotation Xrotation Yrotation").
 */
typedef enum pose_euler_order {
    POSE_EULER_XYZ = 0,
    POSE_EULER_XZY = 1,
    POSE_EULER_YXZ = 2,
    POSE_EULER_YZX = 3,
    POSE_EULER_ZXY = 4,
    POSE_EULER_ZYX = 5,
} pose_euler_order;

/** Skinning method used to deform the tet mesh. */
typedef enum pose_method {
    POSE_LBS = 0, /**< linear blend skinning */
    POSE_DQS = 1, /**< dual quaternion skinning (antipodality handled) */
    POSE_COR = 2, /**< optimized centres of rotation (needs CoR data in the rig) */
    POSE_FEM = 3, /**< CoR (DQS without CoR data) refined by quasi-static co-rotational
                       FEM (needs the rig's fem section; see pose_fem_options) @since 0.2 */
} pose_method;

/** What a tissue surface is. */
typedef enum pose_tissue_kind {
    POSE_TISSUE_SKIN = 0,
    POSE_TISSUE_BONE = 1,
    POSE_TISSUE_MUSCLE = 2,
    POSE_TISSUE_ORGAN = 3,
    POSE_TISSUE_OTHER = 4,
} pose_tissue_kind;

/**
 * Memory callbacks. A zeroed struct means malloc/free. alloc must return
 * memory aligned to at least `align` (a power of two, at most 4096).
 */
typedef struct pose_allocator {
    void *(*alloc)(size_t size, size_t align, void *user);
    void (*free)(void *ptr, void *user);
    void *user;
} pose_allocator;

/* ------------------------------------------------------------ rig loading */

typedef struct pose_rig pose_rig;     /**< immutable, shareable across threads */
typedef struct pose_state pose_state; /**< one posed instance; one thread at a time */

/** Flags for pose_load_options.flags. */
enum {
    /** pose_rig_load_ex: read the file into memory instead of mapping it. */
    POSE_LOAD_NO_MMAP = 1u << 0,
    /** pose_rig_load_memory: use the caller's buffer in place (it must stay
     *  valid and unchanged, and be 64-byte aligned, until pose_rig_free). */
    POSE_LOAD_BORROW = 1u << 1,
    /** skip CRC32 checks (structure is still fully validated). */
    POSE_LOAD_SKIP_CRC = 1u << 2,
};

/**
 * Options structs (pose_load_options, pose_state_options) are zero-default
 * and carry their own size, as pose/bridge.h's do: set size to sizeof the
 * struct, or leave it 0. 0 reads the fields the struct had in 0.1 (all but
 * size), so code written for 0.1 keeps its meaning; fields a later version
 * appends are read only when size covers them; a non-zero size below the
 * 0.2 layout is POSE_ERR_INVALID_ARGUMENT.
 *
 * ABI: programs built against the 0.1 headers pass the 0.1 layouts (no size)
 * to pose_rig_load_ex, pose_rig_load_memory and pose_state_create_ex, and the
 * library keeps those symbols for them; this header maps the three names to
 * the sized entry points below, so a rebuilt program passes the sized
 * layout. Bindings that find symbols by name (ctypes, P/Invoke) call the
 * *_sized symbols.
 */
#define pose_rig_load_ex pose_rig_load_ex_sized
#define pose_rig_load_memory pose_rig_load_memory_sized
#define pose_state_create_ex pose_state_create_ex_sized

/** Options for loading; a zeroed struct gives the defaults. */
typedef struct pose_load_options {
    size_t size;    /**< sizeof(pose_load_options), or 0 (see above) @since 0.2 */
    pose_allocator allocator;
    uint32_t flags; /**< POSE_LOAD_* */
} pose_load_options;

/** Size of the 0.2 layout of pose_load_options: the least non-zero size accepted. */
#define POSE_LOAD_OPTIONS_SIZE_0_2 (offsetof(pose_load_options, flags) + sizeof(uint32_t))

/**
 * Load a rig file (memory-mapped; every section validated before use).
 * On failure *out is NULL and pose_last_error() names file, section and offset.
 * @since 0.1
 */
POSE_API pose_status pose_rig_load(const char *path, pose_rig **out);
/** pose_rig_load with options (NULL = defaults). @since 0.1 */
POSE_API pose_status pose_rig_load_ex(const char *path, const pose_load_options *options,
                                      pose_rig **out);
/**
 * Load a rig from a buffer holding a rig file's bytes. The bytes are copied
 * unless options->flags has POSE_LOAD_BORROW. @since 0.1
 */
POSE_API pose_status pose_rig_load_memory(const void *data, size_t size,
                                          const pose_load_options *options, pose_rig **out);
/** Free a rig; NULL is a no-op. All states made from it must be freed first. @since 0.1 */
POSE_API void pose_rig_free(pose_rig *rig);

/* ---------------------------------------------------------- rig queries */

/** Joint limit flags (pose_joint_info.limit_flags): bit a limits axis a (x=0,y=1,z=2). */
enum { POSE_LIMIT_X = 1u, POSE_LIMIT_Y = 2u, POSE_LIMIT_Z = 4u };

typedef struct pose_joint_info {
    const char *name;          /**< owned by the rig */
    int parent;                /**< -1 for a root; parents come before children */
    pose_transform rest_model; /**< joint frame at rest, in model space */
    pose_transform rest_local; /**< joint frame at rest, relative to the parent's */
    uint32_t limit_flags;      /**< POSE_LIMIT_* bits */
    pose_euler_order limit_order;  /**< order the limits' Euler angles are taken in */
    float limit_min_deg[3];    /**< per axis {x, y, z}, in the joint's local frame */
    float limit_max_deg[3];
} pose_joint_info;

typedef struct pose_tissue_info {
    const char *name;            /**< owned by the rig */
    pose_tissue_kind kind;
    int joint;                   /**< joint a bone tissue belongs to, else -1 */
    size_t vertex_count;
    size_t triangle_count;
    const float *rest_positions; /**< 3 * vertex_count, owned by the rig */
    const uint32_t *triangles;   /**< 3 * triangle_count vertex indices, owned by the rig */
} pose_tissue_info;

/** The rig's tetrahedral mesh and its skinning data, all owned by the rig. */
typedef struct pose_tet_info {
    size_t vertex_count;
    size_t tet_count;
    const float *rest_positions; /**< 3 * vertex_count */
    const uint32_t *tets;        /**< 4 * tet_count vertex indices */
    const uint16_t *labels;      /**< per tet: 0 = soft tissue, j + 1 = bone of joint j */
    unsigned influences;         /**< K weights per vertex (1..8) */
    const uint16_t *weight_joints; /**< K * vertex_count joint indices */
    const float *weights;        /**< K * vertex_count, >= 0, summing to 1 per vertex */
    const float *cor;            /**< 3 * vertex_count centres of rotation, or NULL */
} pose_tet_info;

/** Number of joints. @since 0.1 */
POSE_API size_t pose_rig_joint_count(const pose_rig *rig);
/** Index of the joint with this exact name, or -1. @since 0.1 */
POSE_API int pose_rig_find_joint(const pose_rig *rig, const char *name);
/** Describe joint `joint`. @since 0.1 */
POSE_API pose_status pose_rig_joint_info(const pose_rig *rig, int joint, pose_joint_info *out);
/** Number of tissue surfaces. @since 0.1 */
POSE_API size_t pose_rig_tissue_count(const pose_rig *rig);
/** Index of the tissue with this exact name, or -1. @since 0.1 */
POSE_API int pose_rig_find_tissue(const pose_rig *rig, const char *name);
/** Describe tissue `tissue`. @since 0.1 */
POSE_API pose_status pose_rig_tissue_info(const pose_rig *rig, int tissue, pose_tissue_info *out);
/** Describe the tet mesh and weights. @since 0.1 */
POSE_API pose_status pose_rig_tet_info(const pose_rig *rig, pose_tet_info *out);
/**
 * Where tissue `tissue`'s vertices sit in the tet mesh: per vertex the index
 * of its embedding tet (*tet, vertex_count entries) and its 4 barycentric
 * coordinates in that tet (*bary, 4 * vertex_count), owned by the rig. What
 * pose_apply carries each vertex with; exporters use it to give tissue
 * vertices the tet vertices' skinning weights. @since 0.2
 */
POSE_API pose_status pose_rig_tissue_embedding(const pose_rig *rig, int tissue, const uint32_t **tet,
                                               const float **bary);
/** Free-form provenance text stored in the rig ("" when none); owned by the rig. @since 0.1 */
POSE_API const char *pose_rig_metadata(const pose_rig *rig);
/** The rig file format version `rig` was loaded from (a rig made by
 *  pose_rig_create: the one pose_rig_write_file writes); with NULL, the
 *  version this library writes, to compare with the POSE_RIG_FORMAT_VERSION
 *  a program was built with. @since 0.2 */
POSE_API uint32_t pose_rig_format_version(const pose_rig *rig);

/* ----------------------------------------------------- clinical angles */

/**
 * Clinical joint angles (design §2b): degrees from the anatomical neutral
 * posture (standing upright, arms hanging at the sides, palms to the
 * thighs), named as clinicians and goniometers name them:
 *
 *   deg[0]  flexion (+) / extension (-), about the medio-lateral axis
 *           (plantar flexion (-) / dorsiflexion (+) at the ankle);
 *   deg[1]  abduction (+) / adduction (-), about the floating antero-posterior
 *           axis (lateral bending for the spine, radial deviation (+) / ulnar
 *           deviation (-) at the wrist, varus (+) / valgus (-) at elbow and knee);
 *   deg[2]  internal (+) / external (-) rotation about the distal segment's
 *           long axis (pronation (+) / supination (-) of the forearm, axial
 *           rotation of the spine).
 *
 * pose_joint_clinical.names says what positive means for each joint. The
 * three compose as the ISB joint coordinate systems do (Wu et al., J Biomech
 * 2002, 2005): flexion about the proximal segment's axis, then abduction
 * about the floating axis, then rotation about the distal segment's axis,
 * each axis taken in the neutral posture and expressed in the joint's rest
 * frame:
 *
 *   local = R(axes[0], deg[0]) * R(axes[1], deg[1]) * R(axes[2], deg[2]) * neutral
 *
 * (`local` as in pose_set_joint: relative to the joint's rest frame.) All
 * zero is the neutral posture, whatever pose the rig rests in; on the bundled
 * body, shoulder flexion 90 points the arm forward, 150 puts the hand above
 * the head, and shoulder abduction 90 is the T-pose the body was scanned in.
 *
 * Rotations compose; angles are never added axis by axis. Where a rig carries
 * clinical data for a joint, that joint's limits are the clinical ones
 * (AAOS normal ranges of motion by default; a state may have its own,
 * pose_set_joint_range) and every way of setting it (pose_set_joint,
 * pose_set_joint_euler, pose_set_joint_clinical) is clamped in the clinical
 * convention.
 */
typedef struct pose_joint_clinical {
    float neutral[4];      /**< local rotation (relative to rest) of the neutral posture */
    float axes[3][3];      /**< flexion, abduction, rotation axes: unit, orthogonal, in the rest frame */
    const char *names[3];  /**< what positive means per angle ("flexion", "abduction",
                                "internal_rotation", "pronation" ...); owned by the rig
                                (in a pose_rig_desc: 1..31 bytes each, or NULL for the defaults
                                "flexion", "abduction", "internal_rotation") */
    uint32_t limit_flags;  /**< POSE_LIMIT_X / _Y / _Z: deg[0] / deg[1] / deg[2] limited */
    float limit_min_deg[3];/**< clinical range of motion */
    float limit_max_deg[3];
    uint32_t flags;        /**< POSE_CLINICAL_*; 0 in a desc entry = the joint has no clinical data */
} pose_joint_clinical;

/** pose_joint_clinical.flags */
enum {
    /** The joint has clinical data (neutral, axes, limits). */
    POSE_CLINICAL_DEFINED = 1u << 0,
};

/**
 * The neutral posture and clinical axes of `joint`. POSE_ERR_UNSUPPORTED when
 * the rig has none for it (rigs without the optional `clinical` section, e.g.
 * written before pose 0.2; joints such as the root that have no clinical
 * angles). The axes are stored as given; conversions use them
 * orthonormalized from the flexion axis on (Gram-Schmidt); a left-handed set
 * is allowed (rotation stays about the third axis as stored). @since 0.2
 */
POSE_API pose_status pose_rig_joint_clinical(const pose_rig *rig, int joint, pose_joint_clinical *out);
/** Clinical angles {flexion, abduction, rotation} (degrees) -> local rotation; no limits applied. @since 0.2 */
POSE_API pose_status pose_clinical_to_local(const pose_rig *rig, int joint, const float deg[3], float quat_xyzw[4]);
/**
 * Local rotation -> clinical angles. Two angle triples give every rotation
 * (abduction a and 180 - a); the one nearest `hint_deg` is returned, each
 * angle within 180 degrees of the hint's (NULL: the one inside the joint's
 * limits, limited angles taken by whole turns into their range, else
 * abduction in [-90, 90]). At gimbal lock (abduction +-90) only flexion +-
 * rotation is defined: rotation is the hint's, else 0 (or its limit nearest 0),
 * and flexion takes the rest. @since 0.2
 */
POSE_API pose_status pose_local_to_clinical(const pose_rig *rig, int joint, const float quat_xyzw[4],
                                            const float hint_deg[3], float deg[3]);

/** Unit quaternion {x,y,z,w} from Euler angles {x,y,z} in degrees (the one
 *  implementation, computed in double); identity for an unknown order. @since 0.2 */
POSE_API void pose_euler_to_quat(const float deg[3], pose_euler_order order, float quat_xyzw[4]);
/** Euler angles {x,y,z} (degrees) of a unit quaternion, middle angle in [-90, 90];
 *  within 1e-6 of gimbal lock the middle angle is exactly +-90 and the last is 0.
 *  Zeros for an unknown order. @since 0.2 */
POSE_API void pose_quat_to_euler(const float quat_xyzw[4], pose_euler_order order, float deg[3]);

/* ------------------------------------------------------- building rigs */

/** One joint of a rig description. */
typedef struct pose_joint_desc {
    const char *name;          /**< 1..63 bytes, unique within the rig */
    int parent;                /**< -1 for a root, else an earlier joint's index */
    pose_transform rest_model; /**< joint frame at rest in model space */
    uint32_t limit_flags;      /**< POSE_LIMIT_* */
    pose_euler_order limit_order;
    float limit_min_deg[3];
    float limit_max_deg[3];
} pose_joint_desc;

/** One tissue surface of a rig description, embedded in the tet mesh. */
typedef struct pose_tissue_desc {
    const char *name;          /**< 1..63 bytes */
    pose_tissue_kind kind;
    int joint;                 /**< -1 unless a bone of that joint */
    size_t vertex_count;
    const float *positions;    /**< 3 * vertex_count rest positions */
    size_t triangle_count;
    const uint32_t *triangles; /**< 3 * triangle_count */
    const uint32_t *tet;       /**< per vertex: index of the embedding tet */
    const float *bary;         /**< 4 * vertex_count barycentric coordinates (sum 1;
                                    may be slightly outside [0,1] for vertices
                                    outside the tet mesh) */
} pose_tissue_desc;

/** Everything a rig holds, as caller-owned arrays (see pose_tet_info for layouts). */
typedef struct pose_rig_desc {
    size_t joint_count;
    const pose_joint_desc *joints;
    size_t tet_vertex_count;
    const float *tet_positions;
    size_t tet_count;
    const uint32_t *tets;
    const uint16_t *tet_labels;
    unsigned influences;
    const uint16_t *weight_joints;
    const float *weights;
    const float *cor;          /**< may be NULL: the rig then has no CoR method */
    size_t tissue_count;
    const pose_tissue_desc *tissues;
    const char *metadata;      /**< may be NULL */
    /** Per joint (joint_count entries), or NULL: the rig then knows no neutral
     *  posture and no clinical axes (pose_rig_joint_clinical says
     *  POSE_ERR_UNSUPPORTED). Stored in the optional `clinical` section. @since 0.2 */
    const struct pose_joint_clinical *clinical;
    /** Soft tissue's material, or NULL: the rig then has no POSE_FEM. Stored
     *  in the optional `fem` section. @since 0.2 */
    const struct pose_fem_material *fem;
    /** Rest images (a CT and its labels: struct pose_rig_volume, pose/volume.h),
     *  volume_count entries, or 0 / NULL. Stored in the optional `volumes`
     *  section. @since 0.2 */
    size_t volume_count;
    const struct pose_rig_volume *volumes;
    /** Soft nodes tied to bones by zero-length springs (struct
     *  pose_fem_coupling), fem_coupling_count entries sorted by node, or 0 /
     *  NULL. Stored in the optional `couplings` section; needs `fem`. @since 0.2 */
    size_t fem_coupling_count;
    const struct pose_fem_coupling *fem_couplings;
    /** Soft nodes tied to other soft nodes or to points of the tet mesh by
     *  zero-length springs (struct pose_fem_soft_coupling),
     *  fem_soft_coupling_count entries, or 0 / NULL. Stored in the optional
     *  `soft_couplings` section; needs `fem`. @since 0.2 */
    size_t fem_soft_coupling_count;
    const struct pose_fem_soft_coupling *fem_soft_couplings;
} pose_rig_desc;

/**
 * Validate a description and build a rig from it (the arrays are copied).
 * Applies the same checks as the loader. @since 0.1
 */
POSE_API pose_status pose_rig_create(const pose_rig_desc *desc, const pose_allocator *allocator,
                                     pose_rig **out);
/** Validate a description and write it as a rig file (current format version). @since 0.1 */
POSE_API pose_status pose_rig_write_file(const pose_rig_desc *desc, const char *path);
/**
 * Validate a description and serialize it into a buffer allocated with
 * `allocator` (NULL = malloc); the caller frees *data with the same allocator.
 * @since 0.1
 */
POSE_API pose_status pose_rig_write_memory(const pose_rig_desc *desc, const pose_allocator *allocator,
                                           void **data, size_t *size);

/* ------------------------------------------------------------- instances */

/** Options for a state; a zeroed struct gives the defaults (size: see pose_load_options). */
typedef struct pose_state_options {
    size_t size;        /**< sizeof(pose_state_options), or 0 @since 0.2 */
    pose_allocator allocator;
    int threads;        /**< worker threads for pose_apply; 0 = number of cores */
    pose_method method; /**< initial method (default POSE_LBS) */
} pose_state_options;

/** Size of the 0.2 layout of pose_state_options: the least non-zero size accepted. */
#define POSE_STATE_OPTIONS_SIZE_0_2 (offsetof(pose_state_options, method) + sizeof(pose_method))

/** Create a posed instance of `rig`, at rest. @since 0.1 */
POSE_API pose_status pose_state_create(const pose_rig *rig, pose_state **out);
/** pose_state_create with options (NULL = defaults). @since 0.1 */
POSE_API pose_status pose_state_create_ex(const pose_rig *rig, const pose_state_options *options,
                                          pose_state **out);
/** Free a state and its worker pool; NULL is a no-op. @since 0.1 */
POSE_API void pose_state_free(pose_state *state);
/** The rig a state was made from. @since 0.1 */
POSE_API const pose_rig *pose_state_rig(const pose_state *state);

/**
 * Set a joint's local rotation relative to its rest frame (quaternion
 * {x,y,z,w}, normalized here). Returns POSE_CLAMPED if the rig's joint
 * limits changed it (pose_last_error() says which axis and by how much).
 * Takes effect at the next pose_apply. @since 0.1
 */
POSE_API pose_status pose_set_joint(pose_state *state, int joint, const float quat_xyzw[4]);
/** Set a joint's local rotation from Euler angles {x,y,z} in degrees. @since 0.1 */
POSE_API pose_status pose_set_joint_euler(pose_state *state, int joint, const float deg[3],
                                          pose_euler_order order);
/**
 * Set a joint from clinical angles {flexion, abduction, rotation} in degrees
 * from the neutral posture (see pose_joint_clinical). Limited angles are
 * taken by whole turns nearest their range (350 is -10), then clamped:
 * POSE_CLAMPED when the joint's clinical range of motion changed them
 * (pose_last_error() names the joint, the angle and the amount);
 * POSE_ERR_UNSUPPORTED when the rig has no clinical data for the joint.
 * @since 0.2
 */
POSE_API pose_status pose_set_joint_clinical(pose_state *state, int joint, const float deg[3]);
/** The joint's current clinical angles (the triple nearest the last request:
 *  as set by pose_set_joint_clinical after clamping; for a rotation set
 *  otherwise, the triple inside the range, else the one nearest it).
 *  POSE_ERR_UNSUPPORTED for a joint without clinical data. @since 0.2 */
POSE_API pose_status pose_get_joint_clinical(const pose_state *state, int joint, float deg[3]);
/** Every joint with clinical data to its neutral posture (the others to rest), root to identity.
 *  POSE_CLAMPED if a joint's range of motion excludes its neutral posture. @since 0.2 */
POSE_API pose_status pose_set_neutral(pose_state *state);
/**
 * Give this state its own range of motion for `joint`, in clinical angles
 * {flexion, abduction, rotation} (degrees from neutral, as
 * pose_joint_clinical.limit_min_deg / limit_max_deg): a patient's frozen
 * shoulder or contracture, or a recorded person's range past the rig's
 * (normal ranges of motion are averages, and mocap of healthy people
 * exceeds them). Every setter of the joint then clamps to it, as it did to
 * the rig's; the joint's current rotation is kept until it is set again.
 * An angle whose range spans a whole turn (max - min >= 360) is unlimited;
 * every other angle is limited, including one the rig leaves free. Both
 * pointers NULL restore the rig's range. POSE_ERR_INVALID_ARGUMENT when one
 * is NULL, a value is not finite or min > max; POSE_ERR_UNSUPPORTED for a
 * joint without clinical data. Allocates nothing; pose_reset keeps the
 * state's ranges. pose_local_to_clinical and pose_rig_joint_clinical keep
 * speaking of the rig's. @since 0.2
 */
POSE_API pose_status pose_set_joint_range(pose_state *state, int joint, const float min_deg[3],
                                          const float max_deg[3]);
/**
 * The range of motion this state clamps `joint` to (pose_set_joint_range,
 * else the rig's): any output pointer may be NULL; limit_flags gets
 * POSE_LIMIT_X / _Y / _Z for limited flexion / abduction / rotation, and an
 * unlimited angle reads [-180, 180] unless a range was set for it.
 * POSE_ERR_UNSUPPORTED for a joint without clinical data. @since 0.2
 */
POSE_API pose_status pose_get_joint_range(const pose_state *state, int joint, float min_deg[3],
                                          float max_deg[3], uint32_t *limit_flags);
/** The joint's current local rotation (after clamping). @since 0.1 */
POSE_API pose_status pose_get_joint(const pose_state *state, int joint, float quat_xyzw[4]);
/**
 * Place the whole model: applied on top of the root joints' rest frames,
 * p' = R p + t in model space. Either pointer may be NULL (no translation /
 * no rotation). @since 0.1
 */
POSE_API pose_status pose_set_root(pose_state *state, const float translation[3],
                                   const float quat_xyzw[4]);
/** All joints back to rest, root transform to identity. @since 0.1 */
POSE_API pose_status pose_reset(pose_state *state);
/** Choose the skinning method; POSE_ERR_UNSUPPORTED for POSE_COR on a rig without CoR.
 *  The first POSE_FEM allocates the solver's work arrays (POSE_FEM below);
 *  POSE_ERR_OUT_OF_MEMORY then, the method unchanged. @since 0.1 */
POSE_API pose_status pose_set_method(pose_state *state, pose_method method);
/** The current skinning method. @since 0.1 */
POSE_API pose_method pose_get_method(const pose_state *state);
/** Number of worker threads for pose_apply (0 = cores). Results are identical for
 *  any thread count. @since 0.1 */
POSE_API pose_status pose_set_threads(pose_state *state, int threads);

/**
 * Pose the anatomy: forward kinematics, skinning of the tet mesh, transfer to
 * every tissue vertex, normals. Bone tissues move rigidly with their joint
 * (pose_tissue_info.joint; since 0.2, with every method), whatever the tets
 * that hold their vertices do. Allocates nothing. @since 0.1
 */
POSE_API pose_status pose_apply(pose_state *state);

/**
 * Deformed positions of tissue `tissue` after the last pose_apply (rest
 * positions before the first). Owned by the state, valid until it is freed;
 * overwritten by pose_apply. NULL if the index is out of range.
 * @since 0.1
 */
POSE_API const float *pose_tissue_positions(const pose_state *state, int tissue, size_t *vertex_count);
/**
 * Unit vertex normals of tissue `tissue`, as pose_tissue_positions: the
 * area-weighted rest normals carried by the deformation of each vertex's tet
 * (recomputed from the deformed triangles where a tet is turned inside out);
 * (0, 0, 0) for a vertex no triangle uses. @since 0.1
 */
POSE_API const float *pose_tissue_normals(const pose_state *state, int tissue, size_t *vertex_count);
/** Deformed tet mesh vertices, as pose_tissue_positions. @since 0.1 */
POSE_API const float *pose_tet_positions(const pose_state *state, size_t *vertex_count);
/** Joint frame in model space after the last pose_apply. @since 0.1 */
POSE_API pose_status pose_joint_world(const pose_state *state, int joint, pose_transform *out);

/* ------------------------------------------ physically based layer (FEM) */

/**
 * POSE_FEM (design §2, Sujar et al. §5): the tet mesh is skinned (CoR, or
 * DQS when the rig has no centres), then refined to the steady state of
 * linear co-rotational elasticity: every vertex of a bone tet (label > 0)
 * is held where skinning put it (bones are rigid), the soft tissue
 * (label 0) moves to its elastic equilibrium, and the tissues follow by the
 * usual transfer, except bone tissues: each moves exactly by its joint's
 * rigid motion (pose_tissue_info.joint). The simulation mesh is the rig's
 * own tet mesh; the rig's `fem` section gives the soft tissue's material.
 * Near-incompressible tissue (Poisson's ratio 0.45-0.49) keeps the body's
 * volume where skinning inflates or deflates it.
 *
 * Each outer iteration takes every tet's rotation from its deformation
 * (polar decomposition, started from the state's last rotations) and solves
 * the warped linear system by Jacobi-preconditioned conjugate gradients. The
 * result is identical for any thread count; it depends on the state's
 * previous poses only through where the rotations start (differences far
 * below the tolerance). pose_apply still allocates nothing.
 *
 * The solver's work arrays (60 floats a soft tet and a few per vertex: 406 MB
 * on a default bake of the bundled body) are allocated, with the state's
 * allocator, when the state first needs them: pose_state_create_ex with
 * POSE_FEM, pose_set_method(POSE_FEM), or the dynamics' first
 * pose_step / pose_set_dynamics_options / pose_reset_dynamics. The rig's
 * simulation mesh (64 bytes a soft tet: about 125 MB there) is built, with
 * the rig's allocator, at the first of these on any of its states (or by
 * couplings and pose_rig_fem_nodes_near_joint), once, whatever the threads.
 * A rig and states that only skin never carry either; POSE_ERR_OUT_OF_MEMORY
 * at those calls leaves the state as it was.
 */

/** The soft tissue's linear isotropic material (pose_rig_desc.fem). */
typedef struct pose_fem_material {
    float young_modulus; /**< Pa, > 0 (soft tissue: a few kPa) */
    float poisson_ratio; /**< [0, 0.5); near 0.5 keeps volume */
    float density;       /**< kg per cubic rig unit, >= 0 (gravity only) */
} pose_fem_material;

/** Solver settings; zero fields take the defaults. size: as pose_load_options. */
typedef struct pose_fem_options {
    size_t size;          /**< sizeof(pose_fem_options), or 0 */
    int outer_iterations; /**< co-rotational updates (default 2) */
    int cg_iterations;    /**< most CG iterations per outer iteration (default 200) */
    float tolerance;      /**< stop when the residual force is this fraction of the
                               skinned pose's (default 0.05) */
    float gravity[3];     /**< rig units / s^2 (default 0: no sag) */
} pose_fem_options;

/** What the last pose_apply with POSE_FEM did. */
typedef struct pose_fem_stats {
    size_t size;             /**< sizeof(pose_fem_stats), set by the caller */
    int outer_iterations;
    int cg_iterations;       /**< summed over the outer iterations */
    double residual;         /**< final residual force / the skinned pose's */
    double seconds_skin;     /**< skinning of the tet mesh */
    double seconds_rotations;/**< polar decompositions and elastic forces */
    double seconds_cg;       /**< conjugate gradient iterations */
    double seconds_transfer; /**< transfer to the tissues */
} pose_fem_stats;

/** Whether the rig has what POSE_FEM needs (its `fem` section). @since 0.2 */
POSE_API int pose_rig_has_fem(const pose_rig *rig);
/** The soft tissue's material; POSE_ERR_UNSUPPORTED without a fem section. @since 0.2 */
POSE_API pose_status pose_rig_fem_material(const pose_rig *rig, pose_fem_material *out);
/** Set the solver settings (NULL: defaults). POSE_ERR_INVALID_ARGUMENT for
 *  negative counts or a tolerance outside [0, 1). @since 0.2 */
POSE_API pose_status pose_set_fem_options(pose_state *state, const pose_fem_options *options);
/** Statistics of the last FEM refinement (zeros before one); out->size must be set. @since 0.2 */
POSE_API pose_status pose_get_fem_stats(const pose_state *state, pose_fem_stats *out);

/**
 * Dynamics (design §2, Otaduy et al. §5.1-5.2): pose_step advances the
 * soft tissue by dt toward the skeleton as the setters left it, by backward
 * Euler with linearized forces: A v' = b, x' = x + dt v', with
 * A = (1 + dt alpha) M + (dt beta + dt^2) K (M - dt dF/dv - dt^2 dF/dx
 * with Rayleigh damping alpha M + beta K), K the co-rotational (warped)
 * stiffness of the rig's soft tets at the current positions and the bone
 * springs', b = M v + dt f, f the elastic forces (POSE_FEM's material and
 * skin volume term, with the tets' volume term of plain co-rotated linear
 * elasticity: its warped stiffness is exact up to the rotation's own
 * derivative, which keeps large steps stable where tets invert), gravity
 * and the bones' pull. Bones are kinematic rigid bodies at the skinned pose (the
 * method's skinning, CoR or DQS for POSE_FEM): every bone node (a vertex of
 * a bone tet that also belongs to a soft tet) is tied to its bone by a
 * zero-length spring, every other bone vertex moves with its bone. Each
 * coupling island (a connected part of the soft tissue) is solved by its
 * own block-Jacobi preconditioned conjugate gradients, warm-started from
 * the last velocities. Soft tets whose centre lies outside the skin at
 * rest (what a coarse bake fills between limbs that touch and around the
 * surface) are not tissue: they turn with the skeleton (the blend of the
 * joints that move their corners) instead of with their own deformation,
 * which deep flexion stretches several times over and turns inside out;
 * found when the simulation is allocated (about 0.1 s on the coarse body).
 * Then the tet mesh (pose_tet_positions) and every
 * tissue (the usual transfer; bone tissues by their joint's rigid motion,
 * as POSE_FEM) show the simulated positions.
 *
 * The simulation starts at rest in the skinned pose of its first step or of
 * pose_reset_dynamics. Its buffers are allocated, with the state's
 * allocator, by the first pose_step or pose_set_dynamics_options; later
 * steps allocate nothing. Results are identical for any thread count.
 * pose_apply writes the outputs from skinning (or POSE_FEM) and leaves the
 * simulation as it is; the last of the two calls is what the outputs show.
 * Stable from dt = 1/1000 s to 1/30 s, also under fast joint swings.
 * Contact: with pose_set_contact_response on (pose/contact.h), each step
 * keeps the soft nodes out of bone by velocity constraints solved after
 * the CG solve, and pushes the skin out of bone after the transfer.
 */

/** Dynamics settings. Start from pose_dynamics_defaults; every field is
 *  taken as set. */
typedef struct pose_dynamics_options {
    size_t size;              /**< sizeof(pose_dynamics_options) */
    float mass_damping;       /**< Rayleigh alpha, 1/s, >= 0 (default 1) */
    float stiffness_damping;  /**< Rayleigh beta, s, >= 0 (default 0.01) */
    float gravity[3];         /**< rig units / s^2 (default 0) */
    float coupling_stiffness; /**< the bone springs' stiffness as a multiple of each bone
                                   node's own elastic stiffness, > 0 (default 100) */
    float tolerance;          /**< CG stops for an island when the velocity error, measured
                                   by its energy (preconditioned residual), is this
                                   fraction of the step's momentum b, or of the island
                                   moving at 1e-2 rig units/s where b is smaller (at
                                   rest b is rounding noise); in (0, 1) (default 1e-2) */
    int cg_iterations;        /**< most CG iterations per island and step, >= 1 (default 50) */
} pose_dynamics_options;

/** What the last pose_step did. */
typedef struct pose_dynamics_stats {
    size_t size;              /**< sizeof(pose_dynamics_stats), set by the caller */
    int islands;              /**< coupling islands (connected parts of the soft tissue) */
    int cg_iterations;        /**< most over the islands */
    double residual;          /**< largest final error as a fraction of b (see tolerance) */
    double kinetic_energy;    /**< of the simulated vertices after the step, J (rig units: m) */
    double time;              /**< simulated seconds since the simulation started */
    double seconds_skin;      /**< FK and skinning (where the bones go) */
    double seconds_assembly;  /**< rotations, forces, right-hand side, preconditioner, update */
    double seconds_cg;        /**< conjugate gradient iterations */
    double seconds_transfer;  /**< transfer to the tissues */
    /* The contact response in pose_step (pose_set_contact_response on;
     * pose/contact.h), zeros with it off. Appended in 0.2: a caller whose
     * size ends before them gets the fields above. */
    int contacts;             /**< velocity constraints (a soft node against a bone) */
    int contact_iterations;   /**< most projected Gauss-Seidel sweeps of a contact island */
    double max_impulse;       /**< largest constraint impulse, N s (rig units: kg m/s) */
    double seconds_contact;   /**< detection and response (not in seconds_assembly) */
} pose_dynamics_stats;

/** Size of pose_dynamics_stats before the contact fields: the least size
 *  pose_get_dynamics_stats accepts. */
#define POSE_DYNAMICS_STATS_SIZE_0_2 (offsetof(pose_dynamics_stats, seconds_transfer) + sizeof(double))

/** The default dynamics settings (size set). @since 0.2 */
POSE_API void pose_dynamics_defaults(pose_dynamics_options *out);
/** Set the dynamics settings (NULL: defaults); allocates the simulation if
 *  it has none yet. POSE_ERR_INVALID_ARGUMENT for a field out of range,
 *  POSE_ERR_UNSUPPORTED for a rig without a fem section or with massless
 *  soft tissue (density 0). @since 0.2 */
POSE_API pose_status pose_set_dynamics_options(pose_state *state,
                                               const pose_dynamics_options *options);
/** Advance the simulation by dt seconds (0 < dt <= 1) toward the posed
 *  skeleton and write the outputs. Errors as pose_set_dynamics_options. @since 0.2 */
POSE_API pose_status pose_step(pose_state *state, double dt);
/** Restart the simulation at rest in the current skinned pose and write
 *  the outputs. Errors as pose_set_dynamics_options. @since 0.2 */
POSE_API pose_status pose_reset_dynamics(pose_state *state);
/** Statistics of the last pose_step (zeros before one); out->size must be
 *  set, at least POSE_DYNAMICS_STATS_SIZE_0_2 (the fields it covers are
 *  written). @since 0.2 */
POSE_API pose_status pose_get_dynamics_stats(const pose_state *state, pose_dynamics_stats *out);

/**
 * Couplings (Otaduy et al. §4.2, §5.2): a soft simulation node tied to a
 * bone by a zero-length spring, as the bone nodes are, where the anatomy
 * tethers tissue to bone (skin over the shin, the sternum, the skull, the
 * iliac crest, the olecranon) while the rest slides. The spring's bone end
 * is `anchor` (model space at rest; pose-bake uses the node's rest
 * position) moved by the joint's rigid motion (its skinning transform);
 * its stiffness is `stiffness` times the node's own elastic stiffness at
 * rest (the trace / 3 of its 3x3 block), as pose_dynamics_options'
 * coupling_stiffness scales the bone nodes'. POSE_FEM adds the spring to
 * its equilibrium, pose_step to its forces, stiffness and damping (Rayleigh
 * beta relative to the bone's motion). Other methods ignore couplings.
 *
 * A rig's couplings (its optional `couplings` section: pose-bake resolves
 * a template's "couplings" to nodes, or pose_rig_desc.fem_couplings) are a
 * new state's; pose_set_fem_couplings replaces a state's without a rebake.
 * A node the simulation holds or does not move (a vertex of a bone tet, or
 * of no soft tet) is already tied to its bone: its coupling is ignored.
 *
 * ABI: pose_set_fem_couplings takes its array with the element size
 * (sizeof(pose_fem_coupling)), so a later version may append fields, read
 * only when the element size covers them. pose_rig_fem_couplings and
 * pose_rig_desc.fem_couplings have no element size: they are the 0.2
 * layout, and stay so; a version that appends fields adds calls that take
 * one (as the soft couplings' do).
 */
typedef struct pose_fem_coupling {
    uint32_t node;     /**< simulation node: tet vertex index (pose_tet_positions) */
    int joint;         /**< the bone: its joint, 0 <= joint < joint count */
    float stiffness;   /**< multiple of the node's own elastic stiffness, finite, > 0
                            (pose-bake's default 100, the bone nodes' default) */
    float anchor[3];   /**< the spring's bone end at rest, model space, finite */
} pose_fem_coupling;

/** The rig's couplings: copies min(count, capacity) of them (sorted by node)
 *  to out (may be NULL with capacity 0) and returns the count (0 without a
 *  `couplings` section or for a NULL rig). @since 0.2 */
POSE_API size_t pose_rig_fem_couplings(const pose_rig *rig, pose_fem_coupling *out, size_t capacity);
/** Simulation nodes (tet vertices of a soft tet and of no bone tet) whose
 *  rest position lies within `reach` rig units of the rest surface of
 *  joint's bone tissues (pose_tissue_info: kind POSE_TISSUE_BONE, that
 *  joint), ascending: min(count, capacity) written to nodes, *count the
 *  total. POSE_ERR_INVALID_ARGUMENT for a joint out of range or a reach
 *  not finite or < 0, POSE_ERR_UNSUPPORTED for a rig without a fem section
 *  or a joint without a bone tissue. Brute force over the bone's triangles
 *  near each node: for setting up, not per frame. @since 0.2 */
POSE_API pose_status pose_rig_fem_nodes_near_joint(const pose_rig *rig, int joint, float reach,
                                                   uint32_t *nodes, size_t capacity, size_t *count);
/** Replace the state's couplings by `count` entries of `element_size` bytes
 *  each (>= sizeof(pose_fem_coupling) of 0.2; NULL / 0: none), every node
 *  < tet vertex count and listed once, joint in range, stiffness finite and
 *  > 0, anchor finite (else POSE_ERR_INVALID_ARGUMENT, the state's couplings
 *  unchanged). Allocates with the state's allocator; pose_apply and
 *  pose_step still allocate nothing. A running simulation keeps its
 *  velocities (pose_reset_dynamics restarts it). POSE_ERR_UNSUPPORTED for a
 *  rig without a fem section. @since 0.2 */
POSE_API pose_status pose_set_fem_couplings(pose_state *state, const pose_fem_coupling *couplings,
                                            size_t count, size_t element_size);
/** The state's couplings in effect (the ones on nodes the simulation moves):
 *  their count. @since 0.2 */
POSE_API size_t pose_fem_coupling_count(const pose_state *state);

/**
 * Soft-soft couplings (Otaduy et al. §4.2, §5.2): a soft simulation node
 * tied by a zero-length spring to a point of the tet mesh, the weighted sum
 * of up to 4 other nodes' positions: another node (other {b}, weight {1})
 * or, as pose-bake places them, the point of another part's tet where the
 * node lies at rest (its corners and barycentric weights), so the spring
 * is slack at rest and holds the two parts together as they move, e.g.
 * fascia to the muscle under it, or two separately meshed parts where
 * they touch. The spring's stiffness is `stiffness` times the node's own
 * elastic stiffness at rest, as pose_fem_coupling's. POSE_FEM adds it to
 * its equilibrium, pose_step to its forces, stiffness and damping (Rayleigh
 * beta on the relative velocity); in pose_step the parts a coupling ties
 * become one coupling island, solved together (pose_dynamics_stats.islands
 * counts them). Other methods ignore them.
 *
 * A rig's soft couplings (its optional `soft_couplings` section: pose-bake
 * resolves a template's "couplings" between two parts, or
 * pose_rig_desc.fem_soft_couplings) are a new state's;
 * pose_set_fem_soft_couplings replaces a state's without a rebake. A
 * coupling whose node or any weighted node is not moved freely by the
 * simulation (a vertex of a bone tet, or of no soft tet) is ignored, as a
 * pose_fem_coupling on such a node is.
 *
 * ABI: the calls pass arrays with their element size
 * (sizeof(pose_fem_soft_coupling)); a later version may append fields,
 * read or written only where the element size covers them.
 * pose_rig_desc.fem_soft_couplings has none: it is the 0.2 layout, and
 * stays so.
 */
typedef struct pose_fem_soft_coupling {
    uint32_t node;     /**< simulation node: tet vertex index (pose_tet_positions) */
    uint32_t other[4]; /**< the spring's other end: sum of weight[c] times node other[c]'s
                            position (a weight of 0 leaves its node unused) */
    float weight[4];   /**< finite, summing to 1 (within 1e-4), at least one nonzero;
                            no weighted node is `node` or repeats another */
    float stiffness;   /**< multiple of the node's own elastic stiffness, finite, > 0
                            (pose-bake's default 100, as pose_fem_coupling's) */
} pose_fem_soft_coupling;

/** The rig's soft couplings: copies min(count, capacity) of them, each
 *  element_size bytes apart (its first sizeof(pose_fem_soft_coupling) of 0.2
 *  written), to out (may be NULL with capacity 0) and returns the count (0
 *  without a `soft_couplings` section, for a NULL rig or an element_size
 *  below the 0.2 layout). @since 0.2 */
POSE_API size_t pose_rig_fem_soft_couplings(const pose_rig *rig, pose_fem_soft_coupling *out,
                                            size_t capacity, size_t element_size);
/** Replace the state's soft couplings by `count` entries of `element_size`
 *  bytes each (>= sizeof(pose_fem_soft_coupling) of 0.2; NULL / 0: none):
 *  every node < tet vertex count, weights as pose_fem_soft_coupling says,
 *  stiffness finite and > 0 (else POSE_ERR_INVALID_ARGUMENT naming the
 *  entry, the state's soft couplings unchanged). Allocates with the
 *  state's allocator (a running simulation's islands are joined again
 *  here, its velocities kept); pose_apply and pose_step still allocate
 *  nothing. POSE_ERR_UNSUPPORTED for a rig without a fem section. @since 0.2 */
POSE_API pose_status pose_set_fem_soft_couplings(pose_state *state,
                                                 const pose_fem_soft_coupling *couplings,
                                                 size_t count, size_t element_size);
/** The state's soft couplings in effect (every end moved freely by the
 *  simulation): their count. @since 0.2 */
POSE_API size_t pose_fem_soft_coupling_count(const pose_state *state);

/* ---------------------------------------------------------------- bounds */

/**
 * Axis-aligned bounding box of tissue `tissue` (-1: of every tissue, or of
 * the tet mesh when the rig has none) at rest. One pass over the vertices,
 * nothing cached. @since 0.2
 */
POSE_API pose_status pose_rig_bounds(const pose_rig *rig, int tissue, float min[3], float max[3]);
/** The same box of the posed positions after the last pose_apply (rest before the first). @since 0.2 */
POSE_API pose_status pose_state_bounds(const pose_state *state, int tissue, float min[3], float max[3]);

#ifdef __cplusplus
}
#endif
#endif /* POSE_POSE_H */
