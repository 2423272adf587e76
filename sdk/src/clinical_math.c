/* SPDX-License-Identifier: Apache-2.0 */
#include "clinical_math.h"

#include <math.h>

#include "rt_euler.h"

static void qmul(const double a[4], const double b[4], double r[4])
{
    double x = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    double y = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    double z = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    double w = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
    r[0] = x; r[1] = y; r[2] = z; r[3] = w;
}

static void normalize(double *v, int n)
{
    double s = 0.0;
    for (int i = 0; i < n; i++)
        s += v[i] * v[i];
    s = sqrt(s);
    for (int i = 0; i < n; i++)
        v[i] /= s;
}

/* Quaternion of the rotation matrix whose columns are c[0], c[1], c[2]
 * (Shepperd: divide by the largest of the four candidates). */
static void quat_of_columns(const double c[3][3], double q[4])
{
    double m00 = c[0][0], m11 = c[1][1], m22 = c[2][2];
    double m01 = c[1][0], m10 = c[0][1], m02 = c[2][0], m20 = c[0][2], m12 = c[2][1], m21 = c[1][2];
    double tr = m00 + m11 + m22;
    if (tr > 0.0) {
        double s = 2.0 * sqrt(tr + 1.0);
        q[3] = 0.25 * s; q[0] = (m21 - m12) / s; q[1] = (m02 - m20) / s; q[2] = (m10 - m01) / s;
    } else if (m00 > m11 && m00 > m22) {
        double s = 2.0 * sqrt(1.0 + m00 - m11 - m22);
        q[3] = (m21 - m12) / s; q[0] = 0.25 * s; q[1] = (m01 + m10) / s; q[2] = (m02 + m20) / s;
    } else if (m11 > m22) {
        double s = 2.0 * sqrt(1.0 + m11 - m00 - m22);
        q[3] = (m02 - m20) / s; q[0] = (m01 + m10) / s; q[1] = 0.25 * s; q[2] = (m12 + m21) / s;
    } else {
        double s = 2.0 * sqrt(1.0 + m22 - m00 - m11);
        q[3] = (m10 - m01) / s; q[0] = (m02 + m20) / s; q[1] = (m12 + m21) / s; q[2] = 0.25 * s;
    }
    normalize(q, 4);
}

void pose__clinical_frame_of(const pose__clinical_record *r, pose__clinical_frame *f)
{
    for (int i = 0; i < 4; i++)
        f->neutral[i] = r->neutral[i];
    normalize(f->neutral, 4);
    double c[3][3];
    for (int i = 0; i < 3; i++) {
        c[0][i] = r->axes[0][i];
        c[1][i] = r->axes[1][i];
    }
    normalize(c[0], 3);
    double d = c[0][0] * c[1][0] + c[0][1] * c[1][1] + c[0][2] * c[1][2];
    for (int i = 0; i < 3; i++)
        c[1][i] -= d * c[0][i];
    normalize(c[1], 3);
    c[2][0] = c[0][1] * c[1][2] - c[0][2] * c[1][1];
    c[2][1] = c[0][2] * c[1][0] - c[0][0] * c[1][2];
    c[2][2] = c[0][0] * c[1][1] - c[0][1] * c[1][0];
    double h = c[2][0] * r->axes[2][0] + c[2][1] * r->axes[2][1] + c[2][2] * r->axes[2][2];
    f->handed = h < 0.0 ? -1.0 : 1.0;
    quat_of_columns(c, f->basis);
}

void pose__clinical_to_local(const pose__clinical_frame *f, const double deg[3], double q[4])
{
    double e[3] = {deg[0], deg[1], f->handed * deg[2]}, r[4], t[4];
    pose__euler_to_quat_d(e, 0 /* XYZ */, r);
    double bc[4] = {-f->basis[0], -f->basis[1], -f->basis[2], f->basis[3]};
    qmul(f->basis, r, t);
    qmul(t, bc, r);
    qmul(r, f->neutral, q);
    normalize(q, 4);
}

/* Wrap to (-180, 180]. */
static double wrap(double a)
{
    double w = fmod(a, 360.0);
    if (w <= -180.0)
        w += 360.0;
    else if (w > 180.0)
        w -= 360.0;
    return w;
}

/* Move `a` by whole turns into [lo, hi], or to the representative nearest to
 * it; returns the distance left (0 inside). */
static double fit_angle(double *a, double lo, double hi)
{
    if (*a >= lo && *a <= hi)
        return 0.0;
    double x = lo + fmod(*a - lo, 360.0);
    if (x < lo)
        x += 360.0;
    if (x <= hi) {
        *a = x;
        return 0.0;
    }
    double above = x - hi, below = lo - (x - 360.0);
    *a = above <= below ? x : x - 360.0;
    return above <= below ? above : below;
}

void pose__clinical_range_of(const pose__clinical_record *r, pose__clinical_range *out)
{
    out->limit_flags = r->limit_flags & (POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z);
    for (int a = 0; a < 3; a++) {
        int limited = (out->limit_flags >> a) & 1u;
        out->min_deg[a] = limited ? r->limit_min_deg[a] : -180.0f;
        out->max_deg[a] = limited ? r->limit_max_deg[a] : 180.0f;
    }
}

double pose__clinical_fit(const pose__clinical_range *r, double deg[3])
{
    double excess = 0.0;
    for (int a = 0; a < 3; a++)
        if (r->limit_flags & (1u << a))
            excess += fit_angle(&deg[a], r->min_deg[a], r->max_deg[a]);
    return excess;
}

static double excess_of(const pose__clinical_range *r, const double deg[3])
{
    double copy[3] = {deg[0], deg[1], deg[2]};
    return pose__clinical_fit(r, copy);
}

static double hint_distance(const double deg[3], const double hint[3])
{
    return fabs(wrap(deg[0] - hint[0])) + fabs(wrap(deg[1] - hint[1])) + fabs(wrap(deg[2] - hint[2]));
}

/* Primary triple (abduction in [-90, 90]) of q; 1 at gimbal lock, where
 * deg[2] is 0 and deg[0] carries the whole free rotation. */
static int decompose(const pose__clinical_frame *f, const double q[4], double deg[3])
{
    double nc[4] = {-f->neutral[0], -f->neutral[1], -f->neutral[2], f->neutral[3]};
    double bc[4] = {-f->basis[0], -f->basis[1], -f->basis[2], f->basis[3]}, m[4], t[4];
    qmul(q, nc, m);
    qmul(bc, m, t);
    qmul(t, f->basis, m);
    int locked = pose__quat_to_euler_d(m, 0 /* XYZ */, deg);
    deg[2] *= f->handed;
    return locked;
}

void pose__clinical_from_local(const pose__clinical_frame *f, const pose__clinical_range *r,
                               const double q[4], pose__clinical_pick pick, const double hint[3],
                               double deg[3])
{
    double d[3];
    if (decompose(f, q, d)) {
        /* Rx(a) Ry(+-90) Rz(c) = Rx(a +- c) Ry(+-90): choose c, a follows. */
        double c = 0.0;
        if (pick == POSE__PICK_HINT)
            c = hint[2];
        else if (r->limit_flags & POSE_LIMIT_Z)
            fit_angle(&c, r->min_deg[2], r->max_deg[2]);
        d[0] = wrap(d[0] - (d[1] > 0.0 ? 1.0 : -1.0) * f->handed * c);
        d[2] = c;
    } else {
        double alt[3] = {wrap(d[0] + 180.0), wrap(180.0 - d[1]), wrap(d[2] + 180.0)};
        int take_alt;
        if (pick == POSE__PICK_HINT)
            take_alt = hint_distance(alt, hint) < hint_distance(d, hint);
        else if (pick == POSE__PICK_INSIDE)
            take_alt = excess_of(r, d) > 0.0 && excess_of(r, alt) == 0.0;
        else
            take_alt = excess_of(r, alt) < excess_of(r, d);
        if (take_alt)
            for (int a = 0; a < 3; a++)
                d[a] = alt[a];
    }
    if (pick == POSE__PICK_HINT) /* whole turns: d - hint in [-180, 180) */
        for (int a = 0; a < 3; a++)
            d[a] += 360.0 * ceil((hint[a] - d[a] - 180.0) / 360.0);
    else
        pose__clinical_fit(r, d);
    for (int a = 0; a < 3; a++)
        deg[a] = d[a];
}
