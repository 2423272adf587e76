/* SPDX-License-Identifier: Apache-2.0
 *
 * Neutral posture and clinical axes from the template and the fitted joints.
 *
 * Derivation. Q_j is joint j's rest frame in model space (fits[j].frame), P
 * its parent. FK: W_j = W_P (Q_P^-1 Q_j) L_j with L_j the local rotation
 * relative to the rest frame. The model-space motion of segment j,
 * D_j = W_j Q_j^-1 (rest model vector -> posed model vector), obeys
 *     D_j = D_P (Q_j L_j Q_j^-1).
 * Let A_j = D_P Q_j: the rest frame of j as its parent carries it (the
 * parent-attached frame). Then a local rotation R(a, t) (axis a in the rest
 * frame) is, in model space, R(A_j a, t) applied after the parent:
 *     D_j = D_P Q_j R(a,t) N Q_j^-1 = R(A_j a, t) D_P Q_j N Q_j^-1.
 * Hence, with every parent in its neutral posture (D_P = D_P^N; the root at
 * identity, as pose_set_neutral puts it):
 *  - neutral offset: G = the minimal model-space rotation taking the segment
 *    direction as the parents carry it, D_P^N s_j, onto the template's
 *    "neutral" n_j; D_j^N = G D_P^N, so Q_j N Q_j^-1 = D_P^-1 G D_P, i.e.
 *        N_j = A_j^-1 G A_j;
 *  - axes: a model-space axis v of the neutral posture is a = A_j^-1 v in
 *    the rest frame, and local = R(a0,f) R(a1,b) R(a2,r) N_j turns the
 *    neutral segment by R(v0,f) R(v1,b) R(v2,r): flexion about the axis
 *    fixed in the parent, rotation about the segment's own long axis.
 *  - a hinge's axis is the rest frame's y, fixed in the parent (the
 *    humerus' trochlea, the femoral condyles): v0 = A_j e_y, so a0 = +-e_y
 *    exactly, whatever N_j does to the child.
 *
 * Axes in the neutral posture: the rotation axis follows the segment (joint
 * -> child joint, from the fitted centres); a segment with no child joint (the
 * hand, the foot, the head) turns about its parent segment's line, because the
 * principal axis of a curled hand or a round skull is no anatomical axis.
 * Flexion is the template's nominal axis made perpendicular to the segment,
 * except for hinges: the fitted axis stays exact and the rotation axis is made
 * perpendicular to it instead. Abduction completes the frame; the template's
 * vectors only choose the signs.
 */
#include "clinical_fit.h"

#include <math.h>
#include <string.h>

#define RAD2DEG 57.29577951308232

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double r[3])
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}

static int normalize3(double a[3])
{
    double n = sqrt(dot3(a, a));
    if (!(n > 1e-9))
        return 0;
    for (int k = 0; k < 3; k++)
        a[k] /= n;
    return 1;
}

static void mat_mul(const double a[3][3], const double b[3][3], double r[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
}

static void mat_vec(const double m[3][3], const double v[3], double r[3])
{
    for (int i = 0; i < 3; i++)
        r[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
}

static void mat_tvec(const double m[3][3], const double v[3], double r[3])
{
    for (int i = 0; i < 3; i++)
        r[i] = m[0][i] * v[0] + m[1][i] * v[1] + m[2][i] * v[2];
}

static void mat_identity(double m[3][3])
{
    memset(m, 0, 9 * sizeof m[0][0]);
    m[0][0] = m[1][1] = m[2][2] = 1.0;
}

/* Rotation by `angle` about unit `axis` (Rodrigues). */
static void mat_axis_angle(const double axis[3], double angle, double m[3][3])
{
    double c = cos(angle), s = sin(angle), t = 1.0 - c;
    double x = axis[0], y = axis[1], z = axis[2];
    m[0][0] = t * x * x + c, m[0][1] = t * x * y - s * z, m[0][2] = t * x * z + s * y;
    m[1][0] = t * x * y + s * z, m[1][1] = t * y * y + c, m[1][2] = t * y * z - s * x;
    m[2][0] = t * x * z - s * y, m[2][1] = t * y * z + s * x, m[2][2] = t * z * z + c;
}

/* The minimal rotation taking unit u onto unit n. Antiparallel directions
 * have no minimal one; `hint` (a direction perpendicular-ish to both, the
 * template's flexion axis) picks the axis then. */
static void minimal_rotation(const double u[3], const double n[3], const double hint[3], double m[3][3])
{
    double axis[3];
    cross3(u, n, axis);
    double s = sqrt(dot3(axis, axis)), c = dot3(u, n);
    if (s < 1e-9 && c > 0) {
        mat_identity(m);
        return;
    }
    if (s < 1e-9) {
        double h = dot3(hint, u);
        for (int k = 0; k < 3; k++)
            axis[k] = hint[k] - h * u[k];
        normalize3(axis);
    } else {
        for (int k = 0; k < 3; k++)
            axis[k] /= s;
    }
    mat_axis_angle(axis, atan2(s, c), m);
}

static void vec_of(const float f[3], double d[3])
{
    for (int k = 0; k < 3; k++)
        d[k] = f[k];
}

/* Rest direction of the segment from joint j towards its child joint: the
 * child lying best along the frame's z axis (rig_fit.h builds z from it);
 * for a segment with no child joint, +-z (the segment's principal axis),
 * signed towards the template's neutral direction when there is one, else
 * away from the parent joint. Returns whether a child joint gave it. */
static int rest_segment(const pp_template *t, const pp_fit_joint *fits, size_t j, double s[3])
{
    double z[3] = {fits[j].frame[0][2], fits[j].frame[1][2], fits[j].frame[2][2]};
    double best = 0.5;
    int found = 0;
    for (size_t c = j + 1; c < t->joint_count; c++) {
        if (t->joints[c].parent != (int)j)
            continue;
        double d[3];
        for (int k = 0; k < 3; k++)
            d[k] = fits[c].centre[k] - fits[j].centre[k];
        if (normalize3(d) && fabs(dot3(d, z)) > best) {
            best = fabs(dot3(d, z));
            memcpy(s, d, sizeof d);
            found = 1;
        }
    }
    if (found)
        return 1;
    const pp_template_joint *tj = &t->joints[j];
    double away[3];
    if (tj->clinical.has_neutral) {
        vec_of(tj->clinical.neutral, away);
    } else {
        for (int k = 0; k < 3; k++)
            away[k] = tj->parent >= 0 ? fits[j].centre[k] - fits[tj->parent].centre[k] : z[k];
    }
    for (int k = 0; k < 3; k++)
        s[k] = dot3(z, away) < 0 ? -z[k] : z[k];
    return 0;
}

/* The clinical axes (model space, neutral posture) of joint j. */
static int fit_axes(const pp_template_joint *tj, const double A[3][3], const double distal[3],
                    double v[3][3], char *err, size_t err_size)
{
    const pp_template_clinical *k = &tj->clinical;
    double flex_t[3], abd_t[3], r[3], f[3], b[3];
    vec_of(k->flexion, flex_t);
    vec_of(k->abduction, abd_t);
    memcpy(r, distal, sizeof r);
    if (tj->rule == PP_FIT_HINGE) {
        double ey[3] = {0, 1, 0};
        mat_vec(A, ey, f);
        double agree = dot3(f, flex_t);
        if (fabs(agree) < 0.5)
            return pp_fail(err, err_size, POSE_ERR_INVALID_DATA,
                           "joint '%s': the fitted hinge axis is %.0f degrees from the template's "
                           "'clinical.flexion' in the neutral posture (more than 60)",
                           tj->name, acos(fabs(agree)) * RAD2DEG);
        for (int i = 0; i < 3; i++)
            f[i] = agree < 0 ? -f[i] : f[i];
        double s = dot3(r, f);
        for (int i = 0; i < 3; i++)
            r[i] -= s * f[i];
        if (!normalize3(r))
            return pp_fail(err, err_size, POSE_ERR_INVALID_DATA,
                           "joint '%s': the segment runs along the fitted hinge axis", tj->name);
    } else {
        double s = dot3(flex_t, r);
        if (fabs(s) > 0.866)
            return pp_fail(err, err_size, POSE_ERR_INVALID_DATA,
                           "joint '%s': the template's 'clinical.flexion' is within 30 degrees of the "
                           "segment's direction in the neutral posture",
                           tj->name);
        for (int i = 0; i < 3; i++)
            f[i] = flex_t[i] - s * r[i];
        normalize3(f);
    }
    cross3(r, f, b);
    double agree = dot3(b, abd_t);
    if (fabs(agree) < 0.5)
        return pp_fail(err, err_size, POSE_ERR_INVALID_DATA,
                       "joint '%s': the abduction axis (perpendicular to flexion and the segment) is "
                       "%.0f degrees from the template's 'clinical.abduction' (more than 60)",
                       tj->name, acos(fabs(agree)) * RAD2DEG);
    for (int i = 0; i < 3; i++) {
        v[0][i] = f[i];
        v[1][i] = agree < 0 ? -b[i] : b[i];
        v[2][i] = k->rotation_sign * r[i];
    }
    return POSE_OK;
}

int pp_clinical_fit(const pp_template *t, const pp_fit_joint *fits, pp_clinical_joint *out, char *err,
                    size_t err_size)
{
    if (!t || !fits || !out)
        return pp_fail(err, err_size, POSE_ERR_INVALID_ARGUMENT, "clinical fit: NULL argument");
    memset(out, 0, t->joint_count * sizeof *out);
    for (size_t j = 0; j < t->joint_count; j++) { /* parents come first */
        const pp_template_joint *tj = &t->joints[j];
        const pp_template_clinical *k = &tj->clinical;
        pp_clinical_joint *o = &out[j];
        o->c.neutral[3] = 1.0f;
        if (tj->parent < 0) { /* the root: identity in the neutral posture */
            mat_identity(o->neutral_motion);
            continue;
        }
        const pp_clinical_joint *p = &out[tj->parent];
        double A[3][3], G[3][3], s[3];
        mat_mul(p->neutral_motion, fits[j].frame, A);
        int has_child = rest_segment(t, fits, j, s);
        double carried[3];
        mat_vec(p->neutral_motion, s, carried);
        if (k->defined && k->has_neutral) {
            double n[3], hint[3];
            vec_of(k->neutral, n);
            vec_of(k->flexion, hint);
            minimal_rotation(carried, n, hint, G);
        } else {
            mat_identity(G);
        }
        mat_mul(G, p->neutral_motion, o->neutral_motion);
        o->neutral_deg = acos(fmax(-1.0, fmin(1.0, (G[0][0] + G[1][1] + G[2][2] - 1.0) / 2.0))) * RAD2DEG;
        /* A segment without a child joint turns about its parent's line (see
         * the top), unless the template says where it points or the parent
         * is the root (no line). */
        if (has_child || (k->defined && k->has_neutral) || t->joints[tj->parent].parent < 0)
            mat_vec(G, carried, o->distal);
        else
            memcpy(o->distal, p->distal, sizeof o->distal);
        if (!k->defined)
            continue;
        int rc = fit_axes(tj, A, o->distal, o->model_axes, err, err_size);
        if (rc < 0)
            return rc;
        /* N = A^-1 G A; axes a = A^-1 v (A is a rotation: A^-1 = A^T). */
        double GA[3][3], N[3][3];
        mat_mul(G, A, GA);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                N[r][c] = A[0][r] * GA[0][c] + A[1][r] * GA[1][c] + A[2][r] * GA[2][c];
        pp_quat_from_matrix(N, o->c.neutral);
        for (int a = 0; a < 3; a++) {
            double local[3];
            mat_tvec(A, o->model_axes[a], local);
            for (int i = 0; i < 3; i++)
                o->c.axes[a][i] = (float)local[i];
            o->c.names[a] = k->names[a][0] ? k->names[a] : NULL;
        }
        o->c.limit_flags = k->limit_flags;
        memcpy(o->c.limit_min_deg, k->limit_min_deg, sizeof o->c.limit_min_deg);
        memcpy(o->c.limit_max_deg, k->limit_max_deg, sizeof o->c.limit_max_deg);
        o->c.flags = POSE_CLINICAL_DEFINED;
    }
    return POSE_OK;
}
