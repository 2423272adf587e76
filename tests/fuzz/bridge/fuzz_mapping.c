/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness: mapping JSON, then binding it to a small clip and rig
 * (name resolution, alignment, channel binding) and one retarget step. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mapping.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char BVH[] = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition "
                          "Zrotation Xrotation Yrotation\nJOINT RightArm\n{\nOFFSET -1 2 0\nCHANNELS 3 Zrotation "
                          "Xrotation Yrotation\nJOINT RightForeArm\n{\nOFFSET -2 0 0\nCHANNELS 3 Zrotation Xrotation "
                          "Yrotation\nEnd Site\n{\nOFFSET -2 0 0\n}\n}\n}\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n"
                          "0 0 0 0 0 0 0 0 0 0 0 0\n1 2 3 10 20 30 40 50 60 70 80 90\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static pb_clip *clip;
    static pb_rig_skel *rig;
    pb_error err;
    if (!clip) {
        if (pb_bvh_parse(BVH, strlen(BVH), "fuzz.bvh", &clip, &err) != POSE_OK ||
            pb_rig_skel_from_clip(clip, 1.0, &rig, &err) != POSE_OK)
            abort();
    }
    pb_mapping *m;
    if (pb_mapping_parse((const char *)data, size, "fuzz.json", &m, &err) != POSE_OK)
        return 0;
    pb_retarget *r;
    if (pb_retarget_create(m, clip, rig, &r, &err) == POSE_OK) {
        pb_pose pose;
        double lq[5][4], lt[5][3];
        if (pb_pose_init(&pose, rig->joint_count) == 0) {
            pb_clip_local(clip, pb_clip_frame(clip, 1), lq, lt);
            pb_retarget_apply(r, (const double (*)[4])lq, (const double (*)[3])lt, 0.1, &pose);
            pb_pose_free(&pose);
        }
        pb_retarget_free(r);
    }
    pb_channel ch[2] = {{.name = "A", .usage = 0x00010030}, {.name = "B", .usage = 0x00010031}};
    pb_chanmap *cm;
    if (pb_chanmap_create(m, ch, 2, rig, &cm, &err) == POSE_OK) {
        uint32_t idx[2] = {0, 1};
        double val[2] = {0.5, -3};
        pb_update u = {.t_ns = 1000, .count = 2, .channels = idx, .values = val};
        pb_chanmap_update(cm, &u);
        pb_pose pose;
        if (pb_pose_init(&pose, rig->joint_count) == 0) {
            pb_chanmap_pose(cm, &pose);
            pb_pose_free(&pose);
        }
        pb_chanmap_free(cm);
    }
    pb_mapping_free(m);
    return 0;
}
