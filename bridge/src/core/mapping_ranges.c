/* SPDX-License-Identifier: Apache-2.0
 * A mapping's "ranges" (mapping.h) bound to a rig and put on a pose_state:
 * the range of motion a recorded person had, in place of the rig's normal
 * ranges, so that libpose clamps only what lies past that person's range. */
#include <string.h>

#include "mapping.h"

pose_status pb_mapping_resolve_range(const pb_mapping *map, int entry, const pb_rig_skel *rig,
                                     pb_joint_range *out, pb_error *err)
{
    static const char *const generic[3] = {"flexion", "abduction", "rotation"};
    if (!map || !rig || !out || entry < 0 || entry >= map->range_count)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_mapping_resolve_range: bad argument");
    const pb_map_range *R = &map->ranges[entry];
    int j = pb_rig_skel_find(rig, R->joint);
    if (j < 0)
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: ranges.%s: the rig has no joint '%s'", map->path, R->joint,
                       R->joint);
    const pb_rig_joint *J = &rig->joints[j];
    const pose_joint_clinical *c = &J->clinical;
    if (!(c->flags & POSE_CLINICAL_DEFINED))
        return pb_fail(err, POSE_ERR_UNSUPPORTED,
                       "%s: ranges.%s: the rig has no clinical data for joint %s, so no range of motion in "
                       "clinical angles to replace",
                       map->path, R->joint, J->name);
    out->joint = j;
    for (int a = 0; a < 3; a++) {
        int limited = (c->limit_flags >> a) & 1u;
        out->min_deg[a] = limited ? c->limit_min_deg[a] : -180.0f;
        out->max_deg[a] = limited ? c->limit_max_deg[a] : 180.0f;
    }
    unsigned given = 0;
    for (int k = 0; k < R->angle_count; k++) {
        int a = 0;
        while (a < 3 && strcmp(R->angle[k], generic[a]) != 0 && strcmp(R->angle[k], J->clinical_names[a]) != 0)
            a++;
        if (a == 3)
            return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: ranges.%s.%s: joint %s has no angle '%s' (it has %s, %s, %s)",
                           map->path, R->joint, R->angle[k], J->name, R->angle[k], J->clinical_names[0],
                           J->clinical_names[1], J->clinical_names[2]);
        if (given & (1u << a))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: ranges.%s.%s: the joint's %s range is given twice", map->path,
                           R->joint, R->angle[k], J->clinical_names[a]);
        given |= 1u << a;
        out->min_deg[a] = (float)R->min_deg[k];
        out->max_deg[a] = (float)R->max_deg[k];
    }
    return POSE_OK;
}

pose_status pb_joint_range_apply(const pb_joint_range *r, pose_state *state)
{
    float lo[3], hi[3];
    pose_status s = pose_get_joint_range(state, r->joint, lo, hi, NULL);
    if (s < 0)
        return s;
    if (!memcmp(lo, r->min_deg, sizeof lo) && !memcmp(hi, r->max_deg, sizeof hi))
        return POSE_OK;
    return pose_set_joint_range(state, r->joint, r->min_deg, r->max_deg);
}

pose_status pb_mapping_apply_ranges(const pb_mapping *map, const pb_rig_skel *rig, pose_state *state,
                                    pb_error *err)
{
    if (!map || !rig || !state)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_mapping_apply_ranges: NULL argument");
    for (int i = 0; i < map->range_count; i++) {
        pb_joint_range r;
        pose_status s = pb_mapping_resolve_range(map, i, rig, &r, err);
        if (s < 0)
            return s;
        s = pb_joint_range_apply(&r, state);
        if (s < 0)
            return pb_fail(err, s, "%s: ranges.%s: %s", map->path, map->ranges[i].joint, pose_last_error());
    }
    return POSE_OK;
}
