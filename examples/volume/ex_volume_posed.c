/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_volume_posed.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ex_volume_posed_open(ex_volume_posed *v, const pose_rig *rig, int threads, char *err,
                         size_t err_size)
{
    memset(v, 0, sizeof *v);
    pose_rig_volume rv;
    if (pose_rig_volume_count(rig) == 0 || pose_rig_get_volume(rig, 0, &rv) != POSE_OK) {
        snprintf(err, err_size, "the rig holds no scan (bake it with pose-bake --labels)");
        return -1;
    }
    v->grid = rv.grid;
    v->n[0] = (int)rv.grid.nx, v->n[1] = (int)rv.grid.ny, v->n[2] = (int)rv.grid.nz;
    for (int a = 0; a < 3; a++)
        v->spacing[a] = sqrt((double)rv.grid.affine[0][a] * rv.grid.affine[0][a] +
                             (double)rv.grid.affine[1][a] * rv.grid.affine[1][a] +
                             (double)rv.grid.affine[2][a] * rv.grid.affine[2][a]);
    const size_t nv = (size_t)rv.grid.nx * rv.grid.ny * rv.grid.nz;
    v->hu = rv.intensity ? malloc(nv * sizeof *v->hu) : NULL;
    v->labels = rv.labels ? malloc(nv * sizeof *v->labels) : NULL;
    if ((rv.intensity && !v->hu) || (rv.labels && !v->labels)) {
        snprintf(err, err_size, "out of memory for the scan's %zu voxels", nv);
        ex_volume_posed_close(v);
        return -1;
    }
    /* -1024 HU: air outside the posed body, as the scanner has it */
    const pose_volume_desc rest = {rv.grid, rv.intensity, rv.labels, -1024.0f, 0};
    if (pose_volume_sampler_create(rig, &rest, NULL, threads, NULL, &v->sampler) != POSE_OK) {
        snprintf(err, err_size, "the scan: %s", pose_last_error());
        ex_volume_posed_close(v);
        return -1;
    }
    return 0;
}

int ex_volume_posed_update(ex_volume_posed *v, const pose_state *state, char *err, size_t err_size)
{
    if (pose_volume_sample(v->sampler, state, v->hu, v->labels) != POSE_OK) {
        snprintf(err, err_size, "posing the scan: %s", pose_last_error());
        return -1;
    }
    return 0;
}

void ex_volume_posed_index(const ex_volume_posed *v, const float p[3], int c[3])
{
    /* model -> index: the grid's columns are orthogonal (a scanner grid), so
     * each index is the projection on its column over the column's length^2. */
    for (int a = 0; a < 3; a++) {
        double dot = 0;
        for (int r = 0; r < 3; r++)
            dot += (double)v->grid.affine[r][a] * (p[r] - v->grid.affine[r][3]);
        long idx = lround(dot / (v->spacing[a] * v->spacing[a]));
        c[a] = idx < 0 ? 0 : idx >= v->n[a] ? v->n[a] - 1 : (int)idx;
    }
}

void ex_volume_posed_close(ex_volume_posed *v)
{
    pose_volume_sampler_free(v->sampler);
    free(v->hu);
    free(v->labels);
    memset(v, 0, sizeof *v);
}
