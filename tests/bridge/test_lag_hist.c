/* SPDX-License-Identifier: Apache-2.0
 * The lag histogram against exact order statistics: small lags are exact,
 * larger ones within 1/128 of the sorted sample's value at the same rank
 * (sorted[(size_t)(n * q)], what the runner reported before), the worst
 * exactly; negative lags count as 0; an empty histogram says 0.
 */
#include <stdlib.h>

#include "bridge_test.h"
#include "lag_hist.h"

static int cmp_i64(const void *x, const void *y)
{
    int64_t a = *(const int64_t *)x, b = *(const int64_t *)y;
    return (a > b) - (a < b);
}

static void test_empty_and_exact(void **state)
{
    (void)state;
    static pb_lag_hist h;
    pb_lag_hist_reset(&h);
    assert_true(pb_lag_hist_quantile_ns(&h, 0.5) == 0.0);
    for (int v = 0; v < 64; v++)
        pb_lag_hist_add(&h, v);
    pb_lag_hist_add(&h, -5); /* counts as 0 */
    assert_int_equal(h.count, 65);
    assert_true(pb_lag_hist_quantile_ns(&h, 0.0) == 0.0);
    assert_true(pb_lag_hist_quantile_ns(&h, 0.5) == 31.0); /* rank 32 of 0,0,1..63 */
    assert_true(pb_lag_hist_quantile_ns(&h, 1.0) == 63.0);
}

/* A long-tailed sample like a replay's lags: mostly tens of microseconds,
 * 2 % of milliseconds, one of 40 ms. */
static void test_against_sorted(void **state)
{
    (void)state;
    enum { N = 200000 };
    static pb_lag_hist h;
    static int64_t v[N];
    pb_lag_hist_reset(&h);
    srand(7);
    for (int i = 0; i < N; i++) {
        int64_t x = 5000 + rand() % 60000;
        if (i % 50 == 0)
            x = 1000000 + (int64_t)(rand() % 4000) * 1000;
        if (i == N / 3)
            x = 40123457;
        v[i] = x;
        pb_lag_hist_add(&h, x);
    }
    qsort(v, N, sizeof *v, cmp_i64);
    static const double q[] = {0.01, 0.25, 0.5, 0.9, 0.98, 0.99, 0.999, 1.0};
    for (size_t k = 0; k < sizeof q / sizeof *q; k++) {
        size_t r = (size_t)((double)N * q[k]);
        double want = (double)v[r < N ? r : N - 1], got = pb_lag_hist_quantile_ns(&h, q[k]);
        if (fabs(got - want) > want / 128.0)
            fail_msg("q %.3f: %.0f ns, sorted %.0f ns", q[k], got, want);
    }
    assert_true(pb_lag_hist_quantile_ns(&h, 1.0) == 40123457.0);
    assert_true(h.max_ns == 40123457);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_empty_and_exact),
        cmocka_unit_test(test_against_sorted),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
