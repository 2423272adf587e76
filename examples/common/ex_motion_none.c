/* SPDX-License-Identifier: Apache-2.0
 * ex_motion for builds without the bridge (-DPOSE_BUILD_BRIDGE=OFF): every
 * source is refused with a message that says how to get one. */
#include "ex_motion.h"

#include <stdio.h>

int ex_motion_available(void)
{
    return 0;
}

int ex_motion_open(const char *source, const char *map, const pose_rig *rig, ex_motion **out, char *err,
                   size_t err_size)
{
    (void)map;
    (void)rig;
    *out = NULL;
    snprintf(err, err_size, "%s: this build has no input bridge (configure with -DPOSE_BUILD_BRIDGE=ON)",
             source);
    return -1;
}

/* Nothing below is reachable without a successful open; they keep the interface whole. */
void ex_motion_close(ex_motion *m)
{
    (void)m;
}

long ex_motion_frame_count(const ex_motion *m)
{
    (void)m;
    return -1;
}

double ex_motion_frame_time(const ex_motion *m)
{
    (void)m;
    return 0.0;
}

int ex_motion_set_frame(ex_motion *m, pose_state *st, long frame, char *err, size_t err_size)
{
    (void)m;
    (void)st;
    (void)frame;
    snprintf(err, err_size, "no input bridge in this build");
    return -1;
}

int ex_motion_set_time(ex_motion *m, pose_state *st, double t_s, char *err, size_t err_size)
{
    (void)t_s;
    return ex_motion_set_frame(m, st, 0, err, err_size);
}

int ex_motion_start(ex_motion *m, char *err, size_t err_size)
{
    return ex_motion_set_frame(m, NULL, 0, err, err_size);
}

int ex_motion_poll(ex_motion *m, pose_state *st, char *err, size_t err_size)
{
    return ex_motion_set_frame(m, st, 0, err, err_size);
}

void ex_motion_pause(ex_motion *m, int paused)
{
    (void)m;
    (void)paused;
}

int ex_motion_paused(const ex_motion *m)
{
    (void)m;
    return 1;
}

void ex_motion_seek(ex_motion *m, double media_s)
{
    (void)m;
    (void)media_s;
}

void ex_motion_step(ex_motion *m, int ticks)
{
    (void)m;
    (void)ticks;
}

double ex_motion_time(const ex_motion *m)
{
    (void)m;
    return 0.0;
}

const char *ex_motion_status(ex_motion *m)
{
    (void)m;
    return "no bridge";
}
