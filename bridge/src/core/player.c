/* SPDX-License-Identifier: Apache-2.0 */
#include "player.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pb_math.h"

pose_status pb_player_init(pb_player *p, const pb_clip *clip, int loop, pb_error *err)
{
    memset(p, 0, sizeof *p);
    if (!clip)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_player_init: no clip");
    if (clip->frame_count == 0 && strcmp(clip->format, "asf-amc") == 0) /* an ASF loaded alone */
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT,
                       "%s is a skeleton without motion: open its AMC file (with the ASF as the skeleton)",
                       clip->path);
    if (clip->frame_count == 0)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "%s: the clip has no frames to play", clip->path);
    size_t n = (size_t)(clip->joint_count > 0 ? clip->joint_count : 1);
    p->clip = clip;
    p->loop = loop;
    p->aq = malloc(n * sizeof *p->aq);
    p->bq = malloc(n * sizeof *p->bq);
    p->at = malloc(n * sizeof *p->at);
    p->bt = malloc(n * sizeof *p->bt);
    p->a_frame = p->b_frame = -1;
    if (!p->aq || !p->bq || !p->at || !p->bt) {
        pb_player_free(p);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
    return POSE_OK;
}

void pb_player_free(pb_player *p)
{
    free(p->aq);
    free(p->bq);
    free(p->at);
    free(p->bt);
    memset(p, 0, sizeof *p);
}

double pb_player_duration(const pb_player *p)
{
    return (double)(p->clip->frame_count - 1) * p->clip->frame_time;
}

int pb_player_wrap(const pb_player *p, double media_s, double *clip_s)
{
    double d = pb_player_duration(p);
    if (media_s < 0.0)
        media_s = p->loop && d > 0.0 ? fmod(media_s, d) + d : 0.0;
    if (media_s <= d) {
        *clip_s = media_s;
        return 0;
    }
    if (p->loop && d > 0.0) {
        *clip_s = fmod(media_s, d);
        return 0;
    }
    *clip_s = d;
    return 1;
}

static void load_frame(pb_player *p, long f, double (*q)[4], double (*t)[3])
{
    pb_clip_local(p->clip, pb_clip_frame(p->clip, (size_t)f), q, t);
}

void pb_player_sample(pb_player *p, double t, double (*lq)[4], double (*lt)[3])
{
    const pb_clip *c = p->clip;
    double x = t / c->frame_time;
    long last = (long)c->frame_count - 1;
    if (!(x > 0.0))
        x = 0.0;
    if (x > (double)last)
        x = (double)last;
    long f = (long)floor(x);
    double u = x - (double)f;
    long g = f < last ? f + 1 : f;
    /* keep decoded frames: playback at or above the clip rate reuses them */
    if (p->a_frame != f) {
        if (p->b_frame == f) {
            double (*tq)[4] = p->aq, (*tt)[3] = p->at;
            p->aq = p->bq;
            p->at = p->bt;
            p->bq = tq;
            p->bt = tt;
            p->a_frame = f;
            p->b_frame = -1;
        } else {
            load_frame(p, f, p->aq, p->at);
            p->a_frame = f;
        }
    }
    if (p->b_frame != g) {
        load_frame(p, g, p->bq, p->bt);
        p->b_frame = g;
    }
    for (int j = 0; j < c->joint_count; j++) {
        if (u == 0.0) {
            pb_quat_copy(lq[j], p->aq[j]);
            memcpy(lt[j], p->at[j], sizeof lt[j]);
        } else {
            pb_quat_slerp(p->aq[j], p->bq[j], u, lq[j]);
            for (int k = 0; k < 3; k++)
                lt[j][k] = p->at[j][k] + u * (p->bt[j][k] - p->at[j][k]);
        }
    }
}
