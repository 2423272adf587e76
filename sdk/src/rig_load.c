/* SPDX-License-Identifier: Apache-2.0 */
/* pose_rig_load*: getting a rig file's bytes (mapped, read or from the
 * caller's memory) and handing them to pose__rig_open (rig_open.c). */
#include <stdio.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "platform_map.h"
#include "rig_format.h"
#include "rig_io.h"

/* A sized struct (pose.h: size 0 reads the 0.1 fields) with a complete allocator. */
static bool options_valid(const pose_load_options *o)
{
    return !o || ((o->size == 0 || o->size >= POSE_LOAD_OPTIONS_SIZE_0_2) && pose__allocator_valid(&o->allocator));
}

pose_status pose_rig_load(const char *path, pose_rig **out)
{
    return pose_rig_load_ex(path, NULL, out);
}

pose_status pose_rig_load_ex(const char *path, const pose_load_options *options, pose_rig **out)
{
    pose__clear_error();
    if (out)
        *out = NULL;
    if (!path || !out || !options_valid(options))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_rig_load: NULL path/out, options.size below the 0.2 layout or incomplete allocator");
    uint32_t flags = options ? options->flags & ~(uint32_t)POSE__OPEN_VALIDATE_ONLY : 0;
    const pose_allocator *alloc = options ? &options->allocator : NULL;
    char name[POSE__ERROR_SIZE / 2];
    snprintf(name, sizeof name, "file '%s'", path);

    pose__file file;
    uint64_t file_size;
    char why[POSE__ERROR_SIZE / 4];
    if (pose__file_open(&file, path, &file_size, why, sizeof why) != 0)
        return pose__fail(POSE_ERR_IO, "%s: %s", name, why);
    if (file_size > SIZE_MAX) {
        pose__file_close(&file);
        return pose__fail(POSE_ERR_IO, "%s: too large for this platform", name);
    }
    size_t size = (size_t)file_size;
    if (size < POSE__RIG_HEADER_SIZE) {
        pose__file_close(&file);
        pose__source src = {NULL, size, name, false};
        return pose__source_fail(&src, POSE_ERR_FORMAT, "header", NULL,
                                 "truncated: %zu bytes, a rig file has at least %u", size,
                                 POSE__RIG_HEADER_SIZE);
    }
    if (!(flags & POSE_LOAD_NO_MMAP)) {
        void *map = pose__file_map(&file, size, why, sizeof why);
        pose__file_close(&file);
        if (!map)
            return pose__fail(POSE_ERR_IO, "%s: cannot map %zu bytes: %s", name, size, why);
        return pose__rig_open(map, size, POSE__STORAGE_MAPPED, alloc, flags, name, true, out);
    }
    uint8_t *buf = pose__alloc(alloc, size, POSE__RIG_ALIGN);
    if (!buf) {
        pose__file_close(&file);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: cannot allocate %zu bytes", name, size);
    }
    size_t got = pose__file_read(&file, buf, size, why, sizeof why);
    pose__file_close(&file);
    if (got < size) {
        pose__free(alloc, buf);
        return pose__fail(POSE_ERR_IO, "%s: read failed at byte %zu of %zu: %s", name, got, size,
                          why);
    }
    return pose__rig_open(buf, size, POSE__STORAGE_OWNED, alloc, flags, name, true, out);
}

pose_status pose_rig_load_memory(const void *data, size_t size, const pose_load_options *options,
                                 pose_rig **out)
{
    pose__clear_error();
    if (out)
        *out = NULL;
    if (!data || !out || !options_valid(options))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_rig_load_memory: NULL data/out, options.size below the 0.2 layout or incomplete allocator");
    uint32_t flags = options ? options->flags & ~(uint32_t)POSE__OPEN_VALIDATE_ONLY : 0;
    const pose_allocator *alloc = options ? &options->allocator : NULL;
    if (flags & POSE_LOAD_BORROW) {
        if ((uintptr_t)data % POSE__RIG_ALIGN != 0)
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "memory buffer: POSE_LOAD_BORROW needs a %u-byte aligned buffer",
                              POSE__RIG_ALIGN);
        return pose__rig_open((uint8_t *)(uintptr_t)data, size, POSE__STORAGE_BORROWED, alloc,
                              flags, "memory buffer", true, out);
    }
    if (size == 0) {
        pose__source src = {data, 0, "memory buffer", false};
        return pose__source_fail(&src, POSE_ERR_FORMAT, "header", NULL,
                                 "truncated: 0 bytes, a rig file has at least %u",
                                 POSE__RIG_HEADER_SIZE);
    }
    uint8_t *copy = pose__alloc(alloc, size, POSE__RIG_ALIGN);
    if (!copy)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "memory buffer: cannot allocate %zu bytes", size);
    memcpy(copy, data, size);
    return pose__rig_open(copy, size, POSE__STORAGE_OWNED, alloc, flags, "memory buffer", true,
                          out);
}
