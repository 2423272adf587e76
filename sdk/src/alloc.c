/* SPDX-License-Identifier: Apache-2.0 */
#include <string.h>

#include "alloc.h"
#include "platform_alloc.h"

pose_allocator pose__allocator_resolve(const pose_allocator *a)
{
    if (a && a->alloc && a->free)
        return *a;
    pose_allocator d = {pose__aligned_alloc, pose__aligned_free, NULL};
    return d;
}

bool pose__allocator_valid(const pose_allocator *a)
{
    return !a || (!a->alloc && !a->free) || (a->alloc && a->free);
}

void *pose__alloc(const pose_allocator *a, size_t size, size_t align)
{
    if (size == 0 || align == 0 || (align & (align - 1)) != 0 || align > 4096)
        return NULL;
    pose_allocator r = pose__allocator_resolve(a);
    return r.alloc(size, align, r.user);
}

void *pose__calloc(const pose_allocator *a, size_t size, size_t align)
{
    void *p = pose__alloc(a, size, align);
    if (p)
        memset(p, 0, size);
    return p;
}

void pose__free(const pose_allocator *a, void *ptr)
{
    if (!ptr)
        return;
    pose_allocator r = pose__allocator_resolve(a);
    r.free(ptr, r.user);
}
