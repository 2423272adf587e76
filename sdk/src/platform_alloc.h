/* SPDX-License-Identifier: Apache-2.0 */
/* The default allocator's aligned allocation: one implementation per
 * platform, chosen by CMake: platform_alloc_posix.c (posix_memalign, free)
 * and platform_alloc_win32.c (_aligned_malloc, _aligned_free). */
#ifndef POSE_PLATFORM_ALLOC_H
#define POSE_PLATFORM_ALLOC_H

#include <stddef.h>

/** `size` bytes aligned to `align` (a power of two), or NULL. */
void *pose__aligned_alloc(size_t size, size_t align, void *user);
/** Release memory of pose__aligned_alloc (NULL is ignored). */
void pose__aligned_free(void *ptr, void *user);

#endif /* POSE_PLATFORM_ALLOC_H */
