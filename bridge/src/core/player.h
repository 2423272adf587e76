/* SPDX-License-Identifier: Apache-2.0
 * Clip playback: media time -> interpolated local transforms (slerp of the
 * two neighbouring frames' joint rotations, lerp of translations), with
 * looping. Frame f is shown at media time f * frame_time. */
#ifndef POSE_BRIDGE_PLAYER_H
#define POSE_BRIDGE_PLAYER_H

#include "mocap.h"

typedef struct pb_player {
    const pb_clip *clip;
    int loop;
    double (*aq)[4], (*at)[3], (*bq)[4], (*bt)[3]; /* the two frames' local transforms */
    long a_frame, b_frame;                          /* which frames aq/bq hold (-1: none) */
} pb_player;

pose_status pb_player_init(pb_player *p, const pb_clip *clip, int loop, pb_error *err);
void pb_player_free(pb_player *p);
/** Media time of the last frame ((frame_count - 1) * frame_time). */
double pb_player_duration(const pb_player *p);
/**
 * Map media time onto the clip: wraps when looping, clamps otherwise.
 * Returns 1 when a non-looping clip is past its end.
 */
int pb_player_wrap(const pb_player *p, double media_s, double *clip_s);
/** Local transforms at clip time t (0 <= t <= duration). Allocates nothing. */
void pb_player_sample(pb_player *p, double t, double (*lq)[4], double (*lt)[3]);

#endif /* POSE_BRIDGE_PLAYER_H */
