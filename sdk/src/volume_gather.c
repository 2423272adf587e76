/* SPDX-License-Identifier: Apache-2.0
 * The queued voxels of a slab (volume_raster.c) sampled from the rest
 * image: intensity trilinear, label of the nearest voxel. The generic
 * variant here; volume_gather_avx2.c does eight at a time with the same
 * IEEE operations in the same order, so both give the same bytes. */
#include "volume_internal.h"

void pose__volume_gather_generic(const pose_volume_desc *rest, const pose__vol_stage *st,
                                 unsigned begin, float *oi, uint16_t *ol)
{
    const size_t sy = rest->grid.nx, sz = (size_t)rest->grid.nx * rest->grid.ny;
    const float *img = rest->intensity;
    const uint16_t *lb = rest->labels;
    for (unsigned e = begin; e < st->n; e++) {
        const float x = st->x[e], y = st->y[e], z = st->z[e];
        const int xi = (int)x, yi = (int)y, zi = (int)z;
        const float fx = x - (float)xi, fy = y - (float)yi, fz = z - (float)zi;
        const size_t base = (size_t)zi * sz + (size_t)yi * sy + (size_t)xi, at = st->at[e];
        /* The nearest voxel without a branch: which side of 0.5 a fraction
         * falls on is data, not a pattern a predictor learns. */
        if (ol)
            ol[at] = lb[base + (size_t)(fx >= 0.5f) + (size_t)(fy >= 0.5f) * sy +
                        (size_t)(fz >= 0.5f) * sz];
        if (!oi)
            continue;
        const float *p = img + base;
        const float c00 = p[0] + fx * (p[1] - p[0]);
        const float c10 = p[sy] + fx * (p[sy + 1] - p[sy]);
        const float c01 = p[sz] + fx * (p[sz + 1] - p[sz]);
        const float c11 = p[sz + sy] + fx * (p[sz + sy + 1] - p[sz + sy]);
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
