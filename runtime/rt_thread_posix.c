/* SPDX-License-Identifier: Apache-2.0 */
/* rt_thread.h over pthreads, sysconf and clock_gettime. */
#include "rt_thread.h"

#include <time.h>
#include <unistd.h>

int pose__mutex_init(pose__mutex *m)
{
    return pthread_mutex_init(m, NULL) == 0 ? 0 : -1;
}

void pose__mutex_destroy(pose__mutex *m)
{
    pthread_mutex_destroy(m);
}

void pose__mutex_lock(pose__mutex *m)
{
    pthread_mutex_lock(m);
}

void pose__mutex_unlock(pose__mutex *m)
{
    pthread_mutex_unlock(m);
}

int pose__cond_init(pose__cond *c)
{
    return pthread_cond_init(c, NULL) == 0 ? 0 : -1;
}

void pose__cond_destroy(pose__cond *c)
{
    pthread_cond_destroy(c);
}

void pose__cond_wait(pose__cond *c, pose__mutex *m)
{
    pthread_cond_wait(c, m);
}

void pose__cond_signal(pose__cond *c)
{
    pthread_cond_signal(c);
}

void pose__cond_broadcast(pose__cond *c)
{
    pthread_cond_broadcast(c);
}

int pose__thread_start(pose__thread *t, void *(*fn)(void *), void *arg)
{
    return pthread_create(t, NULL, fn, arg) == 0 ? 0 : -1;
}

void pose__thread_join(pose__thread *t)
{
    pthread_join(*t, NULL);
}

void pose__call_once(pose__once *once, void (*fn)(void))
{
    pthread_once(once, fn);
}

unsigned pose__cpu_count(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (unsigned)n : 1u;
}

int64_t pose__now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}
