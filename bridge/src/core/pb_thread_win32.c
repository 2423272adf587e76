/* SPDX-License-Identifier: Apache-2.0 */
/* pb_thread.h over Win32: SRW locks, condition variables, _beginthreadex
 * and thread priorities. */
#include "pb_thread.h"

#define WIN32_LEAN_AND_MEAN
#include <process.h>
#include <windows.h>

#include "clock.h"

_Static_assert(sizeof(pb_mutex) == sizeof(SRWLOCK), "pb_mutex holds an SRWLOCK");
_Static_assert(sizeof(pb_cond) == sizeof(CONDITION_VARIABLE), "pb_cond holds a CONDITION_VARIABLE");

void pb_mutex_init(pb_mutex *m)
{
    InitializeSRWLock((PSRWLOCK)m);
}

void pb_mutex_destroy(pb_mutex *m)
{
    (void)m; /* an SRW lock holds no resources */
}

void pb_mutex_lock(pb_mutex *m)
{
    AcquireSRWLockExclusive((PSRWLOCK)m);
}

void pb_mutex_unlock(pb_mutex *m)
{
    ReleaseSRWLockExclusive((PSRWLOCK)m);
}

void pb_cond_init(pb_cond *c)
{
    InitializeConditionVariable((PCONDITION_VARIABLE)c);
}

void pb_cond_destroy(pb_cond *c)
{
    (void)c; /* a condition variable holds no resources */
}

void pb_cond_wait(pb_cond *c, pb_mutex *m)
{
    SleepConditionVariableSRW((PCONDITION_VARIABLE)c, (PSRWLOCK)m, INFINITE, 0);
}

int pb_cond_wait_until(pb_cond *c, pb_mutex *m, int64_t t_ns)
{
    /* Whole milliseconds, rounded down: the callers re-check the clock, so
     * the last fraction is waited out in zero-length waits, not overslept. */
    int64_t left = t_ns - pb_now_ns();
    DWORD ms = left <= 0 ? 0 : left >= (int64_t)0x7fffffff * 1000000 ? 0x7fffffffu : (DWORD)(left / 1000000);
    return SleepConditionVariableSRW((PCONDITION_VARIABLE)c, (PSRWLOCK)m, ms, 0) ? 0 : 1;
}

void pb_cond_broadcast(pb_cond *c)
{
    WakeAllConditionVariable((PCONDITION_VARIABLE)c);
}

static unsigned __stdcall thread_main(void *arg)
{
    pb_thread *t = arg;
    t->fn(t->arg);
    return 0;
}

int pb_thread_start(pb_thread *t, void *(*fn)(void *), void *arg)
{
    t->fn = fn;
    t->arg = arg;
    uintptr_t h = _beginthreadex(NULL, 0, thread_main, t, 0, NULL);
    t->handle = (void *)h;
    return h ? 0 : -1;
}

void pb_thread_join(pb_thread *t)
{
    WaitForSingleObject(t->handle, INFINITE);
    CloseHandle(t->handle);
}

void pb_thread_precise_wakeups(void)
{
    /* no per-thread setting: pb_cond_wait_until finishes its waits itself */
}

int pb_thread_realtime(int priority)
{
    (void)priority; /* Win32 has one level above normal for a thread in a normal process */
    return SetThreadPriority(GetCurrentThread(), THREAD_PRIORITY_TIME_CRITICAL) != 0;
}
