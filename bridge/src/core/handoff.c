/* SPDX-License-Identifier: Apache-2.0 */
#include "handoff.h"

#include <stdlib.h>
#include <string.h>

#define PB_HANDOFF_FRESH 4u

int pb_pose_init(pb_pose *p, int joints)
{
    memset(p, 0, sizeof *p);
    size_t n = joints > 0 ? (size_t)joints : 1;
    p->q = malloc(n * sizeof *p->q);
    p->active = malloc(n);
    if (!p->q || !p->active) {
        pb_pose_free(p);
        return -1;
    }
    p->joint_count = joints;
    pb_pose_reset(p);
    return 0;
}

void pb_pose_free(pb_pose *p)
{
    free(p->q);
    free(p->active);
    p->q = NULL;
    p->active = NULL;
    p->joint_count = 0;
}

void pb_pose_reset(pb_pose *p)
{
    for (int j = 0; j < p->joint_count; j++) {
        p->q[j][0] = p->q[j][1] = p->q[j][2] = 0.0f;
        p->q[j][3] = 1.0f;
        p->active[j] = 0;
    }
    p->root_t[0] = p->root_t[1] = p->root_t[2] = 0.0f;
    p->root_q[0] = p->root_q[1] = p->root_q[2] = 0.0f;
    p->root_q[3] = 1.0f;
    p->has_root = 0;
    p->frame = -1;
}

void pb_pose_copy(pb_pose *dst, const pb_pose *src)
{
    size_t n = (size_t)(src->joint_count < dst->joint_count ? src->joint_count : dst->joint_count);
    memcpy(dst->q, src->q, n * sizeof *src->q);
    memcpy(dst->active, src->active, n);
    memcpy(dst->root_t, src->root_t, sizeof dst->root_t);
    memcpy(dst->root_q, src->root_q, sizeof dst->root_q);
    dst->has_root = src->has_root;
    dst->t_ns = src->t_ns;
    dst->lag_ns = src->lag_ns;
    dst->media_s = src->media_s;
    dst->frame = src->frame;
    dst->seq = src->seq;
}

int pb_handoff_init(pb_handoff *h, int joints)
{
    memset(h, 0, sizeof *h);
    for (int i = 0; i < 3; i++)
        if (pb_pose_init(&h->slot[i], joints) != 0) {
            pb_handoff_free(h);
            return -1;
        }
    h->back = 0;
    atomic_init(&h->middle, 1u);
    h->front = 2;
    return 0;
}

void pb_handoff_free(pb_handoff *h)
{
    for (int i = 0; i < 3; i++)
        pb_pose_free(&h->slot[i]);
}

pb_pose *pb_handoff_back(pb_handoff *h) { return &h->slot[h->back]; }

void pb_handoff_publish(pb_handoff *h)
{
    h->slot[h->back].seq = ++h->seq;
    /* release: the slot's contents happen-before the reader's acquire */
    unsigned old = atomic_exchange_explicit(&h->middle, h->back | PB_HANDOFF_FRESH, memory_order_acq_rel);
    h->back = old & 3u;
}

const pb_pose *pb_handoff_latest(pb_handoff *h, int *fresh)
{
    int got = 0;
    if (atomic_load_explicit(&h->middle, memory_order_relaxed) & PB_HANDOFF_FRESH) {
        unsigned old = atomic_exchange_explicit(&h->middle, h->front, memory_order_acq_rel);
        h->front = old & 3u;
        got = 1;
    }
    if (fresh)
        *fresh = got;
    return &h->slot[h->front];
}
