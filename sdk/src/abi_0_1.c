/* SPDX-License-Identifier: Apache-2.0
 * The 0.1 entry points that took options structs, kept for programs built
 * against the 0.1 headers: their structs have no `size`, so each call is
 * copied into the sized layout (size 0: the 0.1 fields) and passed on. pose.h
 * maps the three names to the *_sized symbols; this file alone sees the old
 * names and layouts. */
#include "pose/pose.h"

#undef pose_rig_load_ex
#undef pose_rig_load_memory
#undef pose_state_create_ex

typedef struct load_options_0_1 {
    pose_allocator allocator;
    uint32_t flags;
} load_options_0_1;

typedef struct state_options_0_1 {
    pose_allocator allocator;
    int threads;
    pose_method method;
} state_options_0_1;

POSE_API pose_status pose_rig_load_ex(const char *path, const load_options_0_1 *options, pose_rig **out);
POSE_API pose_status pose_rig_load_memory(const void *data, size_t size, const load_options_0_1 *options,
                                          pose_rig **out);
POSE_API pose_status pose_state_create_ex(const pose_rig *rig, const state_options_0_1 *options, pose_state **out);

static const pose_load_options *load_options(const load_options_0_1 *old, pose_load_options *sized)
{
    if (!old)
        return NULL;
    *sized = (pose_load_options){.allocator = old->allocator, .flags = old->flags};
    return sized;
}

pose_status pose_rig_load_ex(const char *path, const load_options_0_1 *options, pose_rig **out)
{
    pose_load_options sized;
    return pose_rig_load_ex_sized(path, load_options(options, &sized), out);
}

pose_status pose_rig_load_memory(const void *data, size_t size, const load_options_0_1 *options, pose_rig **out)
{
    pose_load_options sized;
    return pose_rig_load_memory_sized(data, size, load_options(options, &sized), out);
}

pose_status pose_state_create_ex(const pose_rig *rig, const state_options_0_1 *options, pose_state **out)
{
    pose_state_options sized = {0};
    if (options)
        sized = (pose_state_options){.allocator = options->allocator, .threads = options->threads,
                                     .method = options->method};
    return pose_state_create_ex_sized(rig, options ? &sized : NULL, out);
}
