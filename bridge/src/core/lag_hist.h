/* SPDX-License-Identifier: Apache-2.0
 * A histogram of lags (nanoseconds) in constant memory, for percentiles over
 * a whole run of any length: recording never allocates and never grows the
 * resident set, and a percentile costs a walk over the bins, no sort.
 *
 * Bins are exact below 64 ns, then 64 per power of two (HDR histogram
 * style): a percentile is within 1/128 (0.8 %) of the recorded value it
 * stands for. The worst lag is kept exactly.
 */
#ifndef PB_LAG_HIST_H
#define PB_LAG_HIST_H

#include <stdint.h>

enum { PB_LAG_SUB_BITS = 6, PB_LAG_SUB = 1 << PB_LAG_SUB_BITS, PB_LAG_BINS = PB_LAG_SUB * (64 - PB_LAG_SUB_BITS + 1) };

typedef struct pb_lag_hist {
    uint64_t count;
    int64_t max_ns;
    uint32_t bins[PB_LAG_BINS]; /* saturate at UINT32_MAX: 50 days at 1 kHz */
} pb_lag_hist;

/** Empty the histogram (and touch all of it, so that recording later does not). */
void pb_lag_hist_reset(pb_lag_hist *h);
/** Count one lag; negative lags count as 0. */
void pb_lag_hist_add(pb_lag_hist *h, int64_t lag_ns);
/** The lag at quantile q in [0, 1] (0.5: median), 0 when empty. */
double pb_lag_hist_quantile_ns(const pb_lag_hist *h, double q);

#endif
