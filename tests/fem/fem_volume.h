/* SPDX-License-Identifier: Apache-2.0 */
/* Geometry helpers of the FEM tests. */
#ifndef POSE_TEST_FEM_VOLUME_H
#define POSE_TEST_FEM_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include "pose/pose.h"

/** Volume enclosed by a closed, outward-oriented triangle mesh (divergence
 *  theorem: sum of a . (b x c) / 6), in double. */
static inline double fx_mesh_volume(const float *p, const uint32_t *tri, size_t n)
{
    double v = 0.0;
    for (size_t f = 0; f < n; f++) {
        const float *a = p + 3 * (size_t)tri[3 * f], *b = p + 3 * (size_t)tri[3 * f + 1],
                    *c = p + 3 * (size_t)tri[3 * f + 2];
        v += (double)a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) +
             (double)a[1] * ((double)b[2] * c[0] - (double)b[0] * c[2]) +
             (double)a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
    }
    return v / 6.0;
}

static inline void fx_rotate(const float q[4], const double v[3], double out[3])
{
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double cx = y * v[2] - z * v[1], cy = z * v[0] - x * v[2], cz = x * v[1] - y * v[0];
    out[0] = v[0] + 2.0 * (w * cx + y * cz - z * cy);
    out[1] = v[1] + 2.0 * (w * cy + z * cx - x * cz);
    out[2] = v[2] + 2.0 * (w * cz + x * cy - y * cx);
}

/** Largest distance of posed points from rest points moved by world * rest^-1. */
static inline double fx_rigid_deviation(const pose_transform *rest, const pose_transform *world,
                                        const float *rest_pos, const float *pos, size_t n)
{
    const float qi[4] = {-rest->rotation[0], -rest->rotation[1], -rest->rotation[2],
                         rest->rotation[3]};
    double worst = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d[3] = {(double)rest_pos[3 * i] - rest->translation[0],
                       (double)rest_pos[3 * i + 1] - rest->translation[1],
                       (double)rest_pos[3 * i + 2] - rest->translation[2]};
        double l[3], m[3];
        fx_rotate(qi, d, l);
        fx_rotate(world->rotation, l, m);
        double e = 0.0;
        for (int a = 0; a < 3; a++) {
            double r = m[a] + world->translation[a] - pos[3 * i + a];
            e += r * r;
        }
        if (e > worst)
            worst = e;
    }
    return sqrt(worst);
}

#endif /* POSE_TEST_FEM_VOLUME_H */
