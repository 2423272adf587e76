/* SPDX-License-Identifier: Apache-2.0 */
/* platform_alloc.h over the CRT's _aligned_malloc and _aligned_free. */
#include "platform_alloc.h"

#include <malloc.h>

void *pose__aligned_alloc(size_t size, size_t align, void *user)
{
    (void)user;
    if (align < sizeof(void *))
        align = sizeof(void *);
    return _aligned_malloc(size ? size : 1, align);
}

void pose__aligned_free(void *ptr, void *user)
{
    (void)user;
    _aligned_free(ptr);
}
