/* SPDX-License-Identifier: Apache-2.0 */
/* Byte-level access to rig file images for tests and the seed maker,
 * written from docs/rig-format.md (not from the library's headers), so the
 * tests also check that the library follows the spec. */
#ifndef POSE_TEST_RIG_BYTES_H
#define POSE_TEST_RIG_BYTES_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

enum { SEC_SKELETON = 1, SEC_TETMESH, SEC_WEIGHTS, SEC_COR, SEC_TISSUES, SEC_METADATA, SEC_VOLUMES,
       SEC_CLINICAL, SEC_FEM, SEC_COUPLINGS, SEC_SOFT_COUPLINGS };
/* A clinical record: 192 bytes per joint after the section's 64-byte header. */
enum { CLIN_FLAGS = 0, CLIN_LIMIT_FLAGS = 4, CLIN_NEUTRAL = 8, CLIN_AXES = 24, CLIN_MIN = 60,
       CLIN_MAX = 72, CLIN_RESERVED = 84, CLIN_NAMES = 96, CLIN_RECORD = 192 };

static inline uint32_t rb_u32(const uint8_t *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static inline uint64_t rb_u64(const uint8_t *p) { uint64_t v; memcpy(&v, p, 8); return v; }
static inline void rb_put_u32(uint8_t *p, uint32_t v) { memcpy(p, &v, 4); }
static inline void rb_put_u64(uint8_t *p, uint64_t v) { memcpy(p, &v, 8); }

/** Reference CRC-32 (bitwise, IEEE). */
static inline uint32_t rb_crc32(const uint8_t *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    }
    return ~c;
}

static inline uint32_t rb_section_count(const uint8_t *img) { return rb_u32(img + 16); }
static inline uint8_t *rb_entry(uint8_t *img, uint32_t i) { return img + 64 + 32 * (size_t)i; }

/** Table index of the section of `type`, or -1. */
static inline int rb_find(uint8_t *img, uint32_t type)
{
    for (uint32_t i = 0; i < rb_section_count(img); i++)
        if (rb_u32(rb_entry(img, i)) == type)
            return (int)i;
    return -1;
}

/** Offset of the section of `type` (0 if absent). */
static inline uint64_t rb_offset(uint8_t *img, uint32_t type)
{
    int i = rb_find(img, type);
    return i < 0 ? 0 : rb_u64(rb_entry(img, (uint32_t)i) + 8);
}

/** Recompute every CRC (sections within `size`, table, header). */
static inline void rb_fix_crcs(uint8_t *img, size_t size)
{
    uint32_t n = rb_section_count(img);
    if (64 + 32 * (size_t)n > size)
        return;
    for (uint32_t i = 0; i < n; i++) {
        uint8_t *e = rb_entry(img, i);
        uint64_t off = rb_u64(e + 8), len = rb_u64(e + 16);
        if (off <= size && len <= size - off)
            rb_put_u32(e + 24, rb_crc32(img + off, (size_t)len));
    }
    rb_put_u32(img + 40, rb_crc32(img + 64, 32 * (size_t)n));
    rb_put_u32(img + 60, rb_crc32(img, 60));
}

#endif /* POSE_TEST_RIG_BYTES_H */
