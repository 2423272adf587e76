/* SPDX-License-Identifier: Apache-2.0 */
/* Morton (Z-order) keys of points in a box, to lay out nearby things
 * together (the contact response's clusters of skin vertices, nodes and
 * skin triangles): sort pose__morton entries with pose__morton_cmp. */
#ifndef POSE_MORTON_H
#define POSE_MORTON_H

#include <stdint.h>

/** A thing's key and its index (ties broken by index: one order). */
typedef struct pose__morton {
    uint64_t key;
    uint32_t index;
} pose__morton;

/* 21 bits -> every third bit. */
static inline uint64_t pose__morton_spread(uint64_t v)
{
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffull;
    v = (v | v << 16) & 0x1f0000ff0000ffull;
    v = (v | v << 8) & 0x100f00f00f00f00full;
    v = (v | v << 4) & 0x10c30c30c30c30c3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
}

/** x's key in the box [lo, hi] (21 bits an axis; clamped to the box). */
static inline uint64_t pose__morton_key(const float *x, const float *lo, const float *hi)
{
    uint64_t key = 0;
    for (int d = 0; d < 3; d++) {
        float e = hi[d] > lo[d] ? (x[d] - lo[d]) / (hi[d] - lo[d]) : 0.0f;
        e = e < 0.0f ? 0.0f : e > 1.0f ? 1.0f : e;
        key |= pose__morton_spread((uint64_t)(e * 1048575.0f)) << d;
    }
    return key;
}

/** qsort's comparison of pose__morton entries. */
static inline int pose__morton_cmp(const void *x, const void *y)
{
    const pose__morton *p = x, *q = y;
    if (p->key != q->key)
        return p->key < q->key ? -1 : 1;
    return p->index < q->index ? -1 : p->index > q->index;
}

#endif /* POSE_MORTON_H */
