/* SPDX-License-Identifier: Apache-2.0 */
/* The `clinical` section's records: what every rig's clinical data must
 * satisfy (whether loaded or created from a description), and the query. */
#include <math.h>
#include <string.h>

#include "error.h"
#include "rig_io.h"

/** Tolerance on |q| - 1 for the neutral rotation and on unit/orthogonal axes:
 *  the rest rotations' tolerance. Axes are orthonormalized before use. */
#define CLINICAL_TOLERANCE 1e-4

static const char k_sec[] = "clinical";
static const char *const k_angle[3] = {"flexion", "abduction", "rotation"};

static bool finite_n(const float *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return false;
    return true;
}

static double dot3(const float a[3], const float b[3])
{
    return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
}

static bool all_zero(const void *p, size_t n)
{
    const uint8_t *b = p;
    for (size_t i = 0; i < n; i++)
        if (b[i])
            return false;
    return true;
}

static pose_status check_names(const pose__source *src, const pose__clinical_record *r, size_t j,
                               const char *joint)
{
    for (int k = 0; k < 3; k++) {
        size_t n = strnlen(r->names[k], POSE__CLINICAL_NAME_SIZE);
        if (n == POSE__CLINICAL_NAME_SIZE)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, r->names[k],
                                     "joint %zu ('%s'): name of the %s angle is not "
                                     "NUL-terminated within %d bytes", j, joint, k_angle[k],
                                     POSE__CLINICAL_NAME_SIZE);
        if (n == 0)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, r->names[k],
                                     "joint %zu ('%s'): empty name for the %s angle", j, joint,
                                     k_angle[k]);
    }
    return POSE_OK;
}

static pose_status check_frame(const pose__source *src, const pose__clinical_record *r, size_t j,
                               const char *joint)
{
    const float *q = r->neutral;
    if (!finite_n(q, 4) || !finite_n(&r->axes[0][0], 9))
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, q,
                                 "joint %zu ('%s'): neutral rotation or axes not finite", j, joint);
    double len = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] +
                      (double)q[3] * q[3]);
    if (fabs(len - 1.0) > CLINICAL_TOLERANCE)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, q,
                                 "joint %zu ('%s'): neutral rotation has length %.6g, expected a "
                                 "unit quaternion (tolerance 1e-4)", j, joint, len);
    for (int a = 0; a < 3; a++) {
        double n = sqrt(dot3(r->axes[a], r->axes[a]));
        if (fabs(n - 1.0) > CLINICAL_TOLERANCE)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, r->axes[a],
                                     "joint %zu ('%s'): %s axis has length %.6g, expected 1 "
                                     "(tolerance 1e-4)", j, joint, k_angle[a], n);
        for (int b = 0; b < a; b++) {
            double d = dot3(r->axes[a], r->axes[b]);
            if (fabs(d) > CLINICAL_TOLERANCE)
                return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, r->axes[a],
                                         "joint %zu ('%s'): %s and %s axes are not orthogonal "
                                         "(dot product %.6g, tolerance 1e-4)", j, joint,
                                         k_angle[b], k_angle[a], d);
        }
    }
    return POSE_OK;
}

static pose_status check_limits(const pose__source *src, const pose__clinical_record *r, size_t j,
                                const char *joint)
{
    if (r->limit_flags & ~(uint32_t)(POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z))
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, &r->limit_flags,
                                 "joint %zu ('%s'): limit flags 0x%x unknown", j, joint,
                                 r->limit_flags);
    for (int a = 0; a < 3; a++)
        if ((r->limit_flags & (1u << a)) &&
            (!isfinite(r->limit_min_deg[a]) || !isfinite(r->limit_max_deg[a]) ||
             r->limit_min_deg[a] > r->limit_max_deg[a]))
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, &r->limit_min_deg[a],
                                     "joint %zu ('%s'): range of %s is [%g, %g]", j, joint,
                                     k_angle[a], (double)r->limit_min_deg[a],
                                     (double)r->limit_max_deg[a]);
    return POSE_OK;
}

pose_status pose__clinical_validate(const pose_rig *rig, const pose__source *src)
{
    if (!rig->clinical)
        return POSE_OK;
    for (size_t j = 0; j < rig->joint_count; j++) {
        const pose__clinical_record *r = &rig->clinical[j];
        const char *joint = pose__joint_name(rig, j);
        if (r->flags == 0) {
            if (!all_zero(r, sizeof *r))
                return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, r,
                                         "joint %zu ('%s'): record without clinical data (flags "
                                         "0) has non-zero bytes", j, joint);
            continue;
        }
        if (r->flags & ~(uint32_t)POSE_CLINICAL_DEFINED)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, r,
                                     "joint %zu ('%s'): flags 0x%x unknown", j, joint, r->flags);
        if (!all_zero(r->reserved, sizeof r->reserved))
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, k_sec, r->reserved,
                                     "joint %zu ('%s'): reserved bytes are not zero", j, joint);
        pose_status st = check_frame(src, r, j, joint);
        if (st == POSE_OK)
            st = check_limits(src, r, j, joint);
        if (st == POSE_OK)
            st = check_names(src, r, j, joint);
        if (st != POSE_OK)
            return st;
    }
    return POSE_OK;
}

pose_status pose_rig_joint_clinical(const pose_rig *rig, int joint, pose_joint_clinical *out)
{
    pose__clear_error();
    if (!rig || !out || joint < 0 || (size_t)joint >= rig->joint_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_rig_joint_clinical: joint %d out of "
                          "range (%zu joints) or NULL argument", joint, rig ? rig->joint_count : 0);
    const pose__clinical_record *r = pose__joint_clinical(rig, (size_t)joint);
    if (!r)
        return pose__fail(POSE_ERR_UNSUPPORTED, "joint %d '%s': the rig has no clinical data for "
                          "it (no neutral posture or clinical axes)", joint,
                          pose__joint_name(rig, (size_t)joint));
    memcpy(out->neutral, r->neutral, sizeof out->neutral);
    memcpy(out->axes, r->axes, sizeof out->axes);
    for (int k = 0; k < 3; k++)
        out->names[k] = r->names[k];
    out->limit_flags = r->limit_flags;
    memcpy(out->limit_min_deg, r->limit_min_deg, sizeof out->limit_min_deg);
    memcpy(out->limit_max_deg, r->limit_max_deg, sizeof out->limit_max_deg);
    out->flags = r->flags;
    return POSE_OK;
}
