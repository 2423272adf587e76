/* SPDX-License-Identifier: Apache-2.0
 * The bridge's only contact with a live pose_rig / pose_state: reading the
 * rig's skeleton, and applying a pose. Kept apart so that everything else
 * in the bridge links without libpose. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bridge_apply.h"
#include "pb_math.h"

pose_status pb_rig_skel_from_rig(const pose_rig *rig, pb_rig_skel **out, pb_error *err)
{
    if (!rig || !out)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_rig_skel_from_rig: NULL argument");
    *out = NULL;
    size_t n = pose_rig_joint_count(rig);
    pose_joint_desc *d = calloc(n ? n : 1, sizeof *d);
    if (!d)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    for (size_t j = 0; j < n; j++) {
        pose_joint_info info;
        pose_status s = pose_rig_joint_info(rig, (int)j, &info);
        if (s < 0) {
            free(d);
            return pb_fail(err, s, "rig joint %zu: %s", j, pose_last_error());
        }
        d[j].name = info.name;
        d[j].parent = info.parent;
        d[j].rest_model = info.rest_model;
        d[j].limit_flags = info.limit_flags;
        d[j].limit_order = info.limit_order;
        memcpy(d[j].limit_min_deg, info.limit_min_deg, sizeof d[j].limit_min_deg);
        memcpy(d[j].limit_max_deg, info.limit_max_deg, sizeof d[j].limit_max_deg);
    }
    pose_status s = pb_rig_skel_from_desc(d, n, out, err);
    free(d);
    /* The neutral posture and clinical axes, where the rig has them (mappings' "dof"). */
    for (size_t j = 0; s == POSE_OK && j < n; j++) {
        pb_rig_joint *R = &(*out)->joints[j];
        if (pose_rig_joint_clinical(rig, (int)j, &R->clinical) != POSE_OK) {
            memset(&R->clinical, 0, sizeof R->clinical);
            continue;
        }
        for (int k = 0; k < 3; k++) {
            snprintf(R->clinical_names[k], sizeof R->clinical_names[k], "%s",
                     R->clinical.names[k] ? R->clinical.names[k] : "");
            R->clinical.names[k] = R->clinical_names[k];
        }
    }
    return s;
}

pose_status pb_pose_apply_to_state(const pb_pose *p, pose_state *st, int *clamped)
{
    int nclamp = 0;
    for (int j = 0; j < p->joint_count; j++) {
        if (!p->active[j])
            continue;
        pose_status s = pose_set_joint(st, j, p->q[j]);
        if (s == POSE_CLAMPED)
            nclamp++;
        else if (s < 0)
            return s;
    }
    if (p->has_root) {
        pose_status s = pose_set_root(st, p->root_t, p->root_q);
        if (s < 0)
            return s;
    }
    if (clamped)
        *clamped = nclamp;
    return POSE_OK;
}
