/* SPDX-License-Identifier: Apache-2.0 */
/* Double-precision reference math for the runtime tests. */
#ifndef POSE_TEST_MATH_H
#define POSE_TEST_MATH_H

#include <math.h>

typedef struct dx {
    double q[4]; /* x y z w */
    double t[3];
} dx;

static inline void dq_mul(double r[4], const double a[4], const double b[4])
{
    double x = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    double y = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    double z = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    double w = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
    r[0] = x; r[1] = y; r[2] = z; r[3] = w;
}

static inline void dq_rot(double out[3], const double q[4], const double v[3])
{
    double p[4] = {v[0], v[1], v[2], 0.0}, c[4] = {-q[0], -q[1], -q[2], q[3]}, t[4];
    dq_mul(t, q, p);
    dq_mul(p, t, c);
    out[0] = p[0]; out[1] = p[1]; out[2] = p[2];
}

/* axis-angle quaternion (axis need not be unit), angle in degrees */
static inline void dq_axis(double q[4], double ax, double ay, double az, double deg)
{
    double n = sqrt(ax * ax + ay * ay + az * az), h = 0.5 * deg * 3.14159265358979323846 / 180.0;
    q[0] = ax / n * sin(h); q[1] = ay / n * sin(h); q[2] = az / n * sin(h); q[3] = cos(h);
}

/* r = a o b */
static inline dx dx_compose(const dx *a, const dx *b)
{
    dx r;
    dq_mul(r.q, a->q, b->q);
    dq_rot(r.t, a->q, b->t);
    for (int i = 0; i < 3; i++)
        r.t[i] += a->t[i];
    return r;
}

static inline dx dx_inverse(const dx *a)
{
    dx r;
    r.q[0] = -a->q[0]; r.q[1] = -a->q[1]; r.q[2] = -a->q[2]; r.q[3] = a->q[3];
    dq_rot(r.t, r.q, a->t);
    for (int i = 0; i < 3; i++)
        r.t[i] = -r.t[i];
    return r;
}

static inline void dx_apply(double out[3], const dx *a, const double p[3])
{
    dq_rot(out, a->q, p);
    for (int i = 0; i < 3; i++)
        out[i] += a->t[i];
}

/* |a.q| vs |b.q| up to sign */
static inline double dq_dist(const double a[4], const float b[4])
{
    double p = 0, m = 0;
    for (int i = 0; i < 4; i++) {
        p = fmax(p, fabs(a[i] - b[i]));
        m = fmax(m, fabs(a[i] + b[i]));
    }
    return fmin(p, m);
}

/* cmocka's assert_float_equal lets NaN through; this does not. */
#define assert_near(a, b, tol) assert_true(fabs((double)(a) - (double)(b)) <= (double)(tol))

#endif /* POSE_TEST_MATH_H */
