/* SPDX-License-Identifier: Apache-2.0
 * The rest cover: which tets hold each output voxel at rest, so that the
 * voxels of tets a pose leaves where they rest are copied from the rest
 * image instead of rasterized and resampled.
 *
 * Only when the output grid is the rest grid (the default): then a tet
 * whose four vertices have the same index-space bits posed as at rest maps
 * each voxel to itself. Most of a patient stays put when a few joints
 * move (hip_l flexed 45 deg leaves 84 % of the bundled CT's tets where they
 * rest), and rasterizing a tet costs the same whether it moved or not.
 *
 * Tets are grouped in blocks of 2^block_shift consecutive tets (TetGen's
 * order is spatially coherent), so that a block id fits 16 bits: 2 bytes a
 * voxel. A voxel's owner is the block of the tet the slab pass would
 * rasterize first at rest (the highest index holding its centre); a block
 * is still when all its tets lie where they rest. Per call, each slab
 * rasterizes the tets of the other blocks first, then copies the voxels
 * whose owner is still and that no moved tet took: where a moved part
 * folds into one that stayed (a thigh flexed into the belly), the moved
 * one shows. */
#include <string.h>

#include "volume_internal.h"

/* Block size so that every block id is below POSE__VOL_NO_OWNER. */
static unsigned block_shift_for(size_t tets)
{
    unsigned shift = 0;
    while (((tets + ((size_t)1 << shift) - 1) >> shift) >= POSE__VOL_NO_OWNER)
        shift++;
    return shift;
}

int pose__vol_rest_cover_wanted(const pose_volume_grid *rest, const pose_volume_grid *out)
{
    return memcmp(rest, out, sizeof *rest) == 0;
}

size_t pose__vol_rest_cover_bytes(const pose_volume_grid *out)
{
    return (size_t)out->nx * out->ny * out->nz * sizeof(uint16_t) +
           (POSE__VOL_NO_OWNER + 1) * sizeof(uint8_t);
}

void pose__vol_rest_cover_init(pose_volume_sampler *s, uint16_t *owner, uint8_t *still)
{
    s->block_shift = block_shift_for(s->tet_count);
    s->owner = owner;
    s->block_still = still;
    memset(still, 0, POSE__VOL_NO_OWNER + 1); /* POSE__VOL_NO_OWNER stays 0 */
    memset(owner, 0xff, (size_t)s->out.nx * s->out.ny * s->out.nz * sizeof *owner);
}

void pose__vol_rest_cover_blocks(pose_volume_sampler *s, size_t block0, size_t block1)
{
    const unsigned shift = s->block_shift;
    for (size_t b = block0; b < block1; b++) {
        const size_t t0 = b << shift, t1 = (b + 1) << shift < s->tet_count ? (b + 1) << shift
                                                                           : s->tet_count;
        int still = 1;
        for (size_t t = t0; t < t1; t++)
            still &= s->boxes[t].identity;
        s->block_still[b] = (uint8_t)still;
    }
}

void pose__vol_rest_cover_copy(const pose_volume_sampler *s, size_t k0, size_t k1)
{
    const size_t nx = s->out.nx, ny = s->out.ny, plane = nx * ny;
    const uint8_t *still = s->block_still;
    const float *ri = s->rest.intensity;
    const uint16_t *rl = s->rest.labels;
    float *oi = s->dst_intensity;
    uint16_t *ol = s->dst_labels;
    for (size_t k = k0; k < k1; k++)
        for (size_t j = 0; j < ny; j++) {
            const size_t row = k * plane + j * nx;
            const uint16_t *own = s->owner + row;
            uint64_t *w = pose__vol_cover_row(s, j, k);
            for (size_t x = 0; x < s->cover_words; x++) {
                const size_t i0 = 64 * x, n = nx - i0 < 64 ? nx - i0 : 64;
                uint64_t m = 0;
                for (size_t i = 0; i < n; i++)
                    m |= (uint64_t)still[own[i0 + i]] << i;
                const uint64_t take = m & ~w[x]; /* not taken by a moved tet */
                w[x] |= m;
                if (take == ~(uint64_t)0) { /* inside the body, 64 at once */
                    if (oi)
                        memcpy(oi + row + i0, ri + row + i0, 64 * sizeof *oi);
                    if (ol)
                        memcpy(ol + row + i0, rl + row + i0, 64 * sizeof *ol);
                    continue;
                }
                for (uint64_t b = take; b; b &= b - 1) {
                    const size_t v = row + i0 + (size_t)__builtin_ctzll(b);
                    if (oi)
                        oi[v] = ri[v];
                    if (ol)
                        ol[v] = rl[v];
                }
            }
        }
}
