/* SPDX-License-Identifier: Apache-2.0 */
/* pose_state in clinical angles: the clinical setter and getter, the neutral
 * posture, and the clinical range of motion that every setter of a joint
 * with clinical data goes through (the state's own: pose_set_joint_range,
 * state_range.c). The state keeps each such joint's last
 * angles, so a getter returns the triple that was asked for rather than
 * whichever of the two equivalent triples a decomposition finds. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "clinical_math.h"
#include "error.h"
#include "state_internal.h"

/* Excess below this many degrees is float noise from the decomposition,
 * not a request past the range (as for rest-frame limits). */
#define CLAMP_TOLERANCE_DEG 1e-3

/* Clamp the limited angles (already moved by whole turns nearest their
 * range) to the range; on a clamp, say which angles and by how much. */
static int clamp_clinical(int joint, const char *joint_name, const pose__clinical_record *r,
                          const pose__clinical_range *range, double deg[3])
{
    char msg[POSE__ERROR_SIZE];
    size_t len = 0;
    int clamped = 0;
    for (int a = 0; a < 3; a++) {
        if (!(range->limit_flags & (1u << a)))
            continue;
        double v = deg[a], c = fmin(fmax(v, (double)range->min_deg[a]), (double)range->max_deg[a]);
        if (fabs(c - v) <= CLAMP_TOLERANCE_DEG)
            continue;
        int n = snprintf(msg + len, sizeof msg - len, "%s%s %.2f clamped to %.2f by %.2f [%.2f, %.2f]",
                         clamped ? ", " : "", r->names[a], v, c, fabs(v - c),
                         (double)range->min_deg[a], (double)range->max_deg[a]);
        if (n > 0 && (size_t)n < sizeof msg - len)
            len += (size_t)n;
        deg[a] = c;
        clamped = 1;
    }
    if (clamped)
        pose__set_error("joint %d '%s': %s degrees from neutral (clinical range of motion)", joint,
                        joint_name, msg);
    return clamped;
}

static void store(pose_state *st, int joint, const double q[4], const double deg[3])
{
    for (int i = 0; i < 4; i++)
        st->local[joint][i] = (float)q[i];
    for (int i = 0; i < 3; i++)
        st->clinical[joint][i] = (float)deg[i];
}

pose_status pose__state_store_clinical(pose_state *st, int joint, const float q[4])
{
    const pose__clinical_record *r = pose__joint_clinical(st->rig, (size_t)joint);
    pose__clinical_frame f;
    pose__clinical_frame_of(r, &f);
    double qd[4] = {q[0], q[1], q[2], q[3]}, deg[3];
    const pose__clinical_range *range = &st->ranges[joint];
    pose__clinical_from_local(&f, range, qd, POSE__PICK_NEAREST_LIMITS, NULL, deg);
    int clamped = clamp_clinical(joint, pose__joint_name(st->rig, (size_t)joint), r, range, deg);
    if (clamped)
        pose__clinical_to_local(&f, deg, qd);
    store(st, joint, qd, deg);
    return clamped ? POSE_CLAMPED : POSE_OK;
}

/* Set joint `joint` (with clinical data) from angles: limited angles move by
 * whole turns nearest their range, then clamp. */
static pose_status set_clinical(pose_state *st, int joint, const pose__clinical_record *r,
                                const double want[3])
{
    double deg[3] = {want[0], want[1], want[2]}, q[4];
    const pose__clinical_range *range = &st->ranges[joint];
    pose__clinical_fit(range, deg);
    int clamped = clamp_clinical(joint, pose__joint_name(st->rig, (size_t)joint), r, range, deg);
    pose__clinical_frame f;
    pose__clinical_frame_of(r, &f);
    pose__clinical_to_local(&f, deg, q);
    store(st, joint, q, deg);
    return clamped ? POSE_CLAMPED : POSE_OK;
}

static pose_status check_clinical_joint(const pose_state *st, int joint, const void *ptr,
                                        const char *fn, const pose__clinical_record **r)
{
    if (!st || !ptr)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: %s is NULL", fn, !st ? "state" : "value");
    if (joint < 0 || (size_t)joint >= st->rig->joint_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: joint %d out of range (%zu joints)", fn,
                          joint, st->rig->joint_count);
    *r = pose__joint_clinical(st->rig, (size_t)joint);
    if (!*r)
        return pose__fail(POSE_ERR_UNSUPPORTED, "%s: joint %d '%s' has no clinical data in this "
                          "rig", fn, joint, pose__joint_name(st->rig, (size_t)joint));
    return POSE_OK;
}

pose_status pose_set_joint_clinical(pose_state *st, int joint, const float deg[3])
{
    pose__clear_error();
    const pose__clinical_record *r;
    pose_status s = check_clinical_joint(st, joint, deg, "pose_set_joint_clinical", &r);
    if (s != POSE_OK)
        return s;
    if (!isfinite(deg[0]) || !isfinite(deg[1]) || !isfinite(deg[2]))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_set_joint_clinical: joint %d: angle not finite", joint);
    double want[3] = {deg[0], deg[1], deg[2]};
    return set_clinical(st, joint, r, want);
}

pose_status pose_get_joint_clinical(const pose_state *st, int joint, float deg[3])
{
    pose__clear_error();
    const pose__clinical_record *r;
    pose_status s = check_clinical_joint(st, joint, deg, "pose_get_joint_clinical", &r);
    if (s != POSE_OK)
        return s;
    memcpy(deg, st->clinical[joint], sizeof(float[3]));
    return POSE_OK;
}

pose_status pose_set_neutral(pose_state *st)
{
    pose__clear_error();
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_neutral: state is NULL");
    static const double zero[3] = {0.0, 0.0, 0.0};
    pose_status result = POSE_OK;
    for (size_t j = 0; j < st->rig->joint_count; j++) {
        const pose__clinical_record *r = pose__joint_clinical(st->rig, j);
        if (!r) {
            pose__quat_identity(st->local[j]);
            continue;
        }
        /* A range of motion without 0 clamps the neutral posture, and says so. */
        if (set_clinical(st, (int)j, r, zero) == POSE_CLAMPED)
            result = POSE_CLAMPED;
    }
    pose__xform_identity(&st->root);
    return result;
}

void pose__state_rest_clinical(pose_state *st)
{
    for (size_t j = 0; j < st->rig->joint_count; j++) {
        const pose__clinical_record *r = pose__joint_clinical(st->rig, j);
        if (!r)
            continue;
        pose__clinical_frame f;
        pose__clinical_frame_of(r, &f);
        static const double identity[4] = {0.0, 0.0, 0.0, 1.0};
        double deg[3];
        pose__clinical_from_local(&f, &st->ranges[j], identity, POSE__PICK_NEAREST_LIMITS, NULL, deg);
        for (int i = 0; i < 3; i++)
            st->clinical[j][i] = (float)deg[i];
    }
}
