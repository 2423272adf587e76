/* SPDX-License-Identifier: Apache-2.0 */
/* On-disk layout of rig files, version 1 (docs/rig-format.md is the spec).
 * Shared by the writer and the loader so both compute the same offsets. */
#ifndef POSE_RIG_FORMAT_H
#define POSE_RIG_FORMAT_H

#include <stdbool.h>
#include <stdint.h>

#define POSE__RIG_MAGIC "\x89POSERIG" /* 8 bytes, no terminator stored */
#define POSE__RIG_MAGIC_SIZE 8
#define POSE__RIG_VERSION 1u
#define POSE__RIG_HEADER_SIZE 64u
#define POSE__RIG_ENTRY_SIZE 32u
#define POSE__RIG_ALIGN 64u
#define POSE__RIG_MAX_SECTIONS 64u
#define POSE__RIG_SECTION_HEADER 64u    /* every section starts with 64 bytes of counts */
#define POSE__RIG_TISSUE_RECORD 128u
#define POSE__RIG_CLINICAL_RECORD 192u  /* one per joint, see pose__clinical_record */
#define POSE__RIG_MAX_TISSUES 65535u
#define POSE__RIG_MAX_COUNT 0xFFFFFFFFu /* vertex/tet/triangle counts: indices are uint32 */

/* Header field offsets. */
enum {
    POSE__HDR_MAGIC = 0,
    POSE__HDR_VERSION = 8,
    POSE__HDR_HEADER_SIZE = 12,
    POSE__HDR_SECTION_COUNT = 16,
    POSE__HDR_FLAGS = 20,
    POSE__HDR_FILE_SIZE = 24,
    POSE__HDR_TABLE_OFFSET = 32,
    POSE__HDR_TABLE_CRC = 40,
    POSE__HDR_RESERVED = 44, /* 16 bytes, zero */
    POSE__HDR_HEADER_CRC = 60 /* CRC32 of bytes 0..59 */
};

/* Section-table entry field offsets. */
enum {
    POSE__ENT_TYPE = 0,
    POSE__ENT_FLAGS = 4,
    POSE__ENT_OFFSET = 8,
    POSE__ENT_SIZE = 16,
    POSE__ENT_CRC = 24,
    POSE__ENT_RESERVED = 28
};

/** Entry flag: readers that do not know this type skip the section. */
#define POSE__SECTION_OPTIONAL 1u

/** Section types. 1..6 and 8 are version 1 (8, written since pose 0.2, is
 *  optional); 7 (volumes) is reserved; numbers are never reused. */
typedef enum pose__section_type {
    POSE__SEC_SKELETON = 1,
    POSE__SEC_TETMESH = 2,
    POSE__SEC_WEIGHTS = 3,
    POSE__SEC_COR = 4,
    POSE__SEC_TISSUES = 5,
    POSE__SEC_METADATA = 6,
    POSE__SEC_VOLUMES = 7, /* rest images on voxel grids (pose/volume.h) */
    POSE__SEC_CLINICAL = 8, /* neutral posture, clinical axes and ranges per joint */
    POSE__SEC_FEM = 9,      /* soft tissue material for POSE_FEM */
    POSE__SEC_COUPLINGS = 10, /* soft nodes tied to bones (pose_fem_coupling) */
    POSE__SEC_SOFT_COUPLINGS = 11 /* soft nodes tied to each other (pose_fem_soft_coupling) */
} pose__section_type;

/** Printable name of a section type ("skeleton", ...; "unknown" otherwise). */
const char *pose__section_name(uint32_t type);
/** Whether this library reads sections of `type` (others are skipped when optional). */
bool pose__section_known(uint32_t type);

/** Round up to the 64-byte alignment. */
static inline uint64_t pose__align64(uint64_t n)
{
    return (n + (POSE__RIG_ALIGN - 1)) & ~(uint64_t)(POSE__RIG_ALIGN - 1);
}

/* Layouts inside each section, offsets from the section start. All counts are
 * bounded before these are called, so no uint64 arithmetic here overflows. */
typedef struct pose__skeleton_layout {
    uint64_t names, parents, rest_model, limits, size;
} pose__skeleton_layout;
typedef struct pose__tetmesh_layout {
    uint64_t positions, tets, labels, size;
} pose__tetmesh_layout;
typedef struct pose__weights_layout {
    uint64_t joints, weights, size;
} pose__weights_layout;

pose__skeleton_layout pose__skeleton_layout_of(uint64_t joints);
pose__tetmesh_layout pose__tetmesh_layout_of(uint64_t vertices, uint64_t tets);
pose__weights_layout pose__weights_layout_of(uint64_t vertices, uint64_t influences);
uint64_t pose__cor_size_of(uint64_t vertices);
uint64_t pose__metadata_size_of(uint64_t length);
uint64_t pose__clinical_size_of(uint64_t joints);
/** The fem section: header, then one 64-byte material record (soft tissue). */
#define POSE__RIG_FEM_RECORD 64u
#define POSE__RIG_FEM_SIZE (POSE__RIG_SECTION_HEADER + POSE__RIG_FEM_RECORD)
/** The couplings section: header (count), then 32-byte records. */
#define POSE__RIG_COUPLING_RECORD 32u
uint64_t pose__couplings_size_of(uint64_t count);
/** The soft_couplings section: header (count), then 40-byte records. */
#define POSE__RIG_SOFT_COUPLING_RECORD 40u
uint64_t pose__soft_couplings_size_of(uint64_t count);
/** The volumes section: header (count), 128-byte records, then each
 *  volume's arrays (rig_volumes.c). */
#define POSE__RIG_VOLUME_RECORD 128u
#define POSE__RIG_MAX_VOLUMES 16u
#define POSE__RIG_MAX_VOLUME_VOXELS ((uint64_t)1 << 31)
/** Bytes one tissue's arrays take (positions, triangles, tet, bary, each padded). */
uint64_t pose__tissue_data_size(uint64_t vertices, uint64_t triangles);

/** CRC-32 (IEEE 802.3, as zlib's crc32) of `size` bytes, continuing from `crc`. */
uint32_t pose__crc32(uint32_t crc, const void *data, size_t size);

#endif /* POSE_RIG_FORMAT_H */
