/* SPDX-License-Identifier: Apache-2.0
 *
 * Skeleton templates: which joints a body has, their hierarchy, the bone
 * meshes forming each joint's segment, how each joint centre is found from
 * the bones (the fitting rule) and default joint limits. Read from JSON
 * (cJSON); preprocess/templates/full_body.json is the full example.
 *
 *   { "format": "pose-skeleton-template", "version": 1, "name": "...",
 *     "contact_mm": 5,                      default contact distance
 *     "joints": [ {                         parents before children
 *       "name": "knee_r",                   1..63 bytes, unique
 *       "parent": "hip_r",                  or null for the root
 *       "rule": "hinge",                    root | ball | hinge | spine | fixed
 *       "bones": ["r_tibia", "r_fibula"],   mesh names (file stems) of the segment
 *       "contact": ["r_tibia"],             optional: child bones in the contact
 *       "parent_contact": ["r_femur"],      optional: parent bones in the contact
 *       "fit": "parent",                    child | parent | both: surface fitted
 *       "contact_mm": 10, "grow_mm": 35,    contact distance; optional growth
 *       "axis": [0, 1, 0], "up": [0, 0, 1], approximate frame y and z (model space)
 *       "at": [x, y, z],                    fixed centre (rule fixed; root optional)
 *       "limits": {"order": "XYZ", "y": [0, 150]},  degrees about frame axes
 *       "clinical": { ... },                optional, see below (not on the root)
 *       "comment": "..." } ],
 *     "couplings": [ {                      optional: soft tissue tethered to bone
 *       "bone": "r_tibia",                  a bone mesh of some joint's "bones", or
 *       "joint": "knee_r",                  every bone mesh of that joint's segment
 *       "reach_mm": 12,                     simulation nodes within this distance of
 *                                           the bone's surface, (0, 100] millimetres
 *       "stiffness": 100,                   optional: multiple of each node's own elastic
 *                                           stiffness, (0, 1e6], default 100
 *       "comment": "..." },
 *     { "tissue": "fascia_lata",            or soft-soft: the nodes of one tissue mesh's
 *       "to": "r_quadriceps",               part of the tet mesh, tied to another's
 *       "reach_mm": 2,                      within this distance of its tets, (0, 10]
 *       "stiffness": 100 } ] }
 * Unknown or repeated keys are errors, so typos do not pass silently.
 *
 * "couplings" (Otaduy et al. §4.2, §5.2): pose-bake ties every soft
 * simulation node (a tet vertex in soft tissue, not a bone tet's) within
 * reach of the named bone's surface to that bone's rigid motion by a
 * zero-length spring (the rig's `couplings` section; pose.h
 * pose_fem_coupling): skin over the shin, the sternum, the skull, the
 * iliac crest, the olecranon. A node within reach of several entries takes
 * the nearest bone. A soft-soft entry ties the free soft nodes of the tets
 * that embed "tissue" (not nodes of those that embed "to") lying within
 * reach of a tet that embeds "to" to that tet's nearest point (the rig's
 * `soft_couplings` section; pose.h pose_fem_soft_coupling): where two
 * parts meshed apart touch; the spring spans the gap at rest (zero where
 * the node lies in the tet), so the reach is small. Tissue names are the
 * bake's mesh names, checked when baking.
 *
 * "clinical" describes the joint's clinical angles (design §2b, pose.h
 * pose_joint_clinical) in model space, in the anatomical neutral posture:
 *   { "neutral": [0, 0, -1],     optional: direction the segment (this joint ->
 *                                its child joint) points in the neutral posture;
 *                                absent: the rest pose is neutral for this joint
 *     "flexion": [0, -1, 0],     nominal axis of positive flexion (right-handed)
 *     "abduction": [-1, 0, 0],   nominal axis of positive abduction
 *     "rotation": -1,            +1: positive rotation is right-handed about the
 *                                distal direction, -1: about the proximal one
 *     "names": ["flexion", "abduction", "internal_rotation"],  optional, 1..31 bytes
 *     "limits": {"flexion": [-60, 180], "abduction": [-30, 180], "rotation": [-90, 70]},
 *     "comment": "..." }
 * pose-bake turns these into the rig's neutral offset and axes from the
 * fitted joints (clinical_fit.h); the vectors are nominal, so they need only
 * say which way, and a hinge's flexion axis comes from the bones.
 */
#ifndef POSE_PP_TEMPLATE_JSON_H
#define POSE_PP_TEMPLATE_JSON_H

#include <stddef.h>
#include <stdint.h>

#include "pose/pose.h"

#define PP_NAME_MAX 64

/** How a joint's centre (and axis) is estimated from the bones. */
typedef enum pp_fit_rule {
    PP_FIT_ROOT = 0,  /**< the root: centroid of its segment (or "at"), world-aligned frame */
    PP_FIT_BALL = 1,  /**< least-squares sphere of the articular contact region */
    PP_FIT_HINGE = 2, /**< axis = principal direction of the contact region; centre on it */
    PP_FIT_SPINE = 3, /**< centroid of the contact region (vertebra groups, saddle joints) */
    PP_FIT_FIXED = 4, /**< centre given by "at" in the template (model space, metres) */
} pp_fit_rule;

/** What point set a ball/hinge centre is fitted to. */
typedef enum pp_fit_side {
    PP_SIDE_CHILD = 0,  /**< the child bone's vertices near the parent (default) */
    PP_SIDE_PARENT = 1, /**< the parent bone's vertices near the child */
    PP_SIDE_BOTH = 2,   /**< both articular surfaces */
} pp_fit_side;

#define PP_CLINICAL_NAME_MAX 32

/** A joint's "clinical" object (model space, neutral posture). */
typedef struct pp_template_clinical {
    int defined;                /**< the joint has a "clinical" object */
    int has_neutral;
    float neutral[3];           /**< unit: the segment's direction in the neutral posture */
    float flexion[3];           /**< unit, nominal positive flexion axis */
    float abduction[3];         /**< unit, nominal positive abduction axis */
    int rotation_sign;          /**< +1: right-handed about the distal direction, -1: proximal */
    char names[3][PP_CLINICAL_NAME_MAX]; /**< "" = libpose's default name */
    uint32_t limit_flags;       /**< POSE_LIMIT_X/Y/Z = flexion/abduction/rotation limited */
    float limit_min_deg[3], limit_max_deg[3];
} pp_template_clinical;

typedef struct pp_template_joint {
    char name[PP_NAME_MAX];
    int parent;                 /**< index of an earlier joint, -1 for the root */
    pp_fit_rule rule;
    pp_fit_side side;
    size_t bone_count;
    char (*bones)[PP_NAME_MAX]; /**< the segment's bone meshes (by mesh name) */
    size_t contact_count;       /**< 0: the whole segment takes part in the contact */
    char (*contact)[PP_NAME_MAX]; /**< child bones used for the contact region */
    size_t parent_contact_count; /**< 0: the whole parent segment */
    char (*parent_contact)[PP_NAME_MAX];
    float contact_mm;           /**< contact distance, millimetres */
    float grow_mm;              /**< > 0: fit to the fit side's vertices within this
                                     distance of the contact region's centroid (the whole
                                     articular surface, when the contact strip is too
                                     narrow an arc for a stable fit) */
    float axis[3];              /**< approximate flexion axis (frame y), model space */
    float up[3];                /**< approximate direction towards the parent (frame z) */
    int has_at;
    float at[3];                /**< fixed centre (PP_FIT_FIXED, optional for the root) */
    uint32_t limit_flags;       /**< POSE_LIMIT_* */
    pose_euler_order limit_order;
    float limit_min_deg[3], limit_max_deg[3];
    pp_template_clinical clinical;
} pp_template_joint;

/** A "couplings" entry: to a bone (joint >= 0), or soft-soft (tissue and to). */
typedef struct pp_template_coupling {
    char bone[PP_NAME_MAX];     /**< a bone mesh, or "" for every bone of the joint */
    int joint;                  /**< the joint whose rigid motion the nodes follow; -1: soft-soft */
    char tissue[PP_NAME_MAX];   /**< soft-soft: the tissue mesh whose nodes are tied ("" else) */
    char to[PP_NAME_MAX];       /**< soft-soft: the tissue mesh they are tied to */
    float reach_mm;             /**< (0, 100]; soft-soft (0, 10] */
    float stiffness;            /**< (0, 1e6]: multiple of a node's own elastic stiffness */
} pp_template_coupling;

/** A coupling's default stiffness: the bone nodes' (pose_dynamics_defaults). */
#define PP_COUPLING_STIFFNESS 100.0f

typedef struct pp_template {
    char name[PP_NAME_MAX];
    size_t joint_count;
    pp_template_joint *joints;
    size_t coupling_count;
    pp_template_coupling *couplings;
} pp_template;

/**
 * Parse a template from `size` bytes of JSON. `source` names the text in
 * messages (usually the file path). On failure returns a negative
 * pose_status, leaves *out empty and writes a message naming the source and
 * the line, joint and field at fault into err.
 */
int pp_template_parse(const char *text, size_t size, const char *source, pp_template *out,
                      char *err, size_t err_size);
/** Read and parse a template file (pp_template_parse). */
int pp_template_load(const char *path, pp_template *out, char *err, size_t err_size);
void pp_template_free(pp_template *t);

/** Index of the joint with this name, or -1. */
int pp_template_find_joint(const pp_template *t, const char *name);
/** Index of the joint whose segment holds this bone mesh, or -1 (a soft mesh). */
int pp_template_joint_of_bone(const pp_template *t, const char *bone);
const char *pp_fit_rule_name(pp_fit_rule rule);

#endif /* POSE_PP_TEMPLATE_JSON_H */
