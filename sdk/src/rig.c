/* SPDX-License-Identifier: Apache-2.0 */
/* pose_rig construction from descriptions, destruction and queries. */
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "platform_map.h"
#include "rig_format.h"
#include "rig_io.h"

/* A description is serialized into the file image it would have on disk and
 * opened like a loaded file: one storage layout, one validator, and a created
 * rig is bit-identical to one written and loaded back. */
pose_status pose_rig_create(const pose_rig_desc *desc, const pose_allocator *allocator,
                            pose_rig **out)
{
    pose__clear_error();
    if (!out || !pose__allocator_valid(allocator))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_rig_create: NULL out or incomplete allocator");
    *out = NULL;
    uint8_t *image;
    size_t size;
    pose_status st = pose__rig_serialize(desc, allocator, &image, &size);
    if (st != POSE_OK)
        return st;
    return pose__rig_open(image, size, POSE__STORAGE_OWNED, allocator, POSE_LOAD_SKIP_CRC,
                          "rig description", false, out);
}

void pose_rig_free(pose_rig *rig)
{
    if (!rig)
        return;
    pose__rig_release(rig);
    pose_allocator a = rig->allocator;
    if (rig->storage == POSE__STORAGE_OWNED)
        pose__free(&a, rig->block);
    else if (rig->storage == POSE__STORAGE_MAPPED)
        pose__file_unmap(rig->block, rig->block_size);
    pose__free(&a, rig->derived);
    pose__free(&a, rig);
}

size_t pose_rig_joint_count(const pose_rig *rig)
{
    return rig ? rig->joint_count : 0;
}

int pose_rig_find_joint(const pose_rig *rig, const char *name)
{
    if (!rig || !name)
        return -1;
    for (size_t j = 0; j < rig->joint_count; j++)
        if (strcmp(pose__joint_name(rig, j), name) == 0)
            return (int)j;
    return -1;
}

pose_status pose_rig_joint_info(const pose_rig *rig, int joint, pose_joint_info *out)
{
    pose__clear_error();
    if (!rig || !out || joint < 0 || (size_t)joint >= rig->joint_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_rig_joint_info: joint %d out of range "
                          "(%zu joints) or NULL argument", joint, rig ? rig->joint_count : 0);
    const pose__joint_limit *l = &rig->joint_limits[joint];
    out->name = pose__joint_name(rig, (size_t)joint);
    out->parent = rig->joint_parents[joint];
    out->rest_model = rig->joint_rest_model[joint];
    out->rest_local = rig->joint_rest_local[joint];
    out->limit_flags = l->flags;
    out->limit_order = (pose_euler_order)l->order;
    memcpy(out->limit_min_deg, l->min_deg, sizeof l->min_deg);
    memcpy(out->limit_max_deg, l->max_deg, sizeof l->max_deg);
    return POSE_OK;
}

size_t pose_rig_tissue_count(const pose_rig *rig)
{
    return rig ? rig->tissue_count : 0;
}

int pose_rig_find_tissue(const pose_rig *rig, const char *name)
{
    if (!rig || !name)
        return -1;
    for (size_t t = 0; t < rig->tissue_count; t++)
        if (strcmp(rig->tissues[t].name, name) == 0)
            return (int)t;
    return -1;
}

pose_status pose_rig_tissue_info(const pose_rig *rig, int tissue, pose_tissue_info *out)
{
    pose__clear_error();
    if (!rig || !out || tissue < 0 || (size_t)tissue >= rig->tissue_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_rig_tissue_info: tissue %d out of "
                          "range (%zu tissues) or NULL argument", tissue,
                          rig ? rig->tissue_count : 0);
    const pose__tissue *t = &rig->tissues[tissue];
    out->name = t->name;
    out->kind = t->kind;
    out->joint = t->joint;
    out->vertex_count = t->vertex_count;
    out->triangle_count = t->triangle_count;
    out->rest_positions = t->positions;
    out->triangles = t->triangles;
    return POSE_OK;
}

pose_status pose_rig_tet_info(const pose_rig *rig, pose_tet_info *out)
{
    pose__clear_error();
    if (!rig || !out)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_rig_tet_info: NULL argument");
    out->vertex_count = rig->tet_vertex_count;
    out->tet_count = rig->tet_count;
    out->rest_positions = rig->tet_positions;
    out->tets = rig->tets;
    out->labels = rig->tet_labels;
    out->influences = rig->influences;
    out->weight_joints = rig->weight_joints;
    out->weights = rig->weights;
    out->cor = rig->cor;
    return POSE_OK;
}

const char *pose_rig_metadata(const pose_rig *rig)
{
    return rig ? rig->metadata : "";
}

_Static_assert(POSE__RIG_VERSION == POSE_RIG_FORMAT_VERSION, "pose.h names the format version the loader reads");

uint32_t pose_rig_format_version(const pose_rig *rig)
{
    (void)rig; /* the loader accepts one version, so every rig was loaded from (or writes) it */
    return POSE__RIG_VERSION;
}
