/* SPDX-License-Identifier: Apache-2.0 */
#include "rt_transfer.h"

#include <math.h>

void pose__transfer(const pose__transfer_mesh *mesh, const float *restrict tp, size_t begin,
                    size_t end, float *restrict pos, float *restrict nrm)
{
    const uint32_t *restrict tv = mesh->tet_vertices;
    const float *restrict bary = mesh->bary;
    const int16_t *restrict key = mesh->normal_key;
    for (size_t i = begin; i < end; i++) {
        const float *v0 = tp + 3 * (size_t)tv[4 * i + 0];
        const float *v1 = tp + 3 * (size_t)tv[4 * i + 1];
        const float *v2 = tp + 3 * (size_t)tv[4 * i + 2];
        const float *v3 = tp + 3 * (size_t)tv[4 * i + 3];
        float e1[3], e2[3], e3[3];
        for (int c = 0; c < 3; c++) {
            e1[c] = v1[c] - v0[c];
            e2[c] = v2[c] - v0[c];
            e3[c] = v3[c] - v0[c];
        }
        float b1 = bary[3 * i], b2 = bary[3 * i + 1], b3 = bary[3 * i + 2];
        for (int c = 0; c < 3; c++)
            pos[3 * i + c] = v0[c] + (b1 * e1[c] + b2 * e2[c] + b3 * e3[c]);
        if (!nrm)
            continue;
        float k1 = key[3 * i], k2 = key[3 * i + 1], k3 = key[3 * i + 2];
        /* cof(D') k = k1 (e2 x e3) + k2 (e3 x e1) + k3 (e1 x e2) */
        float nx = k1 * (e2[1] * e3[2] - e2[2] * e3[1]) + k2 * (e3[1] * e1[2] - e3[2] * e1[1]) +
                   k3 * (e1[1] * e2[2] - e1[2] * e2[1]);
        float ny = k1 * (e2[2] * e3[0] - e2[0] * e3[2]) + k2 * (e3[2] * e1[0] - e3[0] * e1[2]) +
                   k3 * (e1[2] * e2[0] - e1[0] * e2[2]);
        float nz = k1 * (e2[0] * e3[1] - e2[1] * e3[0]) + k2 * (e3[0] * e1[1] - e3[1] * e1[0]) +
                   k3 * (e1[0] * e2[1] - e1[1] * e2[0]);
        float n2 = nx * nx + ny * ny + nz * nz;
        /* A flattened tet or a vertex without triangles has no normal. */
        float s = n2 > 1e-36f ? 1.0f / sqrtf(n2) : 0.0f;
        nrm[3 * i + 0] = nx * s;
        nrm[3 * i + 1] = ny * s;
        nrm[3 * i + 2] = nz * s;
    }
}
