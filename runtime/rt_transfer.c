/* SPDX-License-Identifier: Apache-2.0 */
#include "rt_transfer.h"

#include "rt_kernels.h"

void pose__transfer(const pose__transfer_mesh *mesh, const float *tet_positions, size_t begin,
                    size_t end, float *pos, float *nrm)
{
    if (begin >= end)
        return;
#ifdef POSE__HAVE_AVX2_KERNELS
    if (pose__kernels_use_avx2()) {
        pose__transfer_blocks_avx2(mesh, tet_positions, begin, end, pos, nrm);
        return;
    }
#endif
    pose__transfer_blocks_generic(mesh, tet_positions, begin, end, pos, nrm);
}

size_t pose__transfer_bytes(const pose__transfer_mesh *mesh, size_t tet_vertex_count,
                            int normals)
{
    /* per vertex: 4 tet indices, 3 coordinates, position out; key and
     * normal out with normals; plus every deformed tet vertex read once */
    size_t per = 16 + 12 + 12 + (normals ? 6 + 12 : 0);
    return mesh->block_count * POSE__BLOCK * per + 12 * tet_vertex_count;
}
