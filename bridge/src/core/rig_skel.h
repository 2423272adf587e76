/* SPDX-License-Identifier: Apache-2.0
 * The rig's skeleton as the bridge needs it: names, parents and rest frames.
 * It can come from a loaded pose_rig, from a pose_rig_desc being built (the
 * synthetic bar rig), or from a clip's own hierarchy (an "identical" rig,
 * for tests and for recording a clip's own skeleton). FK here follows
 * libpose: W_j = W_parent * rest_local_j * R_j, with the root placed by the
 * root transform on top of its rest frame. */
#ifndef POSE_BRIDGE_RIG_SKEL_H
#define POSE_BRIDGE_RIG_SKEL_H

#include <stdint.h>

#include "mocap.h"
#include "pose/pose.h"

typedef struct pb_rig_joint {
    char name[PB_NAME_MAX];
    int parent;         /**< -1 for a root; parents precede children */
    double rest_q[4];   /**< rest frame in model space */
    double rest_p[3];
    double local_q[4];  /**< rest frame relative to the parent's */
    double local_p[3];
    uint32_t limit_flags;  /**< POSE_LIMIT_* bits, as in pose_joint_desc (0: none known) */
    float limit_min_deg[3], limit_max_deg[3];
    /** The rig's neutral posture and clinical axes (pose_joint_clinical), when
     *  clinical.flags has POSE_CLINICAL_DEFINED; names copied into clinical_names. */
    pose_joint_clinical clinical;
    char clinical_names[3][32];
} pb_rig_joint;

typedef struct pb_rig_skel {
    int joint_count;
    pb_rig_joint *joints;
} pb_rig_skel;

/** From joint descriptions (rest_model and limits per joint), as in pose_rig_desc. */
pose_status pb_rig_skel_from_desc(const pose_joint_desc *joints, size_t count, pb_rig_skel **out, pb_error *err);
/** From a loaded rig (pose_rig_joint_info). */
pose_status pb_rig_skel_from_rig(const pose_rig *rig, pb_rig_skel **out, pb_error *err);
/**
 * The clip's hierarchy in its reference pose (all channels zero), rest
 * frames axis-aligned (identity rotations), positions scaled by `scale`.
 */
pose_status pb_rig_skel_from_clip(const pb_clip *clip, double scale, pb_rig_skel **out, pb_error *err);
void pb_rig_skel_free(pb_rig_skel *s);
/**
 * The 19 joints of preprocess/templates/full_body.json (names and parents;
 * rest frames identity, 0.1 apart along z) with schematic clinical data:
 * neutral = rest, flexion about +-y, abduction about +-x, rotation about z,
 * signed as the template's frames are. For tests and benchmarks of the
 * full-body mappings that need no baked rig.
 */
pose_status pb_rig_skel_schematic_body(pb_rig_skel **out, pb_error *err);
/**
 * The hinge axis of joint j read from its limits (0 x, 1 y, 2 z), or -1: the
 * joint is a hinge when, of its two axes other than `along` (the local axis
 * nearest its segment, which carries twist), one may turn by 60 degrees or
 * more and the other by 30 or less. A knee (x -5..5, y 0..150, twist z) is a
 * hinge about y; a hip or a joint without limits is not.
 */
int pb_rig_skel_hinge_axis(const pb_rig_skel *s, int j, int along);
int pb_rig_skel_find(const pb_rig_skel *s, const char *name);
/**
 * Model-space joint frames for local rotations q (relative to rest, NULL =
 * rest) and a root transform (root_t/root_q may be NULL).
 */
void pb_rig_skel_fk(const pb_rig_skel *s, const float (*q)[4], const float root_t[3], const float root_q[4],
                    double (*wq)[4], double (*wp)[3]);

#endif /* POSE_BRIDGE_RIG_SKEL_H */
