/* SPDX-License-Identifier: Apache-2.0
 * The queued voxels of a slab (volume_raster_body.h) sampled from the rest
 * image: intensity trilinear, label of the nearest voxel; a preimage more
 * than half a voxel outside the image gets the background (the scan has
 * no data there), within that margin it is clamped to the image. The
 * generic variant here; volume_gather_avx2.c does eight at a time with the
 * same IEEE operations in the same order, so both give the same bytes. */
#include "volume_internal.h"

/* v clamped to [0, hi]; NaN -> 0 (a preimage gone bad still reads inside
 * the image). */
static inline float clamp_index(float v, float hi)
{
    v = v > 0.0f ? v : 0.0f;
    return v < hi ? v : hi;
}

void pose__volume_gather_generic(const pose_volume_desc *rest, const pose__vol_stage *st,
                                 unsigned begin, float *oi, uint16_t *ol)
{
    const pose__vol_cells c = pose__vol_cells_of(&rest->grid);
    const float *img = rest->intensity;
    const uint16_t *lb = rest->labels;
    for (unsigned e = begin; e < st->n; e++) {
        const size_t at = st->at[e];
        float x = st->x[e], y = st->y[e], z = st->z[e];
        if (x < -0.5f || y < -0.5f || z < -0.5f || x > c.out[0] || y > c.out[1] || z > c.out[2]) {
            if (ol)
                ol[at] = rest->label_background;
            if (oi)
                oi[at] = rest->intensity_background;
            continue;
        }
        x = clamp_index(x, c.top[0]), y = clamp_index(y, c.top[1]), z = clamp_index(z, c.top[2]);
        /* the cell: its lower corner at most n - 2 (the top plane samples
         * the cell below it at fraction 1) */
        int xi = (int)x, yi = (int)y, zi = (int)z;
        xi = xi < c.last_cell[0] ? xi : c.last_cell[0];
        yi = yi < c.last_cell[1] ? yi : c.last_cell[1];
        zi = zi < c.last_cell[2] ? zi : c.last_cell[2];
        const float fx = x - (float)xi, fy = y - (float)yi, fz = z - (float)zi;
        const size_t base = (size_t)zi * c.plane + (size_t)yi * c.row + (size_t)xi;
        const size_t sx = c.step[0], sy = c.step[1], sz = c.step[2];
        /* The nearest voxel without a branch: which side of 0.5 a fraction
         * falls on is data, not a pattern a predictor learns. */
        if (ol)
            ol[at] = lb[base + (size_t)(fx >= 0.5f) * sx + (size_t)(fy >= 0.5f) * sy +
                        (size_t)(fz >= 0.5f) * sz];
        if (!oi)
            continue;
        const float *p = img + base;
        const float c00 = p[0] + fx * (p[sx] - p[0]);
        const float c10 = p[sy] + fx * (p[sy + sx] - p[sy]);
        const float c01 = p[sz] + fx * (p[sz + sx] - p[sz]);
        const float c11 = p[sz + sy] + fx * (p[sz + sy + sx] - p[sz + sy]);
        const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
        oi[at] = c0 + fz * (c1 - c0);
    }
}

void pose__volume_gather(const pose_volume_sampler *s, pose__vol_stage *st)
{
    unsigned done = 0;
#ifdef POSE__HAVE_AVX2_VOLUME
    if (s->use_avx2 && s->dst_intensity && s->dst_labels)
        done = pose__volume_gather_avx2(&s->rest, st, s->dst_intensity, s->dst_labels);
#endif
    pose__volume_gather_generic(&s->rest, st, done, s->dst_intensity, s->dst_labels);
    st->n = 0;
}
