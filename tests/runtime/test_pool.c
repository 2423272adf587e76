/* SPDX-License-Identifier: Apache-2.0 */
/* The worker pool: every part runs exactly once per task, on the worker
 * that owns it, with the caller's writes visible to it and its writes
 * visible after pose__pool_run returns; item tasks run every item once
 * (run under TSan with -DPOSE_TSAN=ON). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <time.h>

#include <cmocka.h>

#include "rt_pool.h"

enum { MAX_PARTS = 8, ITEMS = 1000 };

typedef struct job {
    int round;               /* written by the caller before each run */
    int seen[MAX_PARTS];     /* written by part i only */
    int runs[MAX_PARTS];
    int data[ITEMS];
} job;

static void task(void *ctx, unsigned part, unsigned parts)
{
    job *j = ctx;
    j->seen[part] = j->round;
    j->runs[part]++;
    size_t b = pose__part_begin(ITEMS, part, parts), e = pose__part_begin(ITEMS, part + 1, parts);
    for (size_t i = b; i < e; i++)
        j->data[i] += (int)i;
}

static void test_pool_runs_every_part_once(void **unused)
{
    (void)unused;
    for (unsigned threads = 1; threads <= 4; threads++) {
        pose__pool *pool = aligned_alloc(64, (pose__pool_size(threads) + 63) & ~(size_t)63);
        assert_non_null(pool);
        assert_int_equal(pose__pool_init(pool, threads), 0);
        assert_int_equal(pose__pool_threads(pool), threads);
        job *j = calloc(1, sizeof *j);
        for (int r = 1; r <= 200; r++) {
            j->round = r;
            pose__pool_run(pool, task, j);
            for (unsigned p = 0; p < threads; p++)
                assert_int_equal(j->seen[p], r);
        }
        for (unsigned p = 0; p < threads; p++)
            assert_int_equal(j->runs[p], 200);
        for (size_t i = 0; i < ITEMS; i++)
            assert_int_equal(j->data[i], 200 * (int)i); /* each item by exactly one part */
        free(j);
        pose__pool_destroy(pool);
        free(pool);
    }
}

static void sleep_ms(long ms)
{
    struct timespec t = {0, ms * 1000000L};
    nanosleep(&t, NULL);
}

/* A part that outlasts the pool's polling (~0.2 ms) when the round says so:
 * the caller then waits on the condition variable instead of polling. */
static void slow_task(void *ctx, unsigned part, unsigned parts)
{
    job *j = ctx;
    if (part == parts - 1 && j->round % 4 == 0)
        sleep_ms(2);
    task(ctx, part, parts);
}

/* Workers poll for a while after a task, then sleep: tasks posted after a
 * pause (sleeping workers), back to back (polling workers), and parts that
 * finish long after the caller's all run exactly once and are seen whole. */
static void test_pool_sleeps_and_wakes(void **unused)
{
    (void)unused;
    for (unsigned threads = 2; threads <= 3; threads++) {
        pose__pool *pool = aligned_alloc(64, (pose__pool_size(threads) + 63) & ~(size_t)63);
        assert_non_null(pool);
        assert_int_equal(pose__pool_init(pool, threads), 0);
        job *j = calloc(1, sizeof *j);
        for (int r = 1; r <= 24; r++) {
            if (r % 3 == 0)
                sleep_ms(2); /* longer than the polling: the workers are asleep */
            j->round = r;
            pose__pool_run(pool, slow_task, j);
            for (unsigned p = 0; p < threads; p++) {
                assert_int_equal(j->seen[p], r);
                assert_int_equal(j->runs[p], r);
            }
        }
        for (size_t i = 0; i < ITEMS; i++)
            assert_int_equal(j->data[i], 24 * (int)i);
        free(j);
        pose__pool_destroy(pool);
        free(pool);
    }
}

/* An item task's item: adds the round to its slot (each item once per
 * task); the first item of some rounds outlasts the polling. */
static void item(void *ctx, size_t i)
{
    job *j = ctx;
    if (i == 0 && j->round % 5 == 0)
        sleep_ms(1);
    j->data[i] += j->round;
}

/* Item tasks, back to back, after pauses, and between part tasks: every
 * item runs exactly once per task and its write is seen when the call
 * returns (workers that wake late must not touch a closed task). */
static void test_pool_items(void **unused)
{
    (void)unused;
    for (unsigned threads = 1; threads <= 3; threads++) {
        pose__pool *pool = aligned_alloc(64, (pose__pool_size(threads) + 63) & ~(size_t)63);
        assert_non_null(pool);
        assert_int_equal(pose__pool_init(pool, threads), 0);
        job *j = calloc(1, sizeof *j);
        int parts_runs = 0;
        for (int r = 1; r <= 300; r++) {
            if (r % 50 == 0)
                sleep_ms(2); /* the workers are asleep */
            j->round = r;
            const size_t n = (size_t)(r % 7 == 0 ? 1 : 1 + r % 97);
            pose__pool_run_items(pool, item, j, n);
            for (size_t i = 0; i < ITEMS; i++)
                if (i < n)
                    j->data[i] -= r; /* undone: data stays 0 if each ran once */
            if (r % 3 == 0) {
                pose__pool_run(pool, task, j); /* a part task between item tasks */
                parts_runs++;
                for (size_t i = 0; i < ITEMS; i++)
                    j->data[i] -= (int)i;
            }
            for (size_t i = 0; i < ITEMS; i++)
                assert_int_equal(j->data[i], 0);
        }
        for (unsigned p = 0; p < threads; p++)
            assert_int_equal(j->runs[p], parts_runs);
        free(j);
        pose__pool_destroy(pool);
        free(pool);
    }
}

static void test_part_ranges_cover(void **unused)
{
    (void)unused;
    for (unsigned parts = 1; parts <= 7; parts++)
        for (size_t n = 0; n < 50; n++) {
            assert_int_equal(pose__part_begin(n, 0, parts), 0);
            assert_int_equal(pose__part_begin(n, parts, parts), n);
            for (unsigned p = 0; p < parts; p++)
                assert_true(pose__part_begin(n, p, parts) <= pose__part_begin(n, p + 1, parts));
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_part_ranges_cover),
        cmocka_unit_test(test_pool_items),
        cmocka_unit_test(test_pool_runs_every_part_once),
        cmocka_unit_test(test_pool_sleeps_and_wakes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
