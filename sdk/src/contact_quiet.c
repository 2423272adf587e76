/* SPDX-License-Identifier: Apache-2.0 */
/* Quiet clusters of the contact response (contact_quiet.h). */
#include "contact_quiet.h"

#include <math.h>
#include <string.h>

#include "contact_push.h"
#include "error.h"

/* Rounding room on the test (rig units: 10 micrometres on pose-bake's
 * metres): the bounds and moves are floats, the running moves doubles. */
#define QUIET_SLACK 1e-5

pose_status pose__quiet_build(pose__quiet *q, size_t clusters, size_t joints, const pose_allocator *a)
{
    q->clusters = clusters;
    q->joints = joints;
    q->points = pose__alloc(a, (3 * POSE__PUSH_CLUSTER * clusters + 1) * sizeof *q->points, POSE__ALIGN);
    q->clear = pose__alloc(a, (clusters * joints + 1) * sizeof *q->clear, POSE__ALIGN);
    q->held = pose__calloc(a, clusters + 1, POSE__ALIGN);
    if (!q->points || !q->clear || !q->held)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu clusters of the contact response", clusters);
    pose__quiet_forget(q);
    return POSE_OK;
}

void pose__quiet_release(pose__quiet *q, const pose_allocator *a)
{
    pose__free(a, q->points);
    pose__free(a, q->clear);
    pose__free(a, q->held);
    memset(q, 0, sizeof *q);
}

void pose__quiet_forget(pose__quiet *q)
{
    for (size_t k = 0; k < q->clusters * q->joints; k++)
        q->clear[k] = -INFINITY;
}

int pose__quiet_holds(pose__quiet *q, const double *motion, float margin, size_t c, const float *pos,
                      const uint32_t *idx, size_t count)
{
    q->held[c] = 0;
    const double *clear = q->clear + c * q->joints;
    double room = INFINITY;
    for (size_t j = 0; j < q->joints; j++) {
        const double r = clear[j] - motion[j];
        room = r < room ? r : room;
    }
    room -= (double)margin + QUIET_SLACK;
    if (!(room > 0.0))
        return 0;
    /* the farthest point's move, against the room left (squared) */
    const float *then = q->points + 3 * POSE__PUSH_CLUSTER * c;
    const float room2 = (float)(room * room);
    for (size_t i = 0; i < count; i++) {
        const float *x = pos + 3 * (size_t)(idx ? idx[i] : i), *y = then + 3 * i;
        const float dx = x[0] - y[0], dy = x[1] - y[1], dz = x[2] - y[2];
        if (!(dx * dx + dy * dy + dz * dz < room2))
            return 0;
    }
    q->held[c] = 1;
    return 1;
}

size_t pose__quiet_held(const pose__quiet *q)
{
    size_t n = 0;
    for (size_t c = 0; c < q->clusters; c++)
        n += q->held[c];
    return n;
}

void pose__quiet_begin(pose__quiet *q, size_t c, const float *pos, const uint32_t *idx, size_t count)
{
    float *then = q->points + 3 * POSE__PUSH_CLUSTER * c;
    for (size_t i = 0; i < count; i++)
        memcpy(then + 3 * i, pos + 3 * (size_t)(idx ? idx[i] : i), 3 * sizeof(float));
}

void pose__quiet_end(pose__quiet *q, const double *motion, size_t c, const float *bound)
{
    double *clear = q->clear + c * q->joints;
    for (size_t j = 0; j < q->joints; j++)
        clear[j] = (double)bound[j] + motion[j];
}
