/* SPDX-License-Identifier: Apache-2.0 */
#include "rt_transfer.h"

#include "rt_kernels.h"

#include <math.h>

size_t pose__transfer(const pose__transfer_mesh *mesh, const float *tet_positions, size_t begin,
                      size_t end, float *pos, float *nrm, uint32_t *flagged)
{
    if (begin >= end)
        return 0;
#ifdef POSE__HAVE_AVX2_KERNELS
    if (pose__kernels_use_avx2())
        return pose__transfer_blocks_avx2(mesh, tet_positions, begin, end, pos, nrm, flagged);
#endif
    return pose__transfer_blocks_generic(mesh, tet_positions, begin, end, pos, nrm, flagged);
}

void pose__transfer_fix_normals(const pose__transfer_mesh *mesh, const float *pos,
                                const uint32_t *flagged, size_t count, float *nrm)
{
    for (size_t i = 0; i < count; i++) {
        const uint32_t v = flagged[i];
        const float *p = pos + 3 * (size_t)v;
        float nx = 0.0f, ny = 0.0f, nz = 0.0f;
        for (uint32_t f = mesh->fan_offset[v]; f < mesh->fan_offset[v + 1]; f++) {
            const float *a = pos + 3 * (size_t)mesh->fan[2 * (size_t)f];
            const float *b = pos + 3 * (size_t)mesh->fan[2 * (size_t)f + 1];
            float ux = a[0] - p[0], uy = a[1] - p[1], uz = a[2] - p[2];
            float wx = b[0] - p[0], wy = b[1] - p[1], wz = b[2] - p[2];
            nx += uy * wz - uz * wy;
            ny += uz * wx - ux * wz;
            nz += ux * wy - uy * wx;
        }
        float n2 = nx * nx + ny * ny + nz * nz;
        float s = n2 > 1e-36f ? 1.0f / sqrtf(n2) : 0.0f;
        nrm[3 * (size_t)v + 0] = nx * s;
        nrm[3 * (size_t)v + 1] = ny * s;
        nrm[3 * (size_t)v + 2] = nz * s;
    }
}

size_t pose__transfer_bytes(const pose__transfer_mesh *mesh, size_t tet_vertex_count,
                            int normals)
{
    /* per vertex: 4 tet indices, 3 coordinates, position out; key and
     * normal out with normals; plus every deformed tet vertex read once */
    size_t per = 16 + 12 + 12 + (normals ? 6 + 12 : 0);
    return mesh->block_count * POSE__BLOCK * per + 12 * tet_vertex_count;
}
