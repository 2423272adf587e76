/* SPDX-License-Identifier: Apache-2.0
 * One Euro filter (Casiez, Roussel, Vogel, CHI 2012): an adaptive low-pass
 * whose cutoff rises with speed, so slow motion is smoothed (little jitter)
 * and fast motion is followed (little lag).
 *
 *   alpha(fc, Te) = 1 / (1 + tau / Te),  tau = 1 / (2 pi fc)
 *   dX_i  = (X_i - x^_{i-1}) / Te          (x^: previous filtered value)
 *   dx^_i = alpha(d_cutoff) dX_i + (1 - alpha(d_cutoff)) dx^_{i-1}
 *   fc    = min_cutoff + beta |dx^_i|
 *   x^_i  = alpha(fc) X_i + (1 - alpha(fc)) x^_{i-1}
 *
 * The first sample passes through (dx^ = 0). The quaternion variant uses
 * the angular speed of q^_{i-1}^-1 q_i as |dX| and slerps instead of mixing.
 * min_cutoff <= 0 disables a filter (values pass through). */
#ifndef POSE_BRIDGE_ONE_EURO_H
#define POSE_BRIDGE_ONE_EURO_H

#include <stdint.h>

typedef struct pb_one_euro_params {
    double min_cutoff; /**< Hz; 0 disables */
    double beta;       /**< cutoff slope per unit of speed (unit/s) */
    double d_cutoff;   /**< Hz for the speed estimate; 0 means 1 Hz */
} pb_one_euro_params;

typedef struct pb_one_euro {
    pb_one_euro_params p;
    double x, dx;
    int primed;
} pb_one_euro;

typedef struct pb_one_euro_quat {
    pb_one_euro_params p;
    double q[4];
    double dx;
    int primed;
} pb_one_euro_quat;

/** alpha of a first-order low-pass with cutoff fc (Hz) sampled every te seconds. */
double pb_one_euro_alpha(double fc, double te);

void pb_one_euro_init(pb_one_euro *f, const pb_one_euro_params *p);
/** Filter sample x taken te seconds after the previous one (te <= 0: passes through and re-primes). */
double pb_one_euro_step(pb_one_euro *f, double x, double te);

void pb_one_euro_quat_init(pb_one_euro_quat *f, const pb_one_euro_params *p);
/** Filter unit quaternion q {x,y,z,w} in place. */
void pb_one_euro_quat_step(pb_one_euro_quat *f, double q[4], double te);

#endif /* POSE_BRIDGE_ONE_EURO_H */
