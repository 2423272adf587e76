/* SPDX-License-Identifier: Apache-2.0 */
/* Rig descriptions -> rig file images (format version 1) and files. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "rig_format.h"
#include "rig_io.h"

static void put_u32(uint8_t *p, uint32_t v) { memcpy(p, &v, 4); }
static void put_u64(uint8_t *p, uint64_t v) { memcpy(p, &v, 8); }
static void put_i32(uint8_t *p, int32_t v) { memcpy(p, &v, 4); }

static void put_array(uint8_t *dst, const void *src, uint64_t bytes)
{
    if (bytes)
        memcpy(dst, src, (size_t)bytes);
}

static pose_status check_name(const char *name, const char *what, size_t index)
{
    if (!name)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "rig description: %s %zu has no name", what,
                          index);
    size_t n = strnlen(name, POSE__NAME_SIZE);
    if (n == 0 || n >= POSE__NAME_SIZE)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "rig description: %s %zu: name must be 1..%d bytes", what, index,
                          POSE__NAME_SIZE - 1);
    return POSE_OK;
}

/* Names that replace NULL in a description's clinical entries. */
static const char *const k_default_clinical_names[3] = {"flexion", "abduction",
                                                        "internal_rotation"};

/* Clinical names must fit their 32-byte slots; the rest is the loader's job. */
static pose_status check_clinical(const pose_rig_desc *d)
{
    for (size_t j = 0; d->clinical && j < d->joint_count; j++) {
        if (!d->clinical[j].flags)
            continue;
        for (int k = 0; k < 3; k++) {
            const char *name = d->clinical[j].names[k];
            if (name && (name[0] == '\0' || strnlen(name, POSE__CLINICAL_NAME_SIZE) >=
                                                 POSE__CLINICAL_NAME_SIZE))
                return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                                  "rig description: section 'clinical': joint %zu ('%s'): name of "
                                  "angle %d must be 1..%d bytes (or NULL for '%s')", j,
                                  d->joints[j].name, k, POSE__CLINICAL_NAME_SIZE - 1,
                                  k_default_clinical_names[k]);
        }
    }
    return POSE_OK;
}

/* Everything the image needs before bytes are written: counts within the
 * format's limits and arrays present. Sizes stay far below 2^64. */
static pose_status check_desc(const pose_rig_desc *d)
{
    if (!d)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "rig description is NULL");
    if (d->joint_count == 0 || d->joint_count > POSE__MAX_JOINTS || !d->joints)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "rig description: needs 1..%u joints and a joints array (has %zu)",
                          POSE__MAX_JOINTS, d->joint_count);
    for (size_t j = 0; j < d->joint_count; j++) {
        pose_status st = check_name(d->joints[j].name, "joint", j);
        if (st != POSE_OK)
            return st;
    }
    if (d->tet_vertex_count == 0 || d->tet_vertex_count > POSE__RIG_MAX_COUNT ||
        d->tet_count == 0 || d->tet_count > POSE__RIG_MAX_COUNT)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "rig description: tet mesh needs 1..%u vertices and tets (has %zu, %zu)",
                          POSE__RIG_MAX_COUNT, d->tet_vertex_count, d->tet_count);
    if (!d->tet_positions || !d->tets || !d->tet_labels)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "rig description: tet positions, tets and labels are required");
    if (d->influences == 0 || d->influences > POSE__MAX_INFLUENCES || !d->weight_joints ||
        !d->weights)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "rig description: needs 1..%d influences (has %u) and weight arrays",
                          POSE__MAX_INFLUENCES, d->influences);
    if (d->tissue_count > POSE__RIG_MAX_TISSUES || (d->tissue_count && !d->tissues))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "rig description: needs 0..%u tissues and a tissues array (has %zu)",
                          POSE__RIG_MAX_TISSUES, d->tissue_count);
    for (size_t t = 0; t < d->tissue_count; t++) {
        const pose_tissue_desc *td = &d->tissues[t];
        pose_status st = check_name(td->name, "tissue", t);
        if (st != POSE_OK)
            return st;
        if (td->vertex_count > POSE__RIG_MAX_COUNT || td->triangle_count > POSE__RIG_MAX_COUNT)
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "rig description: tissue '%s': too many vertices or triangles",
                              td->name);
        if ((td->vertex_count && (!td->positions || !td->tet || !td->bary)) ||
            (td->triangle_count && !td->triangles))
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "rig description: tissue '%s': missing positions, tet, bary or "
                              "triangles array", td->name);
    }
    if (d->fem_coupling_count && (!d->fem_couplings || !d->fem ||
                                  d->fem_coupling_count > POSE__RIG_MAX_COUNT))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "rig description: %zu fem couplings need the couplings array and fem "
                          "(the soft tissue's material), at most %u",
                          d->fem_coupling_count, POSE__RIG_MAX_COUNT);
    if (d->fem_soft_coupling_count && (!d->fem_soft_couplings || !d->fem ||
                                       d->fem_soft_coupling_count > POSE__RIG_MAX_COUNT))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "rig description: %zu fem soft couplings need their array and fem (the "
                          "soft tissue's material), at most %u",
                          d->fem_soft_coupling_count, POSE__RIG_MAX_COUNT);
    pose_status st = check_clinical(d);
    return st == POSE_OK ? pose__volumes_check_desc(d) : st;
}

typedef struct section_plan {
    uint32_t type;
    uint64_t offset, size;
} section_plan;

static uint64_t tissues_size(const pose_rig_desc *d)
{
    uint64_t s = POSE__RIG_SECTION_HEADER + pose__align64((uint64_t)d->tissue_count *
                                                          POSE__RIG_TISSUE_RECORD);
    for (size_t t = 0; t < d->tissue_count; t++)
        s += pose__tissue_data_size(d->tissues[t].vertex_count, d->tissues[t].triangle_count);
    return s;
}

static void write_skeleton(uint8_t *s, const pose_rig_desc *d)
{
    pose__skeleton_layout l = pose__skeleton_layout_of(d->joint_count);
    put_u32(s, (uint32_t)d->joint_count);
    for (size_t j = 0; j < d->joint_count; j++) {
        const pose_joint_desc *jd = &d->joints[j];
        memcpy(s + l.names + j * 64u, jd->name, strlen(jd->name));
        put_i32(s + l.parents + j * 4u, (int32_t)jd->parent);
        uint8_t *rm = s + l.rest_model + j * 28u;
        memcpy(rm, jd->rest_model.rotation, 16);
        memcpy(rm + 16, jd->rest_model.translation, 12);
        uint8_t *lim = s + l.limits + j * 32u;
        put_u32(lim, jd->limit_flags);
        put_u32(lim + 4, (uint32_t)jd->limit_order);
        memcpy(lim + 8, jd->limit_min_deg, 12);
        memcpy(lim + 20, jd->limit_max_deg, 12);
    }
}

static void write_tetmesh(uint8_t *s, const pose_rig_desc *d)
{
    pose__tetmesh_layout l = pose__tetmesh_layout_of(d->tet_vertex_count, d->tet_count);
    put_u64(s, d->tet_vertex_count);
    put_u64(s + 8, d->tet_count);
    put_array(s + l.positions, d->tet_positions, (uint64_t)d->tet_vertex_count * 12u);
    put_array(s + l.tets, d->tets, (uint64_t)d->tet_count * 16u);
    put_array(s + l.labels, d->tet_labels, (uint64_t)d->tet_count * 2u);
}

static void write_weights(uint8_t *s, const pose_rig_desc *d)
{
    pose__weights_layout l = pose__weights_layout_of(d->tet_vertex_count, d->influences);
    uint64_t n = (uint64_t)d->tet_vertex_count * d->influences;
    put_u64(s, d->tet_vertex_count);
    put_u32(s + 8, d->influences);
    put_array(s + l.joints, d->weight_joints, n * 2u);
    put_array(s + l.weights, d->weights, n * 4u);
}

static void write_cor(uint8_t *s, const pose_rig_desc *d)
{
    put_u64(s, d->tet_vertex_count);
    put_array(s + POSE__RIG_SECTION_HEADER, d->cor, (uint64_t)d->tet_vertex_count * 12u);
}

/* Joints without clinical data get an all-zero record, whatever else their
 * description entry holds. */
static void write_clinical(uint8_t *s, const pose_rig_desc *d)
{
    put_u32(s, (uint32_t)d->joint_count);
    for (size_t j = 0; j < d->joint_count; j++) {
        const pose_joint_clinical *c = &d->clinical[j];
        if (!c->flags)
            continue;
        pose__clinical_record r;
        memset(&r, 0, sizeof r);
        r.flags = c->flags;
        r.limit_flags = c->limit_flags;
        memcpy(r.neutral, c->neutral, sizeof r.neutral);
        memcpy(r.axes, c->axes, sizeof r.axes);
        memcpy(r.limit_min_deg, c->limit_min_deg, sizeof r.limit_min_deg);
        memcpy(r.limit_max_deg, c->limit_max_deg, sizeof r.limit_max_deg);
        for (int k = 0; k < 3; k++) {
            const char *name = c->names[k] ? c->names[k] : k_default_clinical_names[k];
            memcpy(r.names[k], name, strlen(name));
        }
        memcpy(s + POSE__RIG_SECTION_HEADER + j * POSE__RIG_CLINICAL_RECORD, &r, sizeof r);
    }
}

static void write_fem(uint8_t *s, const pose_rig_desc *d)
{
    put_u32(s, 1); /* one material class: soft tissue */
    pose__fem_record r;
    memset(&r, 0, sizeof r);
    r.young = d->fem->young_modulus;
    r.poisson = d->fem->poisson_ratio;
    r.density = d->fem->density;
    memcpy(s + POSE__RIG_SECTION_HEADER, &r, sizeof r);
}

static void write_couplings(uint8_t *s, const pose_rig_desc *d)
{
    put_u32(s, (uint32_t)d->fem_coupling_count);
    for (size_t i = 0; i < d->fem_coupling_count; i++) {
        const pose_fem_coupling *c = &d->fem_couplings[i];
        pose__coupling_record r;
        memset(&r, 0, sizeof r);
        r.node = c->node;
        r.joint = (uint32_t)c->joint;
        r.stiffness = c->stiffness;
        memcpy(r.anchor, c->anchor, sizeof r.anchor);
        memcpy(s + POSE__RIG_SECTION_HEADER + i * POSE__RIG_COUPLING_RECORD, &r, sizeof r);
    }
}

static void write_soft_couplings(uint8_t *s, const pose_rig_desc *d)
{
    put_u32(s, (uint32_t)d->fem_soft_coupling_count);
    for (size_t i = 0; i < d->fem_soft_coupling_count; i++) /* the record is the 0.2 struct */
        memcpy(s + POSE__RIG_SECTION_HEADER + i * POSE__RIG_SOFT_COUPLING_RECORD,
               &d->fem_soft_couplings[i], POSE__RIG_SOFT_COUPLING_RECORD);
}

static void write_tissues(uint8_t *s, const pose_rig_desc *d)
{
    put_u32(s, (uint32_t)d->tissue_count);
    uint64_t data = POSE__RIG_SECTION_HEADER +
                    pose__align64((uint64_t)d->tissue_count * POSE__RIG_TISSUE_RECORD);
    for (size_t t = 0; t < d->tissue_count; t++) {
        const pose_tissue_desc *td = &d->tissues[t];
        uint8_t *rec = s + POSE__RIG_SECTION_HEADER + t * POSE__RIG_TISSUE_RECORD;
        uint64_t nv = td->vertex_count, nt = td->triangle_count;
        uint64_t pos = data, tri = pos + pose__align64(nv * 12u);
        uint64_t tet = tri + pose__align64(nt * 12u), bary = tet + pose__align64(nv * 4u);
        memcpy(rec, td->name, strlen(td->name));
        put_u32(rec + 64, (uint32_t)td->kind);
        put_i32(rec + 68, (int32_t)td->joint);
        put_u64(rec + 72, nv);
        put_u64(rec + 80, nt);
        put_u64(rec + 88, pos);
        put_u64(rec + 96, tri);
        put_u64(rec + 104, tet);
        put_u64(rec + 112, bary);
        put_array(s + pos, td->positions, nv * 12u);
        put_array(s + tri, td->triangles, nt * 12u);
        put_array(s + tet, td->tet, nv * 4u);
        put_array(s + bary, td->bary, nv * 16u);
        data = bary + pose__align64(nv * 16u);
    }
}

pose_status pose__rig_serialize(const pose_rig_desc *d, const pose_allocator *allocator,
                                uint8_t **image, size_t *size)
{
    pose_status st = check_desc(d);
    if (st != POSE_OK)
        return st;
    size_t meta_len = d->metadata ? strlen(d->metadata) : 0;

    section_plan plan[12];
    uint32_t n = 0;
    plan[n++] = (section_plan){POSE__SEC_SKELETON, 0, pose__skeleton_layout_of(d->joint_count).size};
    plan[n++] = (section_plan){POSE__SEC_TETMESH, 0,
                               pose__tetmesh_layout_of(d->tet_vertex_count, d->tet_count).size};
    plan[n++] = (section_plan){POSE__SEC_WEIGHTS, 0,
                               pose__weights_layout_of(d->tet_vertex_count, d->influences).size};
    if (d->cor)
        plan[n++] = (section_plan){POSE__SEC_COR, 0, pose__cor_size_of(d->tet_vertex_count)};
    plan[n++] = (section_plan){POSE__SEC_TISSUES, 0, tissues_size(d)};
    if (meta_len)
        plan[n++] = (section_plan){POSE__SEC_METADATA, 0, pose__metadata_size_of(meta_len)};
    if (d->clinical)
        plan[n++] = (section_plan){POSE__SEC_CLINICAL, 0, pose__clinical_size_of(d->joint_count)};
    if (d->fem)
        plan[n++] = (section_plan){POSE__SEC_FEM, 0, POSE__RIG_FEM_SIZE};
    if (d->fem_coupling_count)
        plan[n++] = (section_plan){POSE__SEC_COUPLINGS, 0,
                                   pose__couplings_size_of(d->fem_coupling_count)};
    if (d->fem_soft_coupling_count)
        plan[n++] = (section_plan){POSE__SEC_SOFT_COUPLINGS, 0,
                                   pose__soft_couplings_size_of(d->fem_soft_coupling_count)};
    if (d->volume_count)
        plan[n++] = (section_plan){POSE__SEC_VOLUMES, 0, pose__volumes_size_of(d)};

    uint64_t total = POSE__RIG_HEADER_SIZE + pose__align64((uint64_t)n * POSE__RIG_ENTRY_SIZE);
    for (uint32_t i = 0; i < n; i++) {
        plan[i].offset = total;
        total += plan[i].size;
    }
    if (total > SIZE_MAX)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "rig description: image of %llu bytes is too "
                          "large for this platform", (unsigned long long)total);
    uint8_t *img = pose__calloc(allocator, (size_t)total, POSE__RIG_ALIGN);
    if (!img)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "rig description: cannot allocate %llu bytes "
                          "for the rig image", (unsigned long long)total);

    for (uint32_t i = 0; i < n; i++) {
        uint8_t *s = img + plan[i].offset;
        switch (plan[i].type) {
        case POSE__SEC_SKELETON: write_skeleton(s, d); break;
        case POSE__SEC_TETMESH: write_tetmesh(s, d); break;
        case POSE__SEC_WEIGHTS: write_weights(s, d); break;
        case POSE__SEC_COR: write_cor(s, d); break;
        case POSE__SEC_TISSUES: write_tissues(s, d); break;
        case POSE__SEC_CLINICAL: write_clinical(s, d); break;
        case POSE__SEC_FEM: write_fem(s, d); break;
        case POSE__SEC_COUPLINGS: write_couplings(s, d); break;
        case POSE__SEC_SOFT_COUPLINGS: write_soft_couplings(s, d); break;
        case POSE__SEC_VOLUMES: pose__volumes_write(s, d); break;
        case POSE__SEC_METADATA:
            put_u64(s, meta_len);
            memcpy(s + POSE__RIG_SECTION_HEADER, d->metadata, meta_len);
            break;
        }
        uint8_t *e = img + POSE__RIG_HEADER_SIZE + i * POSE__RIG_ENTRY_SIZE;
        put_u32(e + POSE__ENT_TYPE, plan[i].type);
        /* Readers before pose 0.2 skip what they do not know only when it is optional. */
        if (plan[i].type == POSE__SEC_CLINICAL || plan[i].type == POSE__SEC_FEM ||
            plan[i].type == POSE__SEC_VOLUMES || plan[i].type == POSE__SEC_COUPLINGS ||
            plan[i].type == POSE__SEC_SOFT_COUPLINGS)
            put_u32(e + POSE__ENT_FLAGS, POSE__SECTION_OPTIONAL);
        put_u64(e + POSE__ENT_OFFSET, plan[i].offset);
        put_u64(e + POSE__ENT_SIZE, plan[i].size);
        put_u32(e + POSE__ENT_CRC, pose__crc32(0, s, (size_t)plan[i].size));
    }
    memcpy(img + POSE__HDR_MAGIC, POSE__RIG_MAGIC, POSE__RIG_MAGIC_SIZE);
    put_u32(img + POSE__HDR_VERSION, POSE__RIG_VERSION);
    put_u32(img + POSE__HDR_HEADER_SIZE, POSE__RIG_HEADER_SIZE);
    put_u32(img + POSE__HDR_SECTION_COUNT, n);
    put_u64(img + POSE__HDR_FILE_SIZE, total);
    put_u64(img + POSE__HDR_TABLE_OFFSET, POSE__RIG_HEADER_SIZE);
    put_u32(img + POSE__HDR_TABLE_CRC,
            pose__crc32(0, img + POSE__RIG_HEADER_SIZE, (size_t)n * POSE__RIG_ENTRY_SIZE));
    put_u32(img + POSE__HDR_HEADER_CRC, pose__crc32(0, img, POSE__HDR_HEADER_CRC));
    *image = img;
    *size = (size_t)total;
    return POSE_OK;
}

/* Serialize, then validate the image exactly as the loader would, so nothing
 * is ever written that pose_rig_load would refuse. */
static pose_status serialize_checked(const pose_rig_desc *desc, const pose_allocator *allocator,
                                     uint8_t **image, size_t *size)
{
    pose_status st = pose__rig_serialize(desc, allocator, image, size);
    if (st != POSE_OK)
        return st;
    pose_rig *rig = NULL;
    /* Borrowed: the image stays ours; SKIP_CRC: we just computed them. */
    st = pose__rig_open(*image, *size, POSE__STORAGE_BORROWED, allocator,
                        POSE_LOAD_SKIP_CRC | POSE__OPEN_VALIDATE_ONLY, "rig description", false,
                        &rig);
    pose_rig_free(rig);
    if (st != POSE_OK) {
        pose__free(allocator, *image);
        *image = NULL;
        *size = 0;
    }
    return st;
}

pose_status pose_rig_write_memory(const pose_rig_desc *desc, const pose_allocator *allocator,
                                  void **data, size_t *size)
{
    pose__clear_error();
    if (!data || !size || !pose__allocator_valid(allocator))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_rig_write_memory: NULL output or incomplete allocator");
    *data = NULL;
    *size = 0;
    uint8_t *img;
    pose_status st = serialize_checked(desc, allocator, &img, size);
    if (st == POSE_OK)
        *data = img;
    return st;
}

pose_status pose_rig_write_file(const pose_rig_desc *desc, const char *path)
{
    pose__clear_error();
    if (!path)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_rig_write_file: path is NULL");
    uint8_t *img;
    size_t size;
    pose_status st = serialize_checked(desc, NULL, &img, &size);
    if (st != POSE_OK)
        return st;
    FILE *f = fopen(path, "wb");
    if (!f) {
        int e = errno;
        pose__free(NULL, img);
        return pose__fail(POSE_ERR_IO, "file '%s': cannot create: %s", path, strerror(e));
    }
    size_t written = fwrite(img, 1, size, f);
    int e = errno;
    int closed = fclose(f);
    pose__free(NULL, img);
    if (written != size || closed != 0) {
        remove(path);
        return pose__fail(POSE_ERR_IO, "file '%s': write failed after %zu of %zu bytes: %s", path,
                          written, size, strerror(written != size ? e : errno));
    }
    return POSE_OK;
}
