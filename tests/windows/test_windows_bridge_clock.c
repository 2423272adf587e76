/* SPDX-License-Identifier: Apache-2.0 */
/* The bridge's Win32 platform files (pb_clock_win32.c, pb_thread_win32.c),
 * which the Windows stage can run without the rest of the bridge (that needs
 * a mingw-w64 cJSON): the clock is monotonic, sleeps and timed waits last
 * until their deadline and no longer than a scheduler tick past it, a thread
 * starts, is woken and joins, and real-time priority is granted or refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "clock.h"
#include "pb_thread.h"

/* Sleeps may overrun by a timer tick (15.6 ms by default) plus a loaded machine. */
#define SLACK_NS 60000000

static void test_clock_is_monotonic_and_sleeps(void **state)
{
    (void)state;
    int64_t prev = pb_now_ns();
    for (int i = 0; i < 100000; i++) {
        int64_t t = pb_now_ns();
        assert_true(t >= prev);
        prev = t;
    }
    for (int ms = 0; ms <= 20; ms += 5) {
        int64_t start = pb_now_ns(), until = start + (int64_t)ms * 1000000;
        pb_sleep_until_ns(until);
        int64_t end = pb_now_ns();
        assert_true(end >= until);
        assert_true(end - until < SLACK_NS);
    }
    pb_sleep_until_ns(pb_now_ns() - 1000000000); /* past: returns at once */
}

static void test_timed_wait_reaches_its_deadline(void **state)
{
    (void)state;
    pb_mutex m;
    pb_cond c;
    pb_mutex_init(&m);
    pb_cond_init(&c);
    pb_mutex_lock(&m);
    int64_t until = pb_now_ns() + 30000000;
    while (pb_cond_wait_until(&c, &m, until) == 0 || pb_now_ns() < until) {
    }
    int64_t end = pb_now_ns();
    pb_mutex_unlock(&m);
    assert_true(end >= until);
    assert_true(end - until < SLACK_NS);
    pb_cond_destroy(&c);
    pb_mutex_destroy(&m);
}

typedef struct shared {
    pb_mutex m;
    pb_cond c;
    int go, done;
} shared;

static void *worker(void *arg)
{
    shared *s = arg;
    pb_thread_precise_wakeups();
    pb_mutex_lock(&s->m);
    while (!s->go)
        pb_cond_wait(&s->c, &s->m);
    s->done = 1;
    pb_cond_broadcast(&s->c);
    pb_mutex_unlock(&s->m);
    return NULL;
}

static void test_thread_is_woken_and_joins(void **state)
{
    (void)state;
    shared s = {.go = 0, .done = 0};
    pb_mutex_init(&s.m);
    pb_cond_init(&s.c);
    pb_thread t;
    assert_int_equal(pb_thread_start(&t, worker, &s), 0);
    pb_mutex_lock(&s.m);
    s.go = 1;
    pb_cond_broadcast(&s.c);
    int64_t until = pb_now_ns() + 5000000000;
    while (!s.done && pb_now_ns() < until)
        pb_cond_wait_until(&s.c, &s.m, until);
    int done = s.done;
    pb_mutex_unlock(&s.m);
    pb_thread_join(&t);
    assert_int_equal(done, 1);
    pb_cond_destroy(&s.c);
    pb_mutex_destroy(&s.m);
}

static void *ask_realtime(void *arg)
{
    *(int *)arg = pb_thread_realtime(50);
    return NULL;
}

static void test_realtime_answers(void **state)
{
    (void)state;
    int granted = -1;
    pb_thread t;
    assert_int_equal(pb_thread_start(&t, ask_realtime, &granted), 0);
    pb_thread_join(&t);
    assert_true(granted == 0 || granted == 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clock_is_monotonic_and_sleeps),
        cmocka_unit_test(test_timed_wait_reaches_its_deadline),
        cmocka_unit_test(test_thread_is_woken_and_joins),
        cmocka_unit_test(test_realtime_answers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
