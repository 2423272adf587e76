/* SPDX-License-Identifier: Apache-2.0 */
/* Quiet clusters of the contact response (contact_quiet.h). */
#include "contact_quiet.h"

#include <string.h>

#include "contact_push.h"
#include "error.h"

/* Rounding room on the test (rig units: 10 micrometres on pose-bake's
 * metres): the bounds and moves are floats, the running moves doubles. */
#define QUIET_SLACK 1e-5
/* ... and on each frame's move where a frame changed. */
#define MOVE_SLACK 1e-6f
/* Most doublings of a moving cluster's wait between snapshots (16 passes:
 * a cluster that stops is quiet again within that many). */
#define QUIET_BACKOFF 4

pose_status pose__quiet_joints_build(pose__quiet_joints *qj, size_t joints, const pose_allocator *a)
{
    qj->count = joints;
    qj->set = 0;
    qj->frames = pose__alloc(a, (12 * joints + 1) * sizeof *qj->frames, POSE__ALIGN);
    qj->pairs = pose__alloc(a, (7 * joints * joints + 1) * sizeof *qj->pairs, POSE__ALIGN);
    qj->motion = pose__calloc(a, (joints * joints + 1) * sizeof *qj->motion, POSE__ALIGN);
    if (!qj->frames || !qj->pairs || !qj->motion)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu joints of the contact response", joints);
    return POSE_OK;
}

void pose__quiet_joints_release(pose__quiet_joints *qj, const pose_allocator *a)
{
    pose__free(a, qj->frames);
    pose__free(a, qj->pairs);
    pose__free(a, qj->motion);
    memset(qj, 0, sizeof *qj);
}

/* x (posed) into the rest frame of frame f: R^T (x - t). */
static void to_frame(const float *f, const float *x, float *q)
{
    const float d[3] = {x[0] - f[9], x[1] - f[10], x[2] - f[11]};
    for (int c = 0; c < 3; c++)
        q[c] = f[c] * d[0] + f[3 + c] * d[1] + f[6 + c] * d[2];
}

/* Pair (R, J): J's rotation in R's frame is g = conj(q_R) q_J, and its
 * bones' sphere's centre there R_R^T (F_J(c) - t_R). Between two frames a
 * point u of that sphere (radius r) moves in R's frame by at most
 * |rot(g') - rot(g)| r + the centre's move, and for unit quaternions
 * |rot(g') - rot(g)| = 2 sin(theta / 2) <= 2 min(|g' - g|, |g' + g|)
 * (|g' -+ g| = 2 sin(theta / 4)), differences of nearby numbers that keep
 * their precision where the angle is small. */
void pose__quiet_joints_update(pose__quiet_joints *qj, const pose__xform *skin, const float *spheres)
{
    const size_t n = qj->count;
    for (size_t k = 0; k < n; k++) {
        pose__quat_to_matrix(skin[k].q, qj->frames + 12 * k);
        memcpy(qj->frames + 12 * k + 9, skin[k].t, 3 * sizeof(float));
    }
    for (size_t r = 0; r < n; r++) {
        float inv[4];
        pose__quat_conj(inv, skin[r].q);
        for (size_t j = 0; j < n; j++) {
            const float *s = spheres + 8 * j;
            if (j == r || !(s[3] >= 0.0f))
                continue;
            float now[7], c[3];
            pose__quat_mul(now, inv, skin[j].q);
            const float *fj = qj->frames + 12 * j;
            for (int e = 0; e < 3; e++)
                c[e] = fj[3 * e] * s[0] + fj[3 * e + 1] * s[1] + fj[3 * e + 2] * s[2] + fj[9 + e];
            to_frame(qj->frames + 12 * r, c, now + 4);
            float *was = qj->pairs + 7 * (r * n + j);
            if (qj->set && memcmp(was, now, sizeof now) != 0) {
                float minus = 0.0f, plus = 0.0f, moved = 0.0f;
                for (int e = 0; e < 4; e++) {
                    minus += (now[e] - was[e]) * (now[e] - was[e]);
                    plus += (now[e] + was[e]) * (now[e] + was[e]);
                }
                for (int e = 4; e < 7; e++)
                    moved += (now[e] - was[e]) * (now[e] - was[e]);
                const float turn = 2.0f * sqrtf(minus < plus ? minus : plus);
                qj->motion[r * n + j] += (double)((turn + MOVE_SLACK) * s[3] + sqrtf(moved) + MOVE_SLACK);
            }
            memcpy(was, now, sizeof now);
        }
    }
    qj->set = 1;
}

pose_status pose__quiet_build(pose__quiet *q, size_t clusters, size_t joints, const pose_allocator *a)
{
    q->clusters = clusters;
    q->joints = joints;
    q->points = pose__alloc(a, (3 * POSE__PUSH_CLUSTER * clusters + 1) * sizeof *q->points, POSE__ALIGN);
    q->frame = pose__alloc(a, (clusters + 1) * sizeof *q->frame, POSE__ALIGN);
    q->frame_then = pose__alloc(a, (12 * clusters + 1) * sizeof *q->frame_then, POSE__ALIGN);
    q->clear = pose__alloc(a, (clusters * joints + 1) * sizeof *q->clear, POSE__ALIGN);
    q->held = pose__calloc(a, clusters + 1, POSE__ALIGN);
    q->wait = pose__calloc(a, clusters + 1, POSE__ALIGN);
    q->misses = pose__calloc(a, clusters + 1, POSE__ALIGN);
    if (!q->points || !q->frame || !q->frame_then || !q->clear || !q->held || !q->wait || !q->misses)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu clusters of the contact response", clusters);
    for (size_t c = 0; c < clusters; c++)
        q->frame[c] = -1;
    return POSE_OK;
}

void pose__quiet_release(pose__quiet *q, const pose_allocator *a)
{
    pose__free(a, q->points);
    pose__free(a, q->frame);
    pose__free(a, q->frame_then);
    pose__free(a, q->clear);
    pose__free(a, q->held);
    pose__free(a, q->wait);
    pose__free(a, q->misses);
    memset(q, 0, sizeof *q);
}

/* Whether the snapshot of cluster c still proves it farther than the
 * margin from every bone. */
static int still_clear(const pose__quiet *q, const pose__quiet_joints *qj, float margin, size_t c, const float *pos,
                       const uint32_t *idx, size_t count)
{
    const int32_t r = q->frame[c];
    const double *clear = q->clear + c * q->joints, *motion = qj->motion + (size_t)r * qj->count;
    double room = INFINITY;
    for (size_t j = 0; j < q->joints; j++) {
        const double left = clear[j] - motion[j];
        room = left < room ? left : room;
    }
    room -= (double)margin + QUIET_SLACK;
    if (!(room > 0.0))
        return 0;
    /* the farthest point's move in R's frame, against the room left
     * (squared): |x - T x_then|, T = F_R(now) F_R(then)^-1 = (M, b) */
    const float *then = q->points + 3 * POSE__PUSH_CLUSTER * c, *f = qj->frames + 12 * (size_t)r,
                *g = q->frame_then + 12 * c;
    float m[9], b[3];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            m[3 * i + k] = f[3 * i] * g[3 * k] + f[3 * i + 1] * g[3 * k + 1] + f[3 * i + 2] * g[3 * k + 2];
    for (int i = 0; i < 3; i++)
        b[i] = f[9 + i] - (m[3 * i] * g[9] + m[3 * i + 1] * g[10] + m[3 * i + 2] * g[11]);
    const float room2 = (float)(room * room);
    for (size_t i = 0; i < count; i++) {
        const float *x = pos + 3 * (size_t)(idx ? idx[i] : i), *y = then + 3 * i;
        float d2 = 0.0f;
        for (int e = 0; e < 3; e++) {
            const float d = x[e] - (m[3 * e] * y[0] + m[3 * e + 1] * y[1] + m[3 * e + 2] * y[2] + b[e]);
            d2 += d * d;
        }
        if (!(d2 < room2))
            return 0;
    }
    return 1;
}

pose__quiet_pass pose__quiet_holds(pose__quiet *q, const pose__quiet_joints *qj, float margin, size_t c,
                                   const float *pos, const uint32_t *idx, size_t count)
{
    q->held[c] = 0;
    if (q->wait[c] > 0) /* the last snapshot failed: a new one when the wait ends */
        return --q->wait[c] > 0 ? POSE__QUIET_SEARCH : POSE__QUIET_RECORD;
    if (q->frame[c] >= 0 && still_clear(q, qj, margin, c, pos, idx, count)) {
        q->held[c] = 1;
        q->misses[c] = 0;
        return POSE__QUIET_HOLDS;
    }
    /* failed, or no snapshot that could hold (none yet, or a point near bone) */
    q->misses[c] += q->misses[c] < QUIET_BACKOFF;
    q->wait[c] = (uint8_t)((1u << q->misses[c]) - 1u);
    return q->wait[c] > 0 ? POSE__QUIET_SEARCH : POSE__QUIET_RECORD;
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

void pose__quiet_end(pose__quiet *q, const pose__quiet_joints *qj, float margin, size_t c, const float *bound)
{
    size_t r = 0; /* the joint whose bones are nearest */
    for (size_t j = 1; j < q->joints; j++)
        r = bound[j] < bound[r] ? j : r;
    q->frame[c] = -1;
    if (!(bound[r] > margin)) /* a point near bone: not quiet before its next full pass */
        return;
    q->frame[c] = (int32_t)r;
    memcpy(q->frame_then + 12 * c, qj->frames + 12 * r, 12 * sizeof(float));
    double *clear = q->clear + c * q->joints;
    const double *motion = qj->motion + r * qj->count;
    for (size_t j = 0; j < q->joints; j++)
        clear[j] = (double)bound[j] + motion[j];
}
