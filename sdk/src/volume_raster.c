/* SPDX-License-Identifier: Apache-2.0
 * The generic rasterizer (volume_raster_body.h) and what a tet's rest
 * positions say, once per sampler. */
#define POSE__VR(name) name##_generic
#include "volume_raster_body.h"

int pose__volume_rest_flags(const float *r[4])
{
    double E[3][3];
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++)
            E[a][c] = (double)r[c + 1][a] - r[0][a];
    const double det = det3(E);
    return det > 0 ? POSE__VOL_REST_POSITIVE : det < 0 ? POSE__VOL_REST_NEGATIVE : 0;
}
