/* SPDX-License-Identifier: Apache-2.0 */
#include "cli_rig.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mocap.h"
#include "rig_skel.h"

static int ends_with(const char *s, const char *suf)
{
    size_t n = strlen(s), m = strlen(suf);
    return n >= m && strcmp(s + n - m, suf) == 0;
}

static pose_status skeleton_rig(const pb_rig_skel *skel, pose_rig **out, char *err, size_t err_size)
{
    pose_joint_desc *d = calloc((size_t)skel->joint_count, sizeof *d);
    if (!d) {
        snprintf(err, err_size, "out of memory");
        return POSE_ERR_OUT_OF_MEMORY;
    }
    for (int j = 0; j < skel->joint_count; j++) {
        const pb_rig_joint *J = &skel->joints[j];
        d[j].name = J->name;
        d[j].parent = J->parent;
        for (int k = 0; k < 4; k++)
            d[j].rest_model.rotation[k] = (float)J->rest_q[k];
        for (int k = 0; k < 3; k++)
            d[j].rest_model.translation[k] = (float)J->rest_p[k];
    }
    /* A rig needs a tet mesh: one small tet on the root, moving with it. */
    static const float tet_p[12] = {0, 0, 0, 0.01f, 0, 0, 0, 0.01f, 0, 0, 0, 0.01f};
    static const uint32_t tet[4] = {0, 1, 2, 3};
    static const uint16_t label[1] = {0}, wj[4] = {0, 0, 0, 0};
    static const float w[4] = {1, 1, 1, 1};
    pose_rig_desc desc = {.joint_count = (size_t)skel->joint_count, .joints = d, .tet_vertex_count = 4,
                          .tet_positions = tet_p, .tet_count = 1, .tets = tet, .tet_labels = label,
                          .influences = 1, .weight_joints = wj, .weights = w};
    pose_status s = pose_rig_create(&desc, NULL, out);
    if (s < 0)
        snprintf(err, err_size, "%s", pose_last_error());
    free(d);
    return s;
}

pose_status pb_cli_rig_load(const char *arg, const char *clip, const char *skeleton, pose_rig **out, char *err,
                            size_t err_size)
{
    *out = NULL;
    if (!ends_with(arg, ".bvh") && !ends_with(arg, ".asf") && strcmp(arg, "self") != 0) {
        pose_status s = pose_rig_load(arg, out);
        if (s < 0)
            snprintf(err, err_size, "%s", pose_last_error());
        return s;
    }
    pb_error pe = {{0}};
    pb_clip *c = NULL;
    pb_rig_skel *skel = NULL;
    pose_status s = strcmp(arg, "self") == 0 ? pb_clip_load(clip, skeleton, &c, &pe) : pb_clip_load(arg, NULL, &c, &pe);
    if (s >= 0)
        s = pb_rig_skel_from_clip(c, 1.0, &skel, &pe);
    if (s >= 0)
        s = skeleton_rig(skel, out, err, err_size);
    else
        snprintf(err, err_size, "%s", pe.message);
    pb_rig_skel_free(skel);
    pb_clip_free(c);
    return s;
}
