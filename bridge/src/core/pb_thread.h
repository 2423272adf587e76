/* SPDX-License-Identifier: Apache-2.0
 * The bridge thread's OS services: a lock, a condition variable whose timed
 * waits run on pb_now_ns's clock, the thread itself and its scheduling. One
 * implementation per platform, chosen by CMake: pb_thread_posix.c (pthreads,
 * CLOCK_MONOTONIC waits, SCHED_FIFO) and pb_thread_win32.c (SRW locks,
 * condition variables, _beginthreadex, THREAD_PRIORITY_TIME_CRITICAL).
 * Only the types differ here; windows.h stays out of the headers. */
#ifndef POSE_BRIDGE_PB_THREAD_H
#define POSE_BRIDGE_PB_THREAD_H

#include <stdint.h>

#ifdef _WIN32
typedef struct { void *opaque; } pb_mutex; /* an SRWLOCK */
typedef struct { void *opaque; } pb_cond;  /* a CONDITION_VARIABLE */
typedef struct pb_thread {
    void *handle;
    void *(*fn)(void *);
    void *arg;
} pb_thread;
#else
#include <pthread.h>
typedef pthread_mutex_t pb_mutex;
typedef pthread_cond_t pb_cond;
typedef pthread_t pb_thread;
#endif

void pb_mutex_init(pb_mutex *m);
void pb_mutex_destroy(pb_mutex *m);
void pb_mutex_lock(pb_mutex *m);
void pb_mutex_unlock(pb_mutex *m);

void pb_cond_init(pb_cond *c);
void pb_cond_destroy(pb_cond *c);
/** Wait on c, `m` held (spurious wake-ups happen: wait in a loop). */
void pb_cond_wait(pb_cond *c, pb_mutex *m);
/** Wait on c until pb_now_ns() reaches t_ns: 0 when woken, nonzero on time-out. */
int pb_cond_wait_until(pb_cond *c, pb_mutex *m, int64_t t_ns);
void pb_cond_broadcast(pb_cond *c);

/** Run fn(arg) on a new thread: 0, or -1. *t stays in place until joined. */
int pb_thread_start(pb_thread *t, void *(*fn)(void *), void *arg);
void pb_thread_join(pb_thread *t);

/** The calling thread's timed waits end at their deadline, not a coalesced
 *  wake-up later (Linux: 1 ns timer slack instead of 50 us). */
void pb_thread_precise_wakeups(void);
/** Ask real-time scheduling for the calling thread (priority 1..99): 1 when
 *  granted, 0 when not (no privilege: the thread runs on normally). */
int pb_thread_realtime(int priority);

#endif /* POSE_BRIDGE_PB_THREAD_H */
