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

void ex_motion_close(ex_motion *m)
{
    (void)m;
}

long ex_motion_frame_count(const ex_motion *m)
{
    (void)m;
    return 0;
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

int ex_motion_set_time(ex_motion *m, pose_state *st, double t, char *err, size_t err_size)
{
    (void)t;
    return ex_motion_set_frame(m, st, 0, err, err_size);
}

const char *ex_motion_status(const ex_motion *m)
{
    (void)m;
    return "no bridge";
}
