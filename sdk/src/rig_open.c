/* SPDX-License-Identifier: Apache-2.0 */
/* Rig file images -> pose_rig: header, section table and section layouts are
 * checked here (nothing is read before its bounds are known), the content by
 * rig_validate.c. Arrays are used in place; nothing large is copied. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "platform_map.h"
#include "rig_format.h"
#include "rig_io.h"

static uint32_t get_u32(const uint8_t *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static uint64_t get_u64(const uint8_t *p) { uint64_t v; memcpy(&v, p, 8); return v; }

pose_status pose__source_fail(const pose__source *src, pose_status status, const char *section,
                              const void *at, const char *fmt, ...)
{
    char what[POSE__ERROR_SIZE];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (src->offsets && at)
        pose__set_error("%s: section '%s' at byte %llu: %s", src->name, section,
                        (unsigned long long)((const uint8_t *)at - src->base), what);
    else
        pose__set_error("%s: section '%s': %s", src->name, section, what);
    return status;
}

typedef struct entry {
    uint32_t type, flags, crc;
    uint64_t offset, size;
    const uint8_t *at; /* the table entry itself, for messages */
} entry;

static bool all_zero(const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i])
            return false;
    return true;
}

static pose_status check_version(const pose__source *src, uint32_t version)
{
    if (version == POSE__RIG_VERSION)
        return POSE_OK;
    const char *why = version < POSE__RIG_VERSION
        ? "version 0 was a development format and is not supported; rebuild the rig with pose-bake"
        : "it was written by a newer pose; upgrade the library or re-export the rig as version 1";
    return pose__source_fail(src, POSE_ERR_VERSION, "header", src->base + POSE__HDR_VERSION,
                             "file is version %u, this library reads %u (%s)", version,
                             POSE__RIG_VERSION, why);
}

/* Magic, version, header fields and CRC. */
static pose_status check_header(const pose__source *src, uint32_t flags)
{
    const uint8_t *b = src->base;
    if (src->size < POSE__RIG_HEADER_SIZE)
        return pose__source_fail(src, POSE_ERR_FORMAT, "header", b,
                                 "truncated: %zu bytes, a rig file has at least %u", src->size,
                                 POSE__RIG_HEADER_SIZE);
    if (memcmp(b, POSE__RIG_MAGIC, POSE__RIG_MAGIC_SIZE) != 0)
        return pose__source_fail(src, POSE_ERR_FORMAT, "header", b,
                                 "bad magic: not a pose rig file");
    pose_status st = check_version(src, get_u32(b + POSE__HDR_VERSION));
    if (st != POSE_OK)
        return st;
    if (!(flags & POSE_LOAD_SKIP_CRC)) {
        uint32_t want = get_u32(b + POSE__HDR_HEADER_CRC);
        uint32_t got = pose__crc32(0, b, POSE__HDR_HEADER_CRC);
        if (want != got)
            return pose__source_fail(src, POSE_ERR_CHECKSUM, "header", b + POSE__HDR_HEADER_CRC,
                                     "header CRC32 is 0x%08x but bytes 0..59 give 0x%08x", want, got);
    }
    if (get_u32(b + POSE__HDR_HEADER_SIZE) != POSE__RIG_HEADER_SIZE ||
        get_u32(b + POSE__HDR_FLAGS) != 0 || !all_zero(b + POSE__HDR_RESERVED, 16))
        return pose__source_fail(src, POSE_ERR_FORMAT, "header", b + POSE__HDR_HEADER_SIZE,
                                 "header size must be %u and flags/reserved bytes zero",
                                 POSE__RIG_HEADER_SIZE);
    return POSE_OK;
}

/* Read and check the section table into e[]; *n entries. */
static pose_status read_table(const pose__source *src, uint32_t flags, entry *e, uint32_t *n)
{
    const uint8_t *b = src->base;
    uint32_t count = get_u32(b + POSE__HDR_SECTION_COUNT);
    uint64_t table = get_u64(b + POSE__HDR_TABLE_OFFSET);
    uint64_t file_size = get_u64(b + POSE__HDR_FILE_SIZE);
    if (count == 0 || count > POSE__RIG_MAX_SECTIONS)
        return pose__source_fail(src, POSE_ERR_FORMAT, "header", b + POSE__HDR_SECTION_COUNT,
                                 "section count %u is outside 1..%u", count, POSE__RIG_MAX_SECTIONS);
    if (table != POSE__RIG_HEADER_SIZE)
        return pose__source_fail(src, POSE_ERR_FORMAT, "header", b + POSE__HDR_TABLE_OFFSET,
                                 "section table at byte %llu, must follow the header at byte %u",
                                 (unsigned long long)table, POSE__RIG_HEADER_SIZE);
    uint64_t table_end = table + (uint64_t)count * POSE__RIG_ENTRY_SIZE;
    if (table_end > src->size)
        return pose__source_fail(src, POSE_ERR_FORMAT, "section table", b + table,
                                 "truncated: %u entries need bytes %llu..%llu, the data has %zu",
                                 count, (unsigned long long)table, (unsigned long long)table_end,
                                 src->size);
    if (!(flags & POSE_LOAD_SKIP_CRC)) {
        uint32_t want = get_u32(b + POSE__HDR_TABLE_CRC);
        uint32_t got = pose__crc32(0, b + table, (size_t)(table_end - table));
        if (want != got)
            return pose__source_fail(src, POSE_ERR_CHECKSUM, "section table", b + table,
                                     "CRC32 is 0x%08x but the %u entries give 0x%08x", want, count,
                                     got);
    }
    for (uint32_t i = 0; i < count; i++) {
        const uint8_t *p = b + table + (uint64_t)i * POSE__RIG_ENTRY_SIZE;
        e[i] = (entry){get_u32(p + POSE__ENT_TYPE), get_u32(p + POSE__ENT_FLAGS),
                       get_u32(p + POSE__ENT_CRC), get_u64(p + POSE__ENT_OFFSET),
                       get_u64(p + POSE__ENT_SIZE), p};
    }
    /* A short file is reported against the section it cuts, the likeliest
     * question after an interrupted copy or write. */
    if (file_size != src->size) {
        for (uint32_t i = 0; i < count && file_size > src->size; i++)
            if (e[i].offset <= file_size && e[i].size <= file_size - e[i].offset &&
                e[i].offset + e[i].size > src->size)
                return pose__source_fail(src, POSE_ERR_FORMAT, pose__section_name(e[i].type),
                                         b + src->size,
                                         "truncated: section spans bytes %llu..%llu but the data "
                                         "ends at %zu (header says %llu bytes)",
                                         (unsigned long long)e[i].offset,
                                         (unsigned long long)(e[i].offset + e[i].size), src->size,
                                         (unsigned long long)file_size);
        return pose__source_fail(src, POSE_ERR_FORMAT, "header", b + POSE__HDR_FILE_SIZE,
                                 "header says %llu bytes, the data has %zu",
                                 (unsigned long long)file_size, src->size);
    }
    uint64_t data_start = pose__align64(table_end);
    for (uint32_t i = 0; i < count; i++) {
        const char *name = pose__section_name(e[i].type);
        if (get_u32(e[i].at + POSE__ENT_RESERVED) != 0 || (e[i].flags & ~POSE__SECTION_OPTIONAL))
            return pose__source_fail(src, POSE_ERR_FORMAT, "section table", e[i].at,
                                     "entry %u: unknown flags 0x%x or non-zero reserved field", i,
                                     e[i].flags);
        if (e[i].offset % POSE__RIG_ALIGN != 0)
            return pose__source_fail(src, POSE_ERR_FORMAT, name, e[i].at,
                                     "misaligned: starts at byte %llu, sections start on %u-byte "
                                     "boundaries", (unsigned long long)e[i].offset, POSE__RIG_ALIGN);
        if (e[i].offset < data_start || e[i].offset > src->size ||
            e[i].size > src->size - e[i].offset)
            return pose__source_fail(src, POSE_ERR_FORMAT, name, e[i].at,
                                     "bytes %llu..+%llu lie outside the data area %llu..%zu",
                                     (unsigned long long)e[i].offset,
                                     (unsigned long long)e[i].size,
                                     (unsigned long long)data_start, src->size);
        for (uint32_t k = 0; k < i; k++) {
            if (e[k].type == e[i].type)
                return pose__source_fail(src, POSE_ERR_FORMAT, name, e[i].at,
                                         "entry %u repeats section type %u of entry %u", i,
                                         e[i].type, k);
            if (e[i].offset < e[k].offset + e[k].size && e[k].offset < e[i].offset + e[i].size)
                return pose__source_fail(src, POSE_ERR_FORMAT, name, b + e[i].offset,
                                         "bytes %llu..%llu overlap section '%s' (bytes %llu..%llu)",
                                         (unsigned long long)e[i].offset,
                                         (unsigned long long)(e[i].offset + e[i].size),
                                         pose__section_name(e[k].type),
                                         (unsigned long long)e[k].offset,
                                         (unsigned long long)(e[k].offset + e[k].size));
        }
        if (!pose__section_known(e[i].type) && !(e[i].flags & POSE__SECTION_OPTIONAL))
            return pose__source_fail(src, POSE_ERR_FORMAT, name, e[i].at,
                                     "section type %u is unknown to format version %u and not "
                                     "marked optional", e[i].type, POSE__RIG_VERSION);
        if (!(flags & POSE_LOAD_SKIP_CRC)) {
            uint32_t got = pose__crc32(0, b + e[i].offset, (size_t)e[i].size);
            if (got != e[i].crc)
                return pose__source_fail(src, POSE_ERR_CHECKSUM, name, b + e[i].offset,
                                         "CRC32 of %llu bytes is 0x%08x, the table says 0x%08x",
                                         (unsigned long long)e[i].size, got, e[i].crc);
        }
    }
    *n = count;
    return POSE_OK;
}

static const entry *find(const entry *e, uint32_t n, uint32_t type)
{
    for (uint32_t i = 0; i < n; i++)
        if (e[i].type == type)
            return &e[i];
    return NULL;
}

/* A section must at least hold its 64-byte header before counts are read. */
static pose_status need_header(const pose__source *src, const entry *s)
{
    if (s->size < POSE__RIG_SECTION_HEADER)
        return pose__source_fail(src, POSE_ERR_FORMAT, pose__section_name(s->type),
                                 src->base + s->offset,
                                 "%llu bytes, shorter than its %u-byte section header",
                                 (unsigned long long)s->size, POSE__RIG_SECTION_HEADER);
    return POSE_OK;
}

static pose_status size_mismatch(const pose__source *src, const entry *s, uint64_t need,
                                  const char *counts)
{
    return pose__source_fail(src, POSE_ERR_FORMAT, pose__section_name(s->type),
                             src->base + s->offset,
                             "%llu bytes, but %s need exactly %llu", (unsigned long long)s->size,
                             counts, (unsigned long long)need);
}

static pose_status bad_count(const pose__source *src, const entry *s, const uint8_t *at,
                             const char *what, uint64_t value, uint64_t lo, uint64_t hi)
{
    return pose__source_fail(src, POSE_ERR_FORMAT, pose__section_name(s->type), at,
                             "%s %llu is outside %llu..%llu", what, (unsigned long long)value,
                             (unsigned long long)lo, (unsigned long long)hi);
}

static pose_status map_skeleton(const pose__source *src, const entry *s, pose_rig *rig)
{
    const uint8_t *p = src->base + s->offset;
    pose_status st = need_header(src, s);
    if (st != POSE_OK)
        return st;
    uint32_t j = get_u32(p);
    if (j == 0 || j > POSE__MAX_JOINTS)
        return bad_count(src, s, p, "joint count", j, 1, POSE__MAX_JOINTS);
    if (!all_zero(p + 4, POSE__RIG_SECTION_HEADER - 4))
        return pose__source_fail(src, POSE_ERR_FORMAT, "skeleton", p + 4,
                                 "reserved header bytes are not zero");
    pose__skeleton_layout l = pose__skeleton_layout_of(j);
    if (l.size != s->size)
        return size_mismatch(src, s, l.size, "its joint count");
    rig->joint_count = j;
    rig->joint_names = (const char *)(p + l.names);
    rig->joint_parents = (const int32_t *)(const void *)(p + l.parents);
    rig->joint_rest_model = (const pose_transform *)(const void *)(p + l.rest_model);
    rig->joint_limits = (const pose__joint_limit *)(const void *)(p + l.limits);
    return POSE_OK;
}

static pose_status map_tetmesh(const pose__source *src, const entry *s, pose_rig *rig)
{
    const uint8_t *p = src->base + s->offset;
    pose_status st = need_header(src, s);
    if (st != POSE_OK)
        return st;
    uint64_t v = get_u64(p), t = get_u64(p + 8);
    if (v == 0 || v > POSE__RIG_MAX_COUNT)
        return bad_count(src, s, p, "vertex count", v, 1, POSE__RIG_MAX_COUNT);
    if (t == 0 || t > POSE__RIG_MAX_COUNT)
        return bad_count(src, s, p + 8, "tet count", t, 1, POSE__RIG_MAX_COUNT);
    if (!all_zero(p + 16, POSE__RIG_SECTION_HEADER - 16))
        return pose__source_fail(src, POSE_ERR_FORMAT, "tetmesh", p + 16,
                                 "reserved header bytes are not zero");
    pose__tetmesh_layout l = pose__tetmesh_layout_of(v, t);
    if (l.size != s->size)
        return size_mismatch(src, s, l.size, "its vertex and tet counts");
    rig->tet_vertex_count = (size_t)v;
    rig->tet_count = (size_t)t;
    rig->tet_positions = (const float *)(const void *)(p + l.positions);
    rig->tets = (const uint32_t *)(const void *)(p + l.tets);
    rig->tet_labels = (const uint16_t *)(const void *)(p + l.labels);
    return POSE_OK;
}

static pose_status map_weights(const pose__source *src, const entry *s, pose_rig *rig)
{
    const uint8_t *p = src->base + s->offset;
    pose_status st = need_header(src, s);
    if (st != POSE_OK)
        return st;
    uint64_t v = get_u64(p);
    uint32_t k = get_u32(p + 8);
    if (v != rig->tet_vertex_count)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, "weights", p,
                                 "weights for %llu vertices, the tet mesh has %zu",
                                 (unsigned long long)v, rig->tet_vertex_count);
    if (k == 0 || k > POSE__MAX_INFLUENCES)
        return bad_count(src, s, p + 8, "influence count", k, 1, POSE__MAX_INFLUENCES);
    if (!all_zero(p + 12, POSE__RIG_SECTION_HEADER - 12))
        return pose__source_fail(src, POSE_ERR_FORMAT, "weights", p + 12,
                                 "reserved header bytes are not zero");
    pose__weights_layout l = pose__weights_layout_of(v, k);
    if (l.size != s->size)
        return size_mismatch(src, s, l.size, "its vertex and influence counts");
    rig->influences = k;
    rig->weight_joints = (const uint16_t *)(const void *)(p + l.joints);
    rig->weights = (const float *)(const void *)(p + l.weights);
    return POSE_OK;
}

static pose_status map_cor(const pose__source *src, const entry *s, pose_rig *rig)
{
    const uint8_t *p = src->base + s->offset;
    pose_status st = need_header(src, s);
    if (st != POSE_OK)
        return st;
    uint64_t v = get_u64(p);
    if (v != rig->tet_vertex_count)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, "cor", p,
                                 "centres for %llu vertices, the tet mesh has %zu",
                                 (unsigned long long)v, rig->tet_vertex_count);
    if (!all_zero(p + 8, POSE__RIG_SECTION_HEADER - 8))
        return pose__source_fail(src, POSE_ERR_FORMAT, "cor", p + 8,
                                 "reserved header bytes are not zero");
    if (pose__cor_size_of(v) != s->size)
        return size_mismatch(src, s, pose__cor_size_of(v), "its vertex count");
    rig->cor = (const float *)(const void *)(p + POSE__RIG_SECTION_HEADER);
    return POSE_OK;
}

static pose_status map_metadata(const pose__source *src, const entry *s, pose_rig *rig)
{
    const uint8_t *p = src->base + s->offset;
    pose_status st = need_header(src, s);
    if (st != POSE_OK)
        return st;
    uint64_t len = get_u64(p);
    if (len >= s->size || pose__metadata_size_of(len) != s->size)
        return pose__source_fail(src, POSE_ERR_FORMAT, "metadata", p,
                                 "text length %llu does not fit a %llu-byte section",
                                 (unsigned long long)len, (unsigned long long)s->size);
    if (!all_zero(p + 8, POSE__RIG_SECTION_HEADER - 8))
        return pose__source_fail(src, POSE_ERR_FORMAT, "metadata", p + 8,
                                 "reserved header bytes are not zero");
    const char *text = (const char *)(p + POSE__RIG_SECTION_HEADER);
    if (memchr(text, 0, (size_t)len) || text[len] != '\0')
        return pose__source_fail(src, POSE_ERR_FORMAT, "metadata", text,
                                 "text is not exactly %llu bytes followed by a NUL",
                                 (unsigned long long)len);
    rig->metadata = text;
    return POSE_OK;
}

/* One record per joint; the records' content is checked by rig_clinical.c. */
static pose_status map_clinical(const pose__source *src, const entry *s, pose_rig *rig)
{
    const uint8_t *p = src->base + s->offset;
    pose_status st = need_header(src, s);
    if (st != POSE_OK)
        return st;
    uint32_t j = get_u32(p);
    if (j != rig->joint_count)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, "clinical", p,
                                 "records for %u joints, the skeleton has %zu", j, rig->joint_count);
    if (!all_zero(p + 4, POSE__RIG_SECTION_HEADER - 4))
        return pose__source_fail(src, POSE_ERR_FORMAT, "clinical", p + 4,
                                 "reserved header bytes are not zero");
    if (pose__clinical_size_of(j) != s->size)
        return size_mismatch(src, s, pose__clinical_size_of(j), "its joint count");
    rig->clinical = (const pose__clinical_record *)(const void *)(p + POSE__RIG_SECTION_HEADER);
    return POSE_OK;
}

/* One material record (soft tissue); its values are checked by rig_fem.c. */
static pose_status map_fem(const pose__source *src, const entry *s, pose_rig *rig)
{
    const uint8_t *p = src->base + s->offset;
    pose_status st = need_header(src, s);
    if (st != POSE_OK)
        return st;
    uint32_t classes = get_u32(p);
    if (classes != 1)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, "fem", p,
                                 "%u material classes, this library reads 1 (soft tissue)", classes);
    if (!all_zero(p + 4, POSE__RIG_SECTION_HEADER - 4))
        return pose__source_fail(src, POSE_ERR_FORMAT, "fem", p + 4,
                                 "reserved header bytes are not zero");
    if (s->size != POSE__RIG_FEM_SIZE)
        return size_mismatch(src, s, POSE__RIG_FEM_SIZE, "one material record");
    rig->fem = (const pose__fem_record *)(const void *)(p + POSE__RIG_SECTION_HEADER);
    return POSE_OK;
}

/* A section of `count` records after its header (the count in its first
 * 4 bytes, the rest zero; a section with none is not written): the records
 * and their count; their values are checked by the section's own file. */
static pose_status map_counted(const pose__source *src, const entry *s, const char *name,
                               const char *records, uint64_t (*size_of)(uint64_t),
                               const uint8_t **first, uint32_t *count)
{
    const uint8_t *p = src->base + s->offset;
    pose_status st = need_header(src, s);
    if (st != POSE_OK)
        return st;
    const uint32_t n = get_u32(p);
    if (n == 0)
        return pose__source_fail(src, POSE_ERR_FORMAT, name, p,
                                 "0 %s (a rig without them has no section)", records);
    if (!all_zero(p + 4, POSE__RIG_SECTION_HEADER - 4))
        return pose__source_fail(src, POSE_ERR_FORMAT, name, p + 4,
                                 "reserved header bytes are not zero");
    if (s->size != size_of(n))
        return size_mismatch(src, s, size_of(n), "its record count");
    *first = p + POSE__RIG_SECTION_HEADER;
    *count = n;
    return POSE_OK;
}

/* Coupling records (rig_couplings.c). */
static pose_status map_couplings(const pose__source *src, const entry *s, pose_rig *rig)
{
    const uint8_t *first;
    uint32_t count;
    pose_status st = map_counted(src, s, "couplings", "couplings", pose__couplings_size_of, &first, &count);
    if (st == POSE_OK) {
        rig->couplings = (const pose__coupling_record *)(const void *)first;
        rig->coupling_count = count;
    }
    return st;
}

/* Soft coupling records (rig_soft_couplings.c). */
static pose_status map_soft_couplings(const pose__source *src, const entry *s, pose_rig *rig)
{
    const uint8_t *first;
    uint32_t count;
    pose_status st = map_counted(src, s, "soft_couplings", "soft couplings",
                                 pose__soft_couplings_size_of, &first, &count);
    if (st == POSE_OK) {
        rig->soft_couplings = (const pose__soft_coupling_record *)(const void *)first;
        rig->soft_coupling_count = count;
    }
    return st;
}

/* Tissue records hold counts and offsets; the offsets must follow the one
 * canonical layout, which rules out overlaps and misalignment at once. */
static pose_status map_tissues(const pose__source *src, const entry *s, pose_rig *rig,
                               pose__tissue *tissues, size_t count)
{
    const uint8_t *p = src->base + s->offset;
    uint64_t data = POSE__RIG_SECTION_HEADER + pose__align64((uint64_t)count * POSE__RIG_TISSUE_RECORD);
    if (data > s->size)
        return pose__source_fail(src, POSE_ERR_FORMAT, "tissues", p,
                                 "%llu bytes cannot hold %zu tissue records",
                                 (unsigned long long)s->size, count);
    for (size_t t = 0; t < count; t++) {
        const uint8_t *rec = p + POSE__RIG_SECTION_HEADER + t * POSE__RIG_TISSUE_RECORD;
        uint64_t nv = get_u64(rec + 72), nt = get_u64(rec + 80);
        if (nv > POSE__RIG_MAX_COUNT || nt > POSE__RIG_MAX_COUNT)
            return pose__source_fail(src, POSE_ERR_FORMAT, "tissues", rec + 72,
                                     "tissue %zu: %llu vertices / %llu triangles exceed %u", t,
                                     (unsigned long long)nv, (unsigned long long)nt,
                                     POSE__RIG_MAX_COUNT);
        uint64_t want[4];
        want[0] = data;
        want[1] = want[0] + pose__align64(nv * 12u);
        want[2] = want[1] + pose__align64(nt * 12u);
        want[3] = want[2] + pose__align64(nv * 4u);
        uint64_t end = want[3] + pose__align64(nv * 16u);
        static const char *const array[4] = {"positions", "triangles", "tet", "bary"};
        for (int a = 0; a < 4; a++) {
            uint64_t got = get_u64(rec + 88 + 8 * a);
            if (got != want[a])
                return pose__source_fail(src, POSE_ERR_FORMAT, "tissues", rec + 88 + 8 * a,
                                         "tissue %zu: %s at section offset %llu, the layout puts "
                                         "them at %llu", t, array[a], (unsigned long long)got,
                                         (unsigned long long)want[a]);
        }
        if (end > s->size)
            return pose__source_fail(src, POSE_ERR_FORMAT, "tissues", rec + 72,
                                     "tissue %zu: arrays end at section offset %llu, past the "
                                     "section's %llu bytes", t, (unsigned long long)end,
                                     (unsigned long long)s->size);
        if (get_u64(rec + 120) != 0)
            return pose__source_fail(src, POSE_ERR_FORMAT, "tissues", rec + 120,
                                     "tissue %zu: reserved field is not zero", t);
        int32_t joint;
        memcpy(&joint, rec + 68, 4);
        tissues[t] = (pose__tissue){
            .name = (const char *)rec,
            .kind = (pose_tissue_kind)get_u32(rec + 64),
            .joint = joint,
            .vertex_count = (size_t)nv,
            .triangle_count = (size_t)nt,
            .positions = (const float *)(const void *)(p + want[0]),
            .triangles = (const uint32_t *)(const void *)(p + want[1]),
            .tet = (const uint32_t *)(const void *)(p + want[2]),
            .bary = (const float *)(const void *)(p + want[3]),
        };
        data = end;
    }
    if (data != s->size)
        return size_mismatch(src, s, data, "its tissue records");
    rig->tissue_count = count;
    rig->tissues = tissues;
    return POSE_OK;
}

/* Sections in dependency order; the tissue table and rest_local live in one
 * derived allocation. */
static pose_status map_sections(const pose__source *src, const entry *e, uint32_t n, pose_rig *rig)
{
    static const uint32_t required[] = {POSE__SEC_SKELETON, POSE__SEC_TETMESH, POSE__SEC_WEIGHTS,
                                        POSE__SEC_TISSUES};
    for (size_t i = 0; i < sizeof required / sizeof required[0]; i++)
        if (!find(e, n, required[i]))
            return pose__source_fail(src, POSE_ERR_FORMAT, pose__section_name(required[i]), NULL,
                                     "required section is missing");
    pose_status st = map_skeleton(src, find(e, n, POSE__SEC_SKELETON), rig);
    if (st == POSE_OK)
        st = map_tetmesh(src, find(e, n, POSE__SEC_TETMESH), rig);
    if (st == POSE_OK)
        st = map_weights(src, find(e, n, POSE__SEC_WEIGHTS), rig);
    if (st == POSE_OK && find(e, n, POSE__SEC_COR))
        st = map_cor(src, find(e, n, POSE__SEC_COR), rig);
    if (st == POSE_OK && find(e, n, POSE__SEC_METADATA))
        st = map_metadata(src, find(e, n, POSE__SEC_METADATA), rig);
    if (st == POSE_OK && find(e, n, POSE__SEC_CLINICAL))
        st = map_clinical(src, find(e, n, POSE__SEC_CLINICAL), rig);
    if (st == POSE_OK && find(e, n, POSE__SEC_FEM))
        st = map_fem(src, find(e, n, POSE__SEC_FEM), rig);
    if (st == POSE_OK && find(e, n, POSE__SEC_COUPLINGS))
        st = map_couplings(src, find(e, n, POSE__SEC_COUPLINGS), rig);
    if (st == POSE_OK && find(e, n, POSE__SEC_SOFT_COUPLINGS))
        st = map_soft_couplings(src, find(e, n, POSE__SEC_SOFT_COUPLINGS), rig);
    if (st == POSE_OK && find(e, n, POSE__SEC_VOLUMES))
        st = pose__map_volumes(src, src->base + find(e, n, POSE__SEC_VOLUMES)->offset,
                               find(e, n, POSE__SEC_VOLUMES)->size, rig);
    if (st != POSE_OK)
        return st;

    const entry *ts = find(e, n, POSE__SEC_TISSUES);
    st = need_header(src, ts);
    if (st != POSE_OK)
        return st;
    const uint8_t *tp = src->base + ts->offset;
    uint32_t count = get_u32(tp);
    if (count > POSE__RIG_MAX_TISSUES)
        return bad_count(src, ts, tp, "tissue count", count, 0, POSE__RIG_MAX_TISSUES);
    if (!all_zero(tp + 4, POSE__RIG_SECTION_HEADER - 4))
        return pose__source_fail(src, POSE_ERR_FORMAT, "tissues", tp + 4,
                                 "reserved header bytes are not zero");

    size_t local_bytes = rig->joint_count * sizeof(pose_transform);
    size_t table_off = (local_bytes + 63u) & ~(size_t)63u;
    rig->derived = pose__calloc(&rig->allocator, table_off + count * sizeof(pose__tissue) + 64u,
                                POSE__ALIGN);
    if (!rig->derived)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: cannot allocate the joint and tissue tables",
                          src->name);
    rig->joint_rest_local = rig->derived;
    return map_tissues(src, ts, rig, (pose__tissue *)(void *)((uint8_t *)rig->derived + table_off),
                       count);
}

static void quat_mul(const float a[4], const float b[4], float r[4])
{
    r[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    r[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    r[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    r[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
}

static void quat_rotate(const float q[4], const float v[3], float r[3])
{
    /* v + 2 w (u x v) + 2 u x (u x v) */
    float tx = 2.0f * (q[1] * v[2] - q[2] * v[1]);
    float ty = 2.0f * (q[2] * v[0] - q[0] * v[2]);
    float tz = 2.0f * (q[0] * v[1] - q[1] * v[0]);
    r[0] = v[0] + q[3] * tx + (q[1] * tz - q[2] * ty);
    r[1] = v[1] + q[3] * ty + (q[2] * tx - q[0] * tz);
    r[2] = v[2] + q[3] * tz + (q[0] * ty - q[1] * tx);
}

/* rest_local = inverse(parent rest_model) * rest_model. */
static void derive_rest_local(pose_rig *rig)
{
    pose_transform *local = rig->derived;
    for (size_t j = 0; j < rig->joint_count; j++) {
        const pose_transform *m = &rig->joint_rest_model[j];
        int32_t p = rig->joint_parents[j];
        if (p < 0) {
            local[j] = *m;
            continue;
        }
        const pose_transform *pm = &rig->joint_rest_model[p];
        float inv[4] = {-pm->rotation[0], -pm->rotation[1], -pm->rotation[2], pm->rotation[3]};
        float q[4], d[3];
        quat_mul(inv, m->rotation, q);
        float len = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        for (int i = 0; i < 4; i++)
            local[j].rotation[i] = q[i] / len;
        for (int i = 0; i < 3; i++)
            d[i] = m->translation[i] - pm->translation[i];
        quat_rotate(inv, d, local[j].translation);
    }
}

pose_status pose__rig_open(uint8_t *image, size_t size, pose__rig_storage storage,
                           const pose_allocator *allocator, uint32_t flags, const char *name,
                           bool offsets, pose_rig **out)
{
    *out = NULL;
    pose_allocator a = pose__allocator_resolve(allocator);
    pose_rig *rig = pose__calloc(&a, sizeof *rig, POSE__ALIGN);
    if (!rig) {
        if (storage == POSE__STORAGE_OWNED)
            pose__free(&a, image);
        else if (storage == POSE__STORAGE_MAPPED)
            pose__file_unmap(image, size);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: cannot allocate the rig", name);
    }
    rig->allocator = a;
    rig->storage = storage;
    rig->block = image;
    rig->block_size = size;
    rig->metadata = "";

    pose__source src = {image, size, name, offsets};
    uint32_t n = 0;
    entry e[POSE__RIG_MAX_SECTIONS];
    pose_status st = check_header(&src, flags);
    if (st == POSE_OK)
        st = read_table(&src, flags, e, &n);
    if (st == POSE_OK)
        st = map_sections(&src, e, n, rig);
    if (st == POSE_OK)
        st = pose__rig_validate(rig, &src);
    if (st == POSE_OK) {
        derive_rest_local(rig);
        if (!(flags & POSE__OPEN_VALIDATE_ONLY))
            st = pose__rig_prepare(rig);
    }
    if (st != POSE_OK) {
        pose_rig_free(rig);
        return st;
    }
    *out = rig;
    return POSE_OK;
}
