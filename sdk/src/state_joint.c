/* SPDX-License-Identifier: Apache-2.0 */
/* pose_state joint inputs: rotations (quaternion or Euler), limits, root. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "error.h"
#include "rt_euler.h"
#include "state_internal.h"

static const char k_axis[3] = {'x', 'y', 'z'};

/* Excess below this many degrees is float noise from the Euler decomposition
 * (a straight knee reads as y = -0.00), not a request past the limit. */
#define POSE__LIMIT_TOLERANCE_DEG 1e-3f

static int finite4(const float *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* Wrap an angle in degrees to (-180, 180]. */
static float wrap_deg(float a)
{
    double w = fmod((double)a, 360.0);
    if (w <= -180.0)
        w += 360.0;
    else if (w > 180.0)
        w -= 360.0;
    return (float)w;
}

/* Clamp Euler angles (in the limits' order) to joint j's limits; on a clamp,
 * say which axes and by how much, and return 1. */
static int clamp_angles(const pose_state *st, int j, float deg[3])
{
    const pose__joint_limit *lim = &st->rig->joint_limits[j];
    char msg[POSE__ERROR_SIZE];
    size_t len = 0;
    int clamped = 0;
    for (int a = 0; a < 3; a++) {
        if (!(lim->flags & (1u << a)))
            continue;
        float v = deg[a], c = v;
        if (c < lim->min_deg[a])
            c = lim->min_deg[a];
        if (c > lim->max_deg[a])
            c = lim->max_deg[a];
        if (fabsf(c - v) <= POSE__LIMIT_TOLERANCE_DEG)
            continue;
        int n = snprintf(msg + len, sizeof msg - len, "%s%c %.2f clamped to %.2f [%.2f, %.2f]",
                         clamped ? ", " : "", k_axis[a], (double)v, (double)c,
                         (double)lim->min_deg[a], (double)lim->max_deg[a]);
        if (n > 0 && (size_t)n < sizeof msg - len)
            len += (size_t)n;
        deg[a] = c;
        clamped = 1;
    }
    if (clamped)
        pose__set_error("joint %d '%s': %s degrees (limits in %s order)", j,
                        pose__joint_name(st->rig, (size_t)j), msg,
                        pose__euler_name((int)lim->order));
    return clamped;
}

static pose_status check_joint(const pose_state *st, int joint, const void *ptr, const char *fn)
{
    if (!st || !ptr)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: %s is NULL", fn,
                          !st ? "state" : "value");
    if (joint < 0 || (size_t)joint >= st->rig->joint_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: joint %d out of range (%zu joints)",
                          fn, joint, st->rig->joint_count);
    return POSE_OK;
}

/* Degrees by which angles {x, y, z} lie outside the limits, summed over axes. */
static float limit_excess(const pose__joint_limit *lim, const float deg[3])
{
    float e = 0.0f;
    for (int a = 0; a < 3; a++) {
        if (!(lim->flags & (1u << a)))
            continue;
        if (deg[a] < lim->min_deg[a])
            e += lim->min_deg[a] - deg[a];
        else if (deg[a] > lim->max_deg[a])
            e += deg[a] - lim->max_deg[a];
    }
    return e;
}

/* Every rotation has two Tait-Bryan triples in an order ABC: (a, b, c) and
 * (a + 180, 180 - b, c + 180). The decomposition returns the one with the
 * middle angle in [-90, 90]; take the other when it is closer to the limits,
 * so that e.g. a knee bent 120 degrees about a middle axis is read as a bend
 * rather than as the two other axes turned by 180 degrees. */
static void euler_nearest_limits(const pose__joint_limit *lim, float deg[3])
{
    int axes[3];
    pose__euler_axes((int)lim->order, axes);
    float alt[3];
    alt[axes[0]] = wrap_deg(deg[axes[0]] + 180.0f);
    alt[axes[1]] = wrap_deg(180.0f - deg[axes[1]]);
    alt[axes[2]] = wrap_deg(deg[axes[2]] + 180.0f);
    if (limit_excess(lim, alt) < limit_excess(lim, deg))
        memcpy(deg, alt, sizeof alt);
}

pose_status pose__state_store_joint(pose_state *st, int joint, float q[4])
{
    if (pose__joint_clinical(st->rig, (size_t)joint))
        return pose__state_store_clinical(st, joint, q);
    pose_status s = POSE_OK;
    const pose__joint_limit *lim = &st->rig->joint_limits[joint];
    if (lim->flags & (POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z)) {
        float deg[3];
        pose__quat_to_euler(q, (int)lim->order, deg);
        euler_nearest_limits(lim, deg);
        if (clamp_angles(st, joint, deg)) {
            pose__euler_to_quat(deg, (int)lim->order, q);
            s = POSE_CLAMPED;
        }
    }
    memcpy(st->local[joint], q, sizeof(float[4]));
    return s;
}

pose_status pose_set_joint(pose_state *st, int joint, const float quat_xyzw[4])
{
    pose__clear_error();
    pose_status s = check_joint(st, joint, quat_xyzw, "pose_set_joint");
    if (s < 0)
        return s;
    float q[4] = {quat_xyzw[0], quat_xyzw[1], quat_xyzw[2], quat_xyzw[3]};
    if (!finite4(q, 4) || pose__quat_normalize(q) == 0.0f)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_set_joint: joint %d: quaternion is zero or not finite", joint);
    return pose__state_store_joint(st, joint, q);
}

pose_status pose_set_joint_euler(pose_state *st, int joint, const float deg[3],
                                 pose_euler_order order)
{
    pose__clear_error();
    pose_status s = check_joint(st, joint, deg, "pose_set_joint_euler");
    if (s < 0)
        return s;
    if ((int)order < POSE_EULER_XYZ || (int)order > POSE_EULER_ZYX)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_joint_euler: unknown order %d",
                          (int)order);
    if (!finite4(deg, 3))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_set_joint_euler: joint %d: angle not finite", joint);
    float q[4];
    const pose__joint_limit *lim = &st->rig->joint_limits[joint];
    if ((lim->flags & 7u) && (int)lim->order == (int)order &&
        !pose__joint_clinical(st->rig, (size_t)joint)) {
        /* Same order as the limits: clamp the angles as given (a decomposition
         * could pick the other, equivalent triple and clamp the wrong axis). */
        float a[3] = {wrap_deg(deg[0]), wrap_deg(deg[1]), wrap_deg(deg[2])};
        int clamped = clamp_angles(st, joint, a);
        pose__euler_to_quat(a, (int)order, q);
        memcpy(st->local[joint], q, sizeof q);
        return clamped ? POSE_CLAMPED : POSE_OK;
    }
    pose__euler_to_quat(deg, (int)order, q);
    return pose__state_store_joint(st, joint, q);
}

pose_status pose_get_joint(const pose_state *st, int joint, float quat_xyzw[4])
{
    pose__clear_error();
    pose_status s = check_joint(st, joint, quat_xyzw, "pose_get_joint");
    if (s < 0)
        return s;
    memcpy(quat_xyzw, st->local[joint], sizeof(float[4]));
    return POSE_OK;
}

pose_status pose_set_root(pose_state *st, const float translation[3], const float quat_xyzw[4])
{
    pose__clear_error();
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_root: state is NULL");
    pose__xform root;
    pose__xform_identity(&root);
    if (translation) {
        if (!finite4(translation, 3))
            return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_root: translation not finite");
        memcpy(root.t, translation, sizeof root.t);
    }
    if (quat_xyzw) {
        memcpy(root.q, quat_xyzw, sizeof root.q);
        if (!finite4(root.q, 4) || pose__quat_normalize(root.q) == 0.0f)
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "pose_set_root: quaternion is zero or not finite");
    }
    st->root = root;
    return POSE_OK;
}

pose_status pose_reset(pose_state *st)
{
    pose__clear_error();
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_reset: state is NULL");
    for (size_t j = 0; j < st->rig->joint_count; j++)
        pose__quat_identity(st->local[j]);
    pose__state_rest_clinical(st);
    pose__xform_identity(&st->root);
    return POSE_OK;
}
