/* SPDX-License-Identifier: Apache-2.0 */
#include "mocap_source.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"

typedef struct mocap_source {
    pb_source base;
    const pb_clip *clip;
    double speed;
    int loop;
    size_t next;       /* next frame to deliver */
    int64_t anchor_ns; /* wall time at which frame `anchor_frame` is due */
    size_t anchor_frame;
    uint32_t *index;   /* 0..n-1 */
} mocap_source;

static const char *const CHAN_NAMES[7] = {"Xposition", "Yposition", "Zposition", "Xrotation",
                                          "Yrotation", "Zrotation", "length"};

static int64_t due_ns(const mocap_source *m, size_t f)
{
    double dt = (double)(f - m->anchor_frame) * m->clip->frame_time / m->speed;
    return m->anchor_ns + (int64_t)llround(dt * 1e9);
}

static int mocap_read(pb_source *src, pb_update *out, int timeout_ms)
{
    mocap_source *m = (mocap_source *)src;
    const pb_clip *c = m->clip;
    if (m->next >= c->frame_count) {
        if (!m->loop || c->frame_count == 0) {
            if (src->state != PB_SOURCE_ENDED)
                pb_source_set_state(src, PB_SOURCE_ENDED, "%s: end of clip after %zu frames", c->path,
                                    c->frame_count);
            return -1;
        }
        /* loop: frame 0 follows the last one a frame time later */
        int64_t wrap = due_ns(m, m->next);
        m->next = 0;
        m->anchor_frame = 0;
        m->anchor_ns = wrap;
    }
    if (m->speed > 0.0) {
        int64_t due = due_ns(m, m->next), now = pb_now_ns();
        if (due > now) {
            if (timeout_ms == 0)
                return 0;
            int64_t limit = timeout_ms < 0 ? due : now + (int64_t)timeout_ms * 1000000;
            pb_sleep_until_ns(due < limit ? due : limit);
            if (pb_now_ns() < due)
                return 0;
        }
    }
    if (src->state != PB_SOURCE_OK)
        pb_source_set_state(src, PB_SOURCE_OK, NULL);
    out->t_ns = (int64_t)llround((double)m->next * c->frame_time * 1e9);
    out->count = (size_t)c->channel_count;
    out->channels = m->index;
    out->values = pb_clip_frame(c, m->next);
    m->next++;
    return 1;
}

static int mocap_seek(pb_source *src, int64_t t_ns)
{
    mocap_source *m = (mocap_source *)src;
    double f = (double)t_ns * 1e-9 / m->clip->frame_time;
    if (!(f >= 0.0))
        f = 0.0;
    size_t k = (size_t)llround(f);
    if (k >= m->clip->frame_count)
        k = m->clip->frame_count ? m->clip->frame_count - 1 : 0;
    m->next = k;
    m->anchor_frame = k;
    m->anchor_ns = pb_now_ns();
    if (src->state == PB_SOURCE_ENDED)
        pb_source_set_state(src, PB_SOURCE_WAITING, NULL);
    return 0;
}

static void mocap_close(pb_source *src)
{
    mocap_source *m = (mocap_source *)src;
    free(m->index);
    free(src->channels);
    m->index = NULL;
    src->channels = NULL;
}

static const pb_source_ops MOCAP_OPS = {"mocap", mocap_read, mocap_seek, mocap_close};

pose_status pb_mocap_source_open(const pb_clip *clip, double speed, int loop, pb_source **out, pb_error *err)
{
    if (!clip || !out || speed < 0.0 || !isfinite(speed))
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_mocap_source_open: bad argument");
    *out = NULL;
    mocap_source *m = calloc(1, sizeof *m);
    size_t n = (size_t)clip->channel_count;
    if (m) {
        m->index = malloc((n ? n : 1) * sizeof *m->index);
        m->base.channels = calloc(n ? n : 1, sizeof *m->base.channels);
    }
    if (!m || !m->index || !m->base.channels) {
        if (m)
            mocap_close(&m->base);
        free(m);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
    m->base.ops = &MOCAP_OPS;
    m->base.channel_count = n;
    m->base.state = PB_SOURCE_WAITING;
    m->clip = clip;
    m->speed = speed;
    m->loop = loop;
    m->anchor_ns = pb_now_ns();
    for (int j = 0; j < clip->joint_count; j++) {
        const pb_clip_joint *J = &clip->joints[j];
        for (int k = 0; k < J->chan_count; k++) {
            size_t i = (size_t)(J->chan_first + k);
            pb_channel *ch = &m->base.channels[i];
            m->index[i] = (uint32_t)i;
            snprintf(ch->name, sizeof ch->name, "%.50s.%s", J->name, CHAN_NAMES[J->chan[k]]);
            snprintf(ch->unit, sizeof ch->unit, "%s", J->chan[k] >= PB_CH_XROT && J->chan[k] <= PB_CH_ZROT ? "deg" : "");
            if (J->has_limits) {
                ch->min = J->limit_min[k];
                ch->max = J->limit_max[k];
            } else {
                ch->min = 1.0;
                ch->max = 0.0;
            }
        }
    }
    *out = &m->base;
    return POSE_OK;
}
