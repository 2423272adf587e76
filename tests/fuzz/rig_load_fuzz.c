/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target for the rig loader: any bytes either load into a rig whose
 * every array can be read, or fail with a message; never a crash or an
 * out-of-bounds read. Loaded a second time, borrowed and with CRCs skipped, so mutations
 * reach the structural and content checks instead of stopping at a CRC. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* posix_memalign; the fuzzer build does not define it */
#endif
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pose/pose.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static volatile float sink;

static void touch(const pose_rig *rig)
{
    float acc = 0.0f;
    for (size_t j = 0; j < pose_rig_joint_count(rig); j++) {
        pose_joint_info ji;
        if (pose_rig_joint_info(rig, (int)j, &ji) == POSE_OK)
            acc += (float)strlen(ji.name) + ji.rest_local.translation[0] + ji.limit_max_deg[2];
    }
    pose_tet_info ti;
    if (pose_rig_tet_info(rig, &ti) == POSE_OK) {
        for (size_t i = 0; i < ti.tet_count; i++)
            acc += ti.rest_positions[3 * ti.tets[4 * i + 3]] + ti.labels[i];
        for (size_t i = 0; i < ti.vertex_count * ti.influences; i++)
            acc += ti.weights[i] + ti.weight_joints[i];
        if (ti.cor)
            acc += ti.cor[3 * ti.vertex_count - 1];
    }
    for (size_t t = 0; t < pose_rig_tissue_count(rig); t++) {
        pose_tissue_info info;
        if (pose_rig_tissue_info(rig, (int)t, &info) != POSE_OK)
            continue;
        for (size_t i = 0; i < 3 * info.triangle_count; i++)
            acc += info.rest_positions[3 * info.triangles[i]];
    }
    acc += (float)strlen(pose_rig_metadata(rig));
    sink = acc;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* Copy, then borrow (from a 64-byte aligned copy sized exactly, so any
     * read past the end is caught by ASan), CRCs skipped. */
    void *block = NULL;
    if (size && posix_memalign(&block, 64, size) != 0)
        return 0;
    uint8_t *aligned = block;
    if (size)
        memcpy(aligned, data, size);
    static const uint32_t flags[2] = {0, POSE_LOAD_SKIP_CRC | POSE_LOAD_BORROW};
    for (int i = 0; i < 2; i++) {
        pose_load_options o = {.flags = flags[i]};
        pose_rig *rig = NULL;
        const uint8_t *src = i == 0 || !aligned ? data : aligned;
        pose_status st = pose_rig_load_memory(size ? src : (const uint8_t *)"", size, &o, &rig);
        if (st == POSE_OK) {
            touch(rig);
            pose_rig_free(rig);
        } else if (rig || !pose_last_error()[0]) {
            abort(); /* a failure must leave no rig and explain itself */
        }
    }
    free(aligned);
    return 0;
}
