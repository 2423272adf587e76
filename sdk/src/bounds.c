/* SPDX-License-Identifier: Apache-2.0 */
/* pose_rig_bounds / pose_state_bounds: boxes over the public accessors, so
 * rest and posed boxes come from the same arrays a host reads. */
#include <math.h>

#include "error.h"
#include "pose/pose.h"

static void box_add(const float *xyz, size_t n, float min[3], float max[3])
{
    for (size_t v = 0; v < n; v++)
        for (int k = 0; k < 3; k++) {
            min[k] = fminf(min[k], xyz[3 * v + k]);
            max[k] = fmaxf(max[k], xyz[3 * v + k]);
        }
}

/* The box of `tissue` (-1: every tissue, else the tet mesh) from rest or posed positions. */
static pose_status bounds(const pose_rig *rig, const pose_state *state, int tissue, float min[3], float max[3])
{
    const char *fn = state ? "pose_state_bounds" : "pose_rig_bounds";
    if (!rig || !min || !max)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: NULL argument", fn);
    const int count = (int)pose_rig_tissue_count(rig);
    if (tissue < -1 || tissue >= count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "%s: tissue %d out of range (the rig has %d; -1 for all)", fn,
                          tissue, count);
    for (int k = 0; k < 3; k++) {
        min[k] = INFINITY;
        max[k] = -INFINITY;
    }
    size_t n;
    if (count == 0) { /* a rig of the tet mesh alone */
        pose_tet_info tet;
        pose_rig_tet_info(rig, &tet);
        box_add(state ? pose_tet_positions(state, &n) : tet.rest_positions, tet.vertex_count, min, max);
        return POSE_OK;
    }
    for (int t = tissue < 0 ? 0 : tissue; t < (tissue < 0 ? count : tissue + 1); t++) {
        pose_tissue_info info;
        pose_rig_tissue_info(rig, t, &info);
        box_add(state ? pose_tissue_positions(state, t, &n) : info.rest_positions, info.vertex_count, min, max);
    }
    return POSE_OK;
}

pose_status pose_rig_bounds(const pose_rig *rig, int tissue, float min[3], float max[3])
{
    pose__clear_error();
    return bounds(rig, NULL, tissue, min, max);
}

pose_status pose_state_bounds(const pose_state *state, int tissue, float min[3], float max[3])
{
    pose__clear_error();
    if (!state)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_state_bounds: NULL state");
    return bounds(pose_state_rig(state), state, tissue, min, max);
}
