/* SPDX-License-Identifier: Apache-2.0 */
/* Public conversions: clinical angles <-> local rotations of a rig's joint,
 * and Euler angles <-> quaternions (the one implementation, rt_euler.c). */
#include <math.h>
#include <stdbool.h>

#include "clinical_math.h"
#include "error.h"
#include "rt_euler.h"

static bool finite_n(const float *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return false;
    return true;
}

/* The joint's record, or a status saying why there is none. */
static pose_status joint_record(const pose_rig *rig, int joint, const void *in, const void *out,
                                const char *fn, const pose__clinical_record **r)
{
    if (!rig || !in || !out)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: NULL argument", fn);
    if (joint < 0 || (size_t)joint >= rig->joint_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: joint %d out of range (%zu joints)", fn,
                          joint, rig->joint_count);
    *r = pose__joint_clinical(rig, (size_t)joint);
    if (!*r)
        return pose__fail(POSE_ERR_UNSUPPORTED, "%s: joint %d '%s' has no clinical data in this "
                          "rig", fn, joint, pose__joint_name(rig, (size_t)joint));
    return POSE_OK;
}

pose_status pose_clinical_to_local(const pose_rig *rig, int joint, const float deg[3],
                                   float quat_xyzw[4])
{
    pose__clear_error();
    const pose__clinical_record *r;
    pose_status st = joint_record(rig, joint, deg, quat_xyzw, "pose_clinical_to_local", &r);
    if (st != POSE_OK)
        return st;
    if (!finite_n(deg, 3))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_clinical_to_local: joint %d: angle not finite", joint);
    pose__clinical_frame f;
    pose__clinical_frame_of(r, &f);
    double d[3] = {deg[0], deg[1], deg[2]}, q[4];
    pose__clinical_to_local(&f, d, q);
    for (int i = 0; i < 4; i++)
        quat_xyzw[i] = (float)q[i];
    return POSE_OK;
}

pose_status pose_local_to_clinical(const pose_rig *rig, int joint, const float quat_xyzw[4],
                                   const float hint_deg[3], float deg[3])
{
    pose__clear_error();
    const pose__clinical_record *r;
    pose_status st = joint_record(rig, joint, quat_xyzw, deg, "pose_local_to_clinical", &r);
    if (st != POSE_OK)
        return st;
    double q[4] = {quat_xyzw[0], quat_xyzw[1], quat_xyzw[2], quat_xyzw[3]};
    if (!finite_n(quat_xyzw, 4) || !(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] > 0.0) ||
        (hint_deg && !finite_n(hint_deg, 3)))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_local_to_clinical: joint %d: "
                          "quaternion zero or not finite, or hint not finite", joint);
    pose__clinical_frame f;
    pose__clinical_frame_of(r, &f);
    double hint[3] = {0.0, 0.0, 0.0}, d[3];
    if (hint_deg)
        for (int i = 0; i < 3; i++)
            hint[i] = hint_deg[i];
    pose__clinical_range range; /* the rig's, not any state's (pose_set_joint_range) */
    pose__clinical_range_of(r, &range);
    pose__clinical_from_local(&f, &range, q, hint_deg ? POSE__PICK_HINT : POSE__PICK_INSIDE, hint, d);
    for (int i = 0; i < 3; i++)
        deg[i] = (float)d[i];
    return POSE_OK;
}

void pose_euler_to_quat(const float deg[3], pose_euler_order order, float quat_xyzw[4])
{
    if (!deg || !quat_xyzw)
        return;
    if ((int)order < POSE_EULER_XYZ || (int)order > POSE_EULER_ZYX) {
        quat_xyzw[0] = quat_xyzw[1] = quat_xyzw[2] = 0.0f;
        quat_xyzw[3] = 1.0f;
        return;
    }
    pose__euler_to_quat(deg, (int)order, quat_xyzw);
}

void pose_quat_to_euler(const float quat_xyzw[4], pose_euler_order order, float deg[3])
{
    if (!deg || !quat_xyzw)
        return;
    if ((int)order < POSE_EULER_XYZ || (int)order > POSE_EULER_ZYX) {
        deg[0] = deg[1] = deg[2] = 0.0f;
        return;
    }
    pose__quat_to_euler(quat_xyzw, (int)order, deg);
}
