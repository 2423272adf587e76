/* SPDX-License-Identifier: Apache-2.0 */
/* Internal entry points between rig building, serialization and loading. */
#ifndef POSE_RIG_IO_H
#define POSE_RIG_IO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rig_internal.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#  error "rig files are little-endian and mapped in place: big-endian hosts are not supported"
#endif

/** Where bytes under validation came from, for error messages. */
typedef struct pose__source {
    const uint8_t *base; /* first byte of the file image */
    size_t size;
    const char *name;    /* "file 'x.rig'", "memory buffer", "rig description" */
    bool offsets;        /* report byte offsets (false for descriptions) */
} pose__source;

/**
 * Set an error "<source>: section '<section>' at byte <offset of at>: <msg>"
 * and return status. `at` points into the image (or is NULL).
 */
pose_status pose__source_fail(const pose__source *src, pose_status status, const char *section,
                              const void *at, const char *fmt, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/**
 * Serialize a description into a rig file image (64-byte aligned, from
 * `allocator`). Checks only what serializing needs (counts, NULL arrays,
 * name lengths); the content is validated by pose__rig_open on the image.
 */
pose_status pose__rig_serialize(const pose_rig_desc *desc, const pose_allocator *allocator,
                                uint8_t **image, size_t *size);

/** Internal pose__rig_open flag: validate only, skip pose__rig_prepare. */
#define POSE__OPEN_VALIDATE_ONLY (1u << 31)

/**
 * Build a rig over a file image: check the structure (header, section table,
 * CRCs unless POSE_LOAD_SKIP_CRC), validate the content, derive rest_local and
 * the tissue table, run pose__rig_prepare. The rig takes ownership of the
 * image as `storage` says, also on failure (owned images are freed, mapped
 * ones unmapped).
 */
pose_status pose__rig_open(uint8_t *image, size_t size, pose__rig_storage storage,
                           const pose_allocator *allocator, uint32_t flags, const char *name,
                           bool offsets, pose_rig **out);

/** Content checks shared by every way of making a rig (rig_validate.c). */
pose_status pose__rig_validate(const pose_rig *rig, const pose__source *src);
/** The `clinical` section's records (rig_clinical.c); a no-op without one. */
pose_status pose__clinical_validate(const pose_rig *rig, const pose__source *src);
/** The fem section's material record (when present): finite, in range. */
pose_status pose__fem_validate(const pose_rig *rig, const pose__source *src);
/** The couplings section's records: nodes and joints in range, nodes
 *  strictly increasing, values finite, reserved bytes zero; needs `fem`. */
pose_status pose__couplings_validate(const pose_rig *rig, const pose__source *src);
/** The soft_couplings section's records (pose__soft_coupling_fault); needs
 *  `fem` (rig_soft_couplings.c). */
pose_status pose__soft_couplings_validate(const pose_rig *rig, const pose__source *src);

/** Map and check the volumes section (bytes p .. p + size of src) into
 *  rig->volumes (rig_volumes.c). */
pose_status pose__map_volumes(const pose__source *src, const uint8_t *p, uint64_t size,
                              pose_rig *rig);
/** Bytes of a volumes section for a description (0 when it has none). */
uint64_t pose__volumes_size_of(const pose_rig_desc *d);
/** Write the volumes section of d at s (pose__volumes_size_of(d) zeroed bytes). */
void pose__volumes_write(uint8_t *s, const pose_rig_desc *d);
/** A description's volumes: names, grids, arrays, sizes (before writing). */
pose_status pose__volumes_check_desc(const pose_rig_desc *d);

#endif /* POSE_RIG_IO_H */
