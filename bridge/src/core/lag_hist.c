/* SPDX-License-Identifier: Apache-2.0 */
#include "lag_hist.h"

#include <string.h>

static int bin_of(uint64_t v)
{
    if (v < PB_LAG_SUB)
        return (int)v;
    int e = 63 - __builtin_clzll(v); /* v in [2^e, 2^(e+1)), e >= PB_LAG_SUB_BITS */
    int sub = (int)((v >> (e - PB_LAG_SUB_BITS)) & (PB_LAG_SUB - 1));
    return PB_LAG_SUB * (e - PB_LAG_SUB_BITS + 1) + sub;
}

/* The middle of bin b's value range [lo, lo + width). */
static double bin_mid(int b)
{
    if (b < PB_LAG_SUB)
        return (double)b;
    int e = b / PB_LAG_SUB + PB_LAG_SUB_BITS - 1, sub = b % PB_LAG_SUB;
    double width = (double)(1ULL << (e - PB_LAG_SUB_BITS));
    return (double)(1ULL << e) + (double)sub * width + 0.5 * width;
}

void pb_lag_hist_reset(pb_lag_hist *h)
{
    /* memset, not calloc: calloc's untouched zero pages would be faulted in
     * one by one as lags arrive, and a soak would see the resident set grow */
    memset(h, 0, sizeof *h);
}

void pb_lag_hist_add(pb_lag_hist *h, int64_t lag_ns)
{
    uint64_t v = lag_ns > 0 ? (uint64_t)lag_ns : 0;
    uint32_t *bin = &h->bins[bin_of(v)];
    if (*bin < UINT32_MAX)
        ++*bin;
    h->count++;
    if ((int64_t)v > h->max_ns)
        h->max_ns = (int64_t)v;
}

double pb_lag_hist_quantile_ns(const pb_lag_hist *h, double q)
{
    if (!h->count)
        return 0.0;
    if (q < 0.0)
        q = 0.0;
    /* the same rank as sorted[(size_t)(n * q)], clamped to the last */
    uint64_t rank = (uint64_t)((double)h->count * q);
    if (rank >= h->count - 1)
        return (double)h->max_ns; /* the worst is kept exactly */
    uint64_t seen = 0;
    for (int b = 0; b < PB_LAG_BINS; b++) {
        seen += h->bins[b];
        if (seen > rank) {
            double v = bin_mid(b);
            return v < (double)h->max_ns ? v : (double)h->max_ns;
        }
    }
    return (double)h->max_ns;
}
