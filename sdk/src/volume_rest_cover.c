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

/* The arrays, in one allocation: per output row its owned words [first,
 * end) (8 bytes), per voxel its owner (2 bytes), per block its still flag
 * (one byte, for every 16-bit id). */
size_t pose__vol_rest_cover_bytes(const pose_volume_grid *out)
{
    const size_t rows = (size_t)out->ny * out->nz;
    return rows * 2 * sizeof(uint32_t) + rows * out->nx * sizeof(uint16_t) +
           (POSE__VOL_NO_OWNER + 1) * sizeof(uint8_t);
}

void pose__vol_rest_cover_init(pose_volume_sampler *s, void *arrays)
{
    const size_t rows = (size_t)s->out.ny * s->out.nz, voxels = rows * s->out.nx;
    s->block_shift = block_shift_for(s->tet_count);
    s->owned_words = arrays;
    s->owner = (uint16_t *)(s->owned_words + 2 * rows);
    s->block_still = (uint8_t *)(s->owner + voxels);
    memset(s->block_still, 0, POSE__VOL_NO_OWNER + 1); /* POSE__VOL_NO_OWNER stays 0 */
    memset(s->owner, 0xff, voxels * sizeof *s->owner);
}

void pose__vol_rest_cover_rows(pose_volume_sampler *s)
{
    const size_t nx = s->out.nx, rows = (size_t)s->out.ny * s->out.nz;
    for (size_t r = 0; r < rows; r++) {
        const uint16_t *own = s->owner + r * nx;
        size_t lo = 0, hi = nx;
        while (lo < nx && own[lo] == POSE__VOL_NO_OWNER)
            lo++;
        while (hi > lo && own[hi - 1] == POSE__VOL_NO_OWNER)
            hi--;
        s->owned_words[2 * r] = (uint32_t)(lo / 64);
        s->owned_words[2 * r + 1] = lo < hi ? (uint32_t)((hi + 63) / 64) : (uint32_t)(lo / 64);
    }
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

/* The still bits of owners own[0 .. n), n <= 64. */
static inline uint64_t still_bits(const uint8_t *still, const uint16_t *own, size_t n)
{
    uint64_t m = 0;
    size_t i = 0;
    for (; i + 8 <= n; i += 8) /* eight lookups per shift: no loop-carried chain per voxel */
        m |= (uint64_t)(still[own[i]] | still[own[i + 1]] << 1 | still[own[i + 2]] << 2 |
                        still[own[i + 3]] << 3 | still[own[i + 4]] << 4 | still[own[i + 5]] << 5 |
                        still[own[i + 6]] << 6 | still[own[i + 7]] << 7)
             << i;
    for (; i < n; i++)
        m |= (uint64_t)still[own[i]] << i;
    return m;
}

void pose__vol_rest_cover_copy(const pose_volume_sampler *s, size_t k0, size_t k1)
{
    const size_t nx = s->out.nx, ny = s->out.ny;
    const float *ri = s->rest.intensity;
    const uint16_t *rl = s->rest.labels;
    float *oi = s->dst_intensity;
    uint16_t *ol = s->dst_labels;
    for (size_t r = k0 * ny; r < k1 * ny; r++) {
        const size_t row = r * nx;
        uint64_t *w = pose__vol_cover_row(s, r % ny, r / ny);
        for (size_t x = s->owned_words[2 * r]; x < s->owned_words[2 * r + 1]; x++) {
            const size_t i0 = 64 * x, n = nx - i0 < 64 ? nx - i0 : 64;
            const uint64_t m = still_bits(s->block_still, s->owner + row + i0, n);
            uint64_t take = m & ~w[x]; /* not taken by a moved tet */
            w[x] |= m;
            while (take) { /* runs of voxels to copy */
                const int lo = __builtin_ctzll(take);
                const uint64_t after = ~(take >> lo);
                const int len = after ? __builtin_ctzll(after) : 64 - lo;
                const size_t v = row + i0 + (size_t)lo;
                if (oi)
                    memcpy(oi + v, ri + v, (size_t)len * sizeof *oi);
                if (ol)
                    memcpy(ol + v, rl + v, (size_t)len * sizeof *ol);
                take = lo + len < 64 ? take & (~(uint64_t)0 << (lo + len)) : 0;
            }
        }
    }
}
