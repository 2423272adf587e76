/* SPDX-License-Identifier: Apache-2.0
 *
 * ex_motion over the bridge's public API (pose/bridge.h), as any host would
 * use it: everything that reads, decodes, maps or times inputs is the
 * bridge's. A recorded source is opened twice: once POSE_BRIDGE_MANUAL for
 * picking frames and times (images, exports), and once on the bridge's own
 * thread when live playback starts (the viewer). A live device is opened
 * on its thread at once.
 */
#include "ex_motion.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pose/bridge.h"

struct ex_motion {
    char name[128];
    char source[1024], map[1024];
    const pose_rig *rig;
    pose_bridge *manual; /* recorded sources: frames and times on demand */
    pose_bridge *live;   /* the bridge thread, once started (live devices: from the open) */
    pose_bridge_status st;
    int paused;
    char status[512];
};

int ex_motion_available(void)
{
    return 1;
}

static int open_bridge(ex_motion *m, pose_bridge_play play, pose_bridge **out, char *err, size_t err_size)
{
    pose_bridge_options o = {.size = sizeof o, .map_path = m->map[0] ? m->map : NULL, .play = play, .loop = 1};
    if (pose_bridge_open(m->source, m->rig, &o, out) < 0) {
        snprintf(err, err_size, "%s", pose_last_error());
        return -1;
    }
    return 0;
}

static int is_live(const ex_motion *m)
{
    return strcmp(m->st.kind, "hid") == 0 || strcmp(m->st.kind, "can") == 0;
}

int ex_motion_open(const char *source, const char *map, const pose_rig *rig, ex_motion **out, char *err,
                   size_t err_size)
{
    *out = NULL;
    ex_motion *m = calloc(1, sizeof *m);
    if (!m) {
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    snprintf(m->name, sizeof m->name, "%s", strrchr(source, '/') ? strrchr(source, '/') + 1 : source);
    snprintf(m->source, sizeof m->source, "%s", source);
    snprintf(m->map, sizeof m->map, "%s", map ? map : "");
    m->rig = rig;
    m->st.size = sizeof m->st;
    /* A live device cannot play MANUAL: it goes straight to its thread. */
    if (open_bridge(m, POSE_BRIDGE_MANUAL, &m->manual, err, err_size) < 0 &&
        (!strstr(pose_last_error(), "live source") || open_bridge(m, POSE_BRIDGE_REALTIME, &m->live, err, err_size) < 0)) {
        ex_motion_close(m);
        return -1;
    }
    pose_bridge_status_get(m->manual ? m->manual : m->live, &m->st);
    if (m->st.frame_count >= 0)
        snprintf(m->status, sizeof m->status, "%s: %ld frames at %.0f Hz", m->name, m->st.frame_count,
                 1.0 / m->st.frame_time_s);
    else
        snprintf(m->status, sizeof m->status, "%s: %s", m->name, m->st.kind);
    *out = m;
    return 0;
}

void ex_motion_close(ex_motion *m)
{
    if (!m)
        return;
    pose_bridge_close(m->live);
    pose_bridge_close(m->manual);
    free(m);
}

long ex_motion_frame_count(const ex_motion *m)
{
    return m->st.frame_count;
}

double ex_motion_frame_time(const ex_motion *m)
{
    return m->st.frame_time_s;
}

static int pose_at(ex_motion *m, pose_state *st, double t_s, char *err, size_t err_size)
{
    if (pose_bridge_pose_at(m->manual, t_s, st, NULL) < 0) {
        snprintf(err, err_size, "%s", pose_last_error());
        return -1;
    }
    return 0;
}

int ex_motion_set_frame(ex_motion *m, pose_state *st, long frame, char *err, size_t err_size)
{
    if (m->st.frame_count < 0) {
        snprintf(err, err_size, "%s: a device source or recording has no frames to pick; pick recorded "
                                "times (--times), or play it live (pose-view, pose-bridge)", m->name);
        return -1;
    }
    if (frame < 0 || frame >= m->st.frame_count) {
        snprintf(err, err_size, "%s: frame %ld is out of range (0..%ld)", m->source, frame, m->st.frame_count - 1);
        return -1;
    }
    return pose_at(m, st, (double)frame * m->st.frame_time_s, err, err_size);
}

int ex_motion_set_time(ex_motion *m, pose_state *st, double t_s, char *err, size_t err_size)
{
    if (!m->manual) {
        snprintf(err, err_size, "%s: a live device has no recorded time to pick; play it live (pose-view)", m->name);
        return -1;
    }
    if (m->st.frame_count >= 0 && t_s > m->st.duration_s + 1e-9) {
        snprintf(err, err_size, "%s: %.3f s is past the end of the clip (%.3f s)", m->name, t_s, m->st.duration_s);
        return -1;
    }
    return pose_at(m, st, t_s, err, err_size);
}

int ex_motion_start(ex_motion *m, char *err, size_t err_size)
{
    if (m->live)
        return 0;
    return open_bridge(m, POSE_BRIDGE_REALTIME, &m->live, err, err_size);
}

int ex_motion_poll(ex_motion *m, pose_state *st, char *err, size_t err_size)
{
    if (!m->live)
        return 0;
    pose_bridge_frame f;
    if (pose_bridge_apply(m->live, st, &f) < 0) {
        snprintf(err, err_size, "cannot apply the pose: %s", pose_last_error());
        return -1;
    }
    return f.fresh;
}

void ex_motion_pause(ex_motion *m, int paused)
{
    if (m->live && !is_live(m))
        pose_bridge_pause(m->live, paused);
    m->paused = paused;
}

int ex_motion_paused(const ex_motion *m)
{
    return m->paused;
}

void ex_motion_seek(ex_motion *m, double media_s)
{
    if (m->live && m->st.frame_count >= 0)
        pose_bridge_seek(m->live, media_s < 0.0 ? 0.0 : media_s);
}

void ex_motion_step(ex_motion *m, int ticks)
{
    if (!m->live || m->st.frame_count < 0)
        return;
    ex_motion_pause(m, 1);
    /* seeking a paused clip shows the pose there */
    pose_bridge_status s = {.size = sizeof s};
    pose_bridge_status_get(m->live, &s);
    double t = (double)(s.frame < 0 ? 0 : s.frame + ticks) * m->st.frame_time_s;
    pose_bridge_seek(m->live, t < 0.0 ? 0.0 : t);
}

double ex_motion_time(const ex_motion *m)
{
    pose_bridge_status s = {.size = sizeof s};
    if (!m->live || pose_bridge_status_get(m->live, &s) < 0)
        return 0.0;
    return s.media_s;
}

const char *ex_motion_status(ex_motion *m)
{
    if (!m->live)
        return m->status;
    pose_bridge_status s = {.size = sizeof s};
    if (pose_bridge_status_get(m->live, &s) < 0)
        return m->status;
    if (s.frame_count >= 0)
        snprintf(m->status, sizeof m->status, "%s  frame %ld/%ld  lag max %.2f ms  %s%s", m->name, s.frame,
                 s.frame_count, s.lag_max_ms, pose_bridge_state_name(s.state), m->paused ? " (paused)" : "");
    else
        snprintf(m->status, sizeof m->status, "%s  %llu poses, %llu drops  %s%s%s", m->name,
                 (unsigned long long)s.poses, (unsigned long long)s.drops, pose_bridge_state_name(s.state),
                 s.fault[0] && s.state != POSE_BRIDGE_OK ? ": " : "",
                 s.fault[0] && s.state != POSE_BRIDGE_OK ? s.fault : "");
    return m->status;
}
