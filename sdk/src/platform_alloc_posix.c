/* SPDX-License-Identifier: Apache-2.0 */
/* platform_alloc.h over posix_memalign and free. */
#include "platform_alloc.h"

#include <stdlib.h>

void *pose__aligned_alloc(size_t size, size_t align, void *user)
{
    (void)user;
    void *p = NULL;
    if (align < sizeof(void *))
        align = sizeof(void *);
    return posix_memalign(&p, align, size) == 0 ? p : NULL;
}

void pose__aligned_free(void *ptr, void *user)
{
    (void)user;
    free(ptr);
}
