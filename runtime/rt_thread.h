/* SPDX-License-Identifier: Apache-2.0 */
/* The operating-system services of the runtime: threads, a lock and
 * condition variables, one-time initialisation, the CPU count and a
 * monotonic clock. One implementation per platform, chosen by CMake:
 * rt_thread_posix.c (pthreads, clock_gettime) and rt_thread_win32.c
 * (SRW locks, condition variables, _beginthreadex, QueryPerformanceCounter).
 * Only the types differ here; windows.h stays out of the headers. */
#ifndef POSE_RT_THREAD_H
#define POSE_RT_THREAD_H

#include <stdint.h>

#ifdef _WIN32
typedef struct { void *opaque; } pose__mutex; /* an SRWLOCK */
typedef struct { void *opaque; } pose__cond;  /* a CONDITION_VARIABLE */
typedef struct { void *opaque; } pose__once;  /* an INIT_ONCE */
typedef struct pose__thread {
    void *handle;
    void *(*fn)(void *);
    void *arg;
} pose__thread;
#define POSE__ONCE_INIT {0}
#else
#include <pthread.h>
typedef pthread_mutex_t pose__mutex;
typedef pthread_cond_t pose__cond;
typedef pthread_once_t pose__once;
typedef pthread_t pose__thread;
#define POSE__ONCE_INIT PTHREAD_ONCE_INIT
#endif

/** 0, or -1 when the lock could not be created. */
int pose__mutex_init(pose__mutex *m);
void pose__mutex_destroy(pose__mutex *m);
void pose__mutex_lock(pose__mutex *m);
void pose__mutex_unlock(pose__mutex *m);

/** 0, or -1 when the condition variable could not be created. */
int pose__cond_init(pose__cond *c);
void pose__cond_destroy(pose__cond *c);
/** Wait on c, `m` held (spurious wake-ups happen: wait in a loop). */
void pose__cond_wait(pose__cond *c, pose__mutex *m);
void pose__cond_signal(pose__cond *c);
void pose__cond_broadcast(pose__cond *c);

/** Run fn(arg) on a new thread: 0, or -1. *t stays in place until joined. */
int pose__thread_start(pose__thread *t, void *(*fn)(void *), void *arg);
void pose__thread_join(pose__thread *t);

/** Run fn exactly once for `once` (POSE__ONCE_INIT), whatever the threads. */
void pose__call_once(pose__once *once, void (*fn)(void));

/** Processors online (at least 1). */
unsigned pose__cpu_count(void);

/** Nanoseconds of a monotonic clock (CLOCK_MONOTONIC, QueryPerformanceCounter). */
int64_t pose__now_ns(void);

#endif /* POSE_RT_THREAD_H */
