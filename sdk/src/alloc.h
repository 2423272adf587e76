/* SPDX-License-Identifier: Apache-2.0 */
/* Allocation through a caller's pose_allocator (zeroed struct = malloc/free). */
#ifndef POSE_ALLOC_H
#define POSE_ALLOC_H

#include <stdbool.h>
#include <stddef.h>

#include "pose/pose.h"

/** Alignment of every block pose hands out: one cache line. */
#define POSE__ALIGN 64

/** The allocator to use: *a when given and non-zero, else malloc/free. */
pose_allocator pose__allocator_resolve(const pose_allocator *a);
/** True when a is NULL, zeroed, or has both alloc and free. */
bool pose__allocator_valid(const pose_allocator *a);
/** `size` bytes aligned to `align` (power of two <= 4096); NULL on failure or size 0. */
void *pose__alloc(const pose_allocator *a, size_t size, size_t align);
/** As pose__alloc, zero-filled. */
void *pose__calloc(const pose_allocator *a, size_t size, size_t align);
/** Free what pose__alloc returned; NULL is a no-op. */
void pose__free(const pose_allocator *a, void *ptr);

#endif /* POSE_ALLOC_H */
