/* SPDX-License-Identifier: Apache-2.0 */
/* rt_thread.h over Win32: SRW locks, condition variables, INIT_ONCE,
 * _beginthreadex (the CRT's own thread start) and QueryPerformanceCounter. */
#include "rt_thread.h"

#define WIN32_LEAN_AND_MEAN
#include <process.h>
#include <windows.h>

_Static_assert(sizeof(pose__mutex) == sizeof(SRWLOCK), "pose__mutex holds an SRWLOCK");
_Static_assert(sizeof(pose__cond) == sizeof(CONDITION_VARIABLE), "pose__cond holds a CONDITION_VARIABLE");
_Static_assert(sizeof(pose__once) == sizeof(INIT_ONCE), "pose__once holds an INIT_ONCE");

int pose__mutex_init(pose__mutex *m)
{
    InitializeSRWLock((PSRWLOCK)m);
    return 0;
}

void pose__mutex_destroy(pose__mutex *m)
{
    (void)m; /* an SRW lock holds no resources */
}

void pose__mutex_lock(pose__mutex *m)
{
    AcquireSRWLockExclusive((PSRWLOCK)m);
}

void pose__mutex_unlock(pose__mutex *m)
{
    ReleaseSRWLockExclusive((PSRWLOCK)m);
}

int pose__cond_init(pose__cond *c)
{
    InitializeConditionVariable((PCONDITION_VARIABLE)c);
    return 0;
}

void pose__cond_destroy(pose__cond *c)
{
    (void)c; /* a condition variable holds no resources */
}

void pose__cond_wait(pose__cond *c, pose__mutex *m)
{
    SleepConditionVariableSRW((PCONDITION_VARIABLE)c, (PSRWLOCK)m, INFINITE, 0);
}

void pose__cond_signal(pose__cond *c)
{
    WakeConditionVariable((PCONDITION_VARIABLE)c);
}

void pose__cond_broadcast(pose__cond *c)
{
    WakeAllConditionVariable((PCONDITION_VARIABLE)c);
}

static unsigned __stdcall thread_main(void *arg)
{
    pose__thread *t = arg;
    t->fn(t->arg);
    return 0;
}

int pose__thread_start(pose__thread *t, void *(*fn)(void *), void *arg)
{
    t->fn = fn;
    t->arg = arg;
    uintptr_t h = _beginthreadex(NULL, 0, thread_main, t, 0, NULL);
    t->handle = (void *)h;
    return h ? 0 : -1;
}

void pose__thread_join(pose__thread *t)
{
    WaitForSingleObject(t->handle, INFINITE);
    CloseHandle(t->handle);
}

static BOOL CALLBACK once_main(PINIT_ONCE once, PVOID param, PVOID *context)
{
    (void)once;
    (void)context;
    (*(void (**)(void))param)();
    return TRUE;
}

void pose__call_once(pose__once *once, void (*fn)(void))
{
    InitOnceExecuteOnce((PINIT_ONCE)once, once_main, &fn, NULL);
}

unsigned pose__cpu_count(void)
{
    DWORD n = GetActiveProcessorCount(ALL_PROCESSOR_GROUPS);
    return n > 0 ? (unsigned)n : 1u;
}

int64_t pose__now_ns(void)
{
    LARGE_INTEGER count, freq;
    QueryPerformanceCounter(&count);
    QueryPerformanceFrequency(&freq);
    /* whole seconds and the remainder apart: count * 1e9 overflows after days */
    int64_t s = count.QuadPart / freq.QuadPart, r = count.QuadPart % freq.QuadPart;
    return s * 1000000000 + r * 1000000000 / freq.QuadPart;
}
