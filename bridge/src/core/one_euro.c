/* SPDX-License-Identifier: Apache-2.0 */
#include "one_euro.h"

#include <math.h>

#include "pb_math.h"

double pb_one_euro_alpha(double fc, double te)
{
    double tau = 1.0 / (2.0 * PB_PI * fc);
    return 1.0 / (1.0 + tau / te);
}

void pb_one_euro_init(pb_one_euro *f, const pb_one_euro_params *p)
{
    f->p = *p;
    if (f->p.d_cutoff <= 0.0)
        f->p.d_cutoff = 1.0;
    f->x = f->dx = 0.0;
    f->primed = 0;
}

double pb_one_euro_step(pb_one_euro *f, double x, double te)
{
    if (f->p.min_cutoff <= 0.0)
        return x;
    if (!f->primed || !(te > 0.0)) {
        f->x = x;
        f->dx = 0.0;
        f->primed = 1;
        return x;
    }
    double dx = (x - f->x) / te;
    double ad = pb_one_euro_alpha(f->p.d_cutoff, te);
    f->dx = ad * dx + (1.0 - ad) * f->dx;
    double fc = f->p.min_cutoff + f->p.beta * fabs(f->dx);
    double a = pb_one_euro_alpha(fc, te);
    f->x = a * x + (1.0 - a) * f->x;
    return f->x;
}

void pb_one_euro_quat_init(pb_one_euro_quat *f, const pb_one_euro_params *p)
{
    f->p = *p;
    if (f->p.d_cutoff <= 0.0)
        f->p.d_cutoff = 1.0;
    pb_quat_identity(f->q);
    f->dx = 0.0;
    f->primed = 0;
}

void pb_one_euro_quat_step(pb_one_euro_quat *f, double q[4], double te)
{
    if (f->p.min_cutoff <= 0.0)
        return;
    if (!f->primed || !(te > 0.0)) {
        pb_quat_copy(f->q, q);
        f->dx = 0.0;
        f->primed = 1;
        return;
    }
    /* angle of the rotation from the previous estimate to the sample (rad) */
    double s = pb_quat_dot(f->q, q) < 0.0 ? -1.0 : 1.0, dm = 0.0, dp = 0.0;
    for (int i = 0; i < 4; i++) {
        dm += (q[i] - s * f->q[i]) * (q[i] - s * f->q[i]);
        dp += (q[i] + s * f->q[i]) * (q[i] + s * f->q[i]);
    }
    double speed = 4.0 * atan2(sqrt(dm), sqrt(dp)) / te; /* rotation angle / te */
    double ad = pb_one_euro_alpha(f->p.d_cutoff, te);
    f->dx = ad * speed + (1.0 - ad) * f->dx;
    double fc = f->p.min_cutoff + f->p.beta * f->dx;
    double a = pb_one_euro_alpha(fc, te);
    pb_quat_slerp(f->q, q, a, f->q);
    pb_quat_copy(q, f->q);
}
