/* SPDX-License-Identifier: Apache-2.0
 *
 * The neutral posture and clinical axes of a fitted skeleton (design §2b):
 * from the template's "clinical" objects (nominal directions in model space)
 * and the fitted joints, per joint the neutral offset (a local rotation
 * relative to the rest frame) and the flexion, abduction and rotation axes in
 * the rest frame, as pose_joint_clinical (pose.h) stores them.
 */
#ifndef POSE_PP_CLINICAL_FIT_H
#define POSE_PP_CLINICAL_FIT_H

#include "rig_fit.h"
#include "template_json.h"

typedef struct pp_clinical_joint {
    pose_joint_clinical c;  /**< as the rig stores it; c.flags 0: no clinical data (the
                                 root, or no "clinical" in the template). c.names point
                                 into the template (NULL: libpose's default) */
    double neutral_deg;     /**< angle of the neutral offset */
    double model_axes[3][3];/**< the three axes in model space, in the neutral posture */
    double distal[3];       /**< the segment's direction in the neutral posture (model; a
                                 segment without a child joint: its parent's), which the
                                 rotation axis follows */
    double neutral_motion[3][3]; /**< D: model-space rotation taking the segment from the
                                      rest pose to the neutral posture (row-major) */
} pp_clinical_joint;

/**
 * Compute every joint's clinical data, parents first. out has
 * t->joint_count entries. Fails, naming the joint, when a template direction
 * contradicts the fitted skeleton (a nominal axis along the segment, or a
 * hinge axis or abduction axis more than 60 degrees from the template's).
 */
int pp_clinical_fit(const pp_template *t, const pp_fit_joint *fits, pp_clinical_joint *out, char *err,
                    size_t err_size);

#endif /* POSE_PP_CLINICAL_FIT_H */
