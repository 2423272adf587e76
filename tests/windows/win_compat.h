/* SPDX-License-Identifier: Apache-2.0 */
/* Force-included into the tests of the Windows stage. msvcrt has neither
 * C11's aligned_alloc nor posix_memalign, and memory of _aligned_malloc must
 * go back through _aligned_free: so every allocation the tests make goes
 * through the _aligned_* functions, and free() releases any of them.
 * nanosleep is winpthreads', which the Windows build does not link. */
#ifndef POSE_WINDOWS_COMPAT_H
#define POSE_WINDOWS_COMPAT_H

#include <malloc.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define WIN32_LEAN_AND_MEAN
#define NOMINMAX
#include <windows.h>

static inline void *win_malloc(size_t size)
{
    return _aligned_malloc(size ? size : 1, 16);
}

static inline void *win_calloc(size_t n, size_t size)
{
    if (size && n > SIZE_MAX / size)
        return NULL;
    size_t bytes = n * size;
    void *p = _aligned_malloc(bytes ? bytes : 1, 16);
    if (p)
        memset(p, 0, bytes);
    return p;
}

static inline int win_posix_memalign(void **p, size_t align, size_t size)
{
    *p = _aligned_malloc(size ? size : 1, align);
    return *p ? 0 : 12; /* ENOMEM */
}

static inline char *win_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *p = _aligned_malloc(n, 16);
    return p ? memcpy(p, s, n) : NULL;
}

/* nanosleep is winpthreads', which the Windows build does not link */
static inline int win_nanosleep(const struct timespec *t, struct timespec *rem)
{
    (void)rem;
    Sleep((DWORD)(t->tv_sec * 1000 + (t->tv_nsec + 999999) / 1000000));
    return 0;
}

#define nanosleep(t, rem) win_nanosleep((t), (rem))
#define aligned_alloc(align, size) _aligned_malloc((size), (align))
#define posix_memalign(p, align, size) win_posix_memalign((p), (align), (size))
#define malloc(size) win_malloc(size)
#define calloc(n, size) win_calloc((n), (size))
#define realloc(p, size) _aligned_realloc((p), (size), 16)
#define strdup(s) win_strdup(s)
#define free(p) _aligned_free(p)

#endif /* POSE_WINDOWS_COMPAT_H */
