/* SPDX-License-Identifier: Apache-2.0 */
/* pb_thread.h over pthreads, CLOCK_MONOTONIC condition variables and SCHED_FIFO. */
#include "pb_thread.h"

#include <sched.h>
#include <time.h>
#if defined(__linux__)
#include <sys/prctl.h>
#endif

void pb_mutex_init(pb_mutex *m)
{
    pthread_mutex_init(m, NULL);
}

void pb_mutex_destroy(pb_mutex *m)
{
    pthread_mutex_destroy(m);
}

void pb_mutex_lock(pb_mutex *m)
{
    pthread_mutex_lock(m);
}

void pb_mutex_unlock(pb_mutex *m)
{
    pthread_mutex_unlock(m);
}

void pb_cond_init(pb_cond *c)
{
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(c, &ca);
    pthread_condattr_destroy(&ca);
}

void pb_cond_destroy(pb_cond *c)
{
    pthread_cond_destroy(c);
}

void pb_cond_wait(pb_cond *c, pb_mutex *m)
{
    pthread_cond_wait(c, m);
}

int pb_cond_wait_until(pb_cond *c, pb_mutex *m, int64_t t_ns)
{
    struct timespec ts = {(time_t)(t_ns / 1000000000), (long)(t_ns % 1000000000)};
    return pthread_cond_timedwait(c, m, &ts);
}

void pb_cond_broadcast(pb_cond *c)
{
    pthread_cond_broadcast(c);
}

int pb_thread_start(pb_thread *t, void *(*fn)(void *), void *arg)
{
    return pthread_create(t, NULL, fn, arg) == 0 ? 0 : -1;
}

void pb_thread_join(pb_thread *t)
{
    pthread_join(*t, NULL);
}

void pb_thread_precise_wakeups(void)
{
#if defined(__linux__) && defined(PR_SET_TIMERSLACK)
    prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
#endif
}

int pb_thread_realtime(int priority)
{
    struct sched_param sp = {.sched_priority = priority > 99 ? 99 : priority};
    return pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
}
