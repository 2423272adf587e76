/* SPDX-License-Identifier: Apache-2.0 */
/* A state's own range of motion per joint with clinical data: the rig's
 * (AAOS normals on a body from pose-bake) until pose_set_joint_range gives
 * the joint another, a patient's contracture or a recorded person's wider
 * range. The state's ranges live in its one allocation (state.c), so setting
 * one allocates nothing. */
#include <math.h>
#include <string.h>

#include "error.h"
#include "state_internal.h"

void pose__state_rig_ranges(pose_state *st)
{
    for (size_t j = 0; j < st->rig->joint_count; j++) {
        const pose__clinical_record *r = pose__joint_clinical(st->rig, j);
        if (r)
            pose__clinical_range_of(r, &st->ranges[j]);
    }
}

static pose_status check_range_joint(const pose_state *st, int joint, const char *fn)
{
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: state is NULL", fn);
    if (joint < 0 || (size_t)joint >= st->rig->joint_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: joint %d out of range (%zu joints)", fn, joint,
                          st->rig->joint_count);
    if (!pose__joint_clinical(st->rig, (size_t)joint))
        return pose__fail(POSE_ERR_UNSUPPORTED, "%s: joint %d '%s' has no clinical data in this rig", fn,
                          joint, pose__joint_name(st->rig, (size_t)joint));
    return POSE_OK;
}

pose_status pose_set_joint_range(pose_state *st, int joint, const float min_deg[3], const float max_deg[3])
{
    pose__clear_error();
    static const char fn[] = "pose_set_joint_range";
    pose_status s = check_range_joint(st, joint, fn);
    if (s != POSE_OK)
        return s;
    const pose__clinical_record *r = pose__joint_clinical(st->rig, (size_t)joint);
    if (!min_deg && !max_deg) {
        pose__clinical_range_of(r, &st->ranges[joint]);
        return POSE_OK;
    }
    if (!min_deg || !max_deg)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: joint %d: give both min_deg and max_deg "
                          "(or neither, for the rig's range)", fn, joint);
    pose__clinical_range range = {0};
    for (int a = 0; a < 3; a++) {
        if (!isfinite(min_deg[a]) || !isfinite(max_deg[a]) || min_deg[a] > max_deg[a])
            return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: joint %d '%s': %s range [%g, %g] is not "
                              "finite with min <= max", fn, joint, pose__joint_name(st->rig, (size_t)joint),
                              r->names[a], (double)min_deg[a], (double)max_deg[a]);
        /* A whole turn or more reaches every angle: it limits nothing. */
        if ((double)max_deg[a] - (double)min_deg[a] < 360.0)
            range.limit_flags |= 1u << a;
        range.min_deg[a] = min_deg[a];
        range.max_deg[a] = max_deg[a];
    }
    st->ranges[joint] = range;
    return POSE_OK;
}

pose_status pose_get_joint_range(const pose_state *st, int joint, float min_deg[3], float max_deg[3],
                                 uint32_t *limit_flags)
{
    pose__clear_error();
    pose_status s = check_range_joint(st, joint, "pose_get_joint_range");
    if (s != POSE_OK)
        return s;
    const pose__clinical_range *range = &st->ranges[joint];
    if (min_deg)
        memcpy(min_deg, range->min_deg, sizeof range->min_deg);
    if (max_deg)
        memcpy(max_deg, range->max_deg, sizeof range->max_deg);
    if (limit_flags)
        *limit_flags = range->limit_flags;
    return POSE_OK;
}
