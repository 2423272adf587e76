/* SPDX-License-Identifier: Apache-2.0
 *
 * ex_motion over the bridge library. Everything that reads, decodes, maps or
 * times inputs is the bridge's: clips are parsed by pb_clip_load and
 * retargeted by pb_retarget_*, HID and CAN sources are opened by pb_hid_open,
 * pb_candump_replay_open and pb_can_live_open, live playback runs on the
 * bridge's own thread (pb_runner) and poses reach the state through
 * pb_pose_apply_to_state. This file only picks the right calls.
 */
#include "ex_motion.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bridge_apply.h"
#include "can_bus.h"
#include "can_source.h"
#include "hid_open.h"
#include "mapping.h"
#include "mocap.h"
#include "rig_skel.h"
#include "runner.h"

struct ex_motion {
    char name[128];
    pb_clip *clip;      /* a mocap clip, or NULL for a device source */
    pb_source *src;     /* a device source until the runner takes it */
    pb_mapping *map;
    pb_rig_skel *skel;
    pb_retarget *rt;    /* frame-by-frame retargeting (clips) */
    pb_pose pose;
    double (*lq)[4], (*lt)[3];
    pb_runner *runner;
    /* --times: a second, as-fast-as-possible replay of a recording, fed up
     * to each requested time; the first update past it waits in next_*. */
    char spec[1024], map_path[1024];
    pb_source *scrub;
    pb_chanmap *scrub_cm;
    int64_t scrub_t0, scrub_last;
    int scrub_started, have_next;
    pb_update next;
    uint32_t *next_ch;
    double *next_val;
    int paused;
    char status[512];
};

int ex_motion_available(void)
{
    return 1;
}

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && !strcmp(s + n - m, suffix);
}

static int open_clip(ex_motion *m, const char *source, pb_error *pe, char *err, size_t err_size)
{
    /* An .amc finds its CMU skeleton (01_01.amc -> 01.asf) beside it: the bridge looks. */
    if (pb_clip_load(source, NULL, &m->clip, pe) < 0 || pb_retarget_create(m->map, m->clip, m->skel, &m->rt, pe) < 0)
        return -1;
    if (m->clip->frame_count == 0) {
        snprintf(err, err_size, "%s: the clip has no frames", source);
        return -1;
    }
    m->lq = calloc((size_t)m->clip->joint_count, sizeof *m->lq);
    m->lt = calloc((size_t)m->clip->joint_count, sizeof *m->lt);
    if (!m->lq || !m->lt) {
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    return 0;
}

/* CAN: a candump -l log, or "can:IFACE" / an interface name; the bus comes from the mapping's "can".
 * Logs loop for live play; scrub = once through, as fast as possible (--times). */
static int open_can(const char *source, const char *map, int scrub, pb_source **out, pb_error *pe)
{
    pb_can_bus *bus = NULL;
    if (pb_can_bus_load(map, &bus, pe) < 0)
        return -1;
    if (ends_with(source, ".log")) {
        pb_candump_replay_options opt = {.loop = !scrub, .as_fast_as_possible = scrub};
        return pb_candump_replay_open(source, bus, &opt, out, pe) < 0 ? -1 : 0;
    }
    const char *iface = !strncmp(source, "can:", 4) ? source + 4 : source;
    return pb_can_live_open(iface, bus, NULL, out, pe) < 0 ? -1 : 0;
}

/* What kind of source a command-line spec names: 'c' clip, 'h' HID, 'n' CAN, 0 unknown. */
static char source_kind(const char *s)
{
    if (ends_with(s, ".bvh") || ends_with(s, ".BVH") || ends_with(s, ".amc"))
        return 'c';
    if (ends_with(s, ".hid") || !strncmp(s, "/dev/hidraw", 11) || !strncmp(s, "hid:", 4))
        return 'h';
    if (ends_with(s, ".log") || !strncmp(s, "can:", 4) || (!strchr(s, '/') && !strchr(s, '.') && *s))
        return 'n'; /* a candump -l log, or an interface such as can0 / vcan0 */
    return 0;
}

int ex_motion_open(const char *source, const char *map, const pose_rig *rig, ex_motion **out, char *err,
                   size_t err_size)
{
    pb_error pe = {{0}};
    *out = NULL;
    char kind = source_kind(source);
    int clip = kind == 'c';
    if (!kind) {
        snprintf(err, err_size,
                 "%s: unknown kind of source (expected .bvh, .amc, .hid, /dev/hidrawN, hid:VID:PID, "
                 "a candump .log, or a CAN interface such as can0)",
                 source);
        return -1;
    }
    if (!clip && !map) {
        snprintf(err, err_size, "%s: a HID or CAN source needs --map (a mapping file with \"channels\")", source);
        return -1;
    }
    ex_motion *m = calloc(1, sizeof *m);
    if (!m) {
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    snprintf(m->name, sizeof m->name, "%s", strrchr(source, '/') ? strrchr(source, '/') + 1 : source);
    snprintf(m->spec, sizeof m->spec, "%s", source);
    snprintf(m->map_path, sizeof m->map_path, "%s", map ? map : "");
    int rc = (map ? pb_mapping_load(map, &m->map, &pe) : pb_mapping_identity(&m->map, &pe)) < 0 ||
                     pb_rig_skel_from_rig(rig, &m->skel, &pe) < 0
                 ? -1
                 : 0;
    if (rc == 0) {
        if (clip)
            rc = open_clip(m, source, &pe, err, err_size);
        else if (kind == 'n')
            rc = open_can(source, map, 0, &m->src, &pe);
        else
            rc = pb_hid_open(source, &(pb_hid_replay_options){.loop = 1}, &m->src, &pe) < 0 ? -1 : 0;
    }
    if (rc == 0 && pb_pose_init(&m->pose, m->skel->joint_count) != 0) {
        snprintf(err, err_size, "out of memory");
        rc = -1;
    }
    if (rc < 0) {
        if (pe.message[0])
            snprintf(err, err_size, "%s", pe.message);
        ex_motion_close(m);
        return -1;
    }
    if (m->clip)
        snprintf(m->status, sizeof m->status, "%s: %zu frames at %.0f Hz, %d joints mapped", m->name,
                 m->clip->frame_count, 1.0 / m->clip->frame_time, pb_retarget_mapped_count(m->rt));
    else
        snprintf(m->status, sizeof m->status, "%s: %s, %zu channels", m->name, m->src->ops->kind,
                 m->src->channel_count);
    *out = m;
    return 0;
}

static void scrub_close(ex_motion *m)
{
    pb_chanmap_free(m->scrub_cm);
    pb_source_destroy(m->scrub);
    m->scrub_cm = NULL;
    m->scrub = NULL;
}

/* (Re)start the scrub replay at the recording's beginning: a fresh source and
 * channel mapping, so filters start from the same state as live play. */
static int scrub_open(ex_motion *m, char *err, size_t err_size)
{
    pb_error pe = {{0}};
    int rc;
    scrub_close(m);
    if (source_kind(m->spec) == 'n')
        rc = open_can(m->spec, m->map_path, 1, &m->scrub, &pe);
    else
        rc = pb_hid_open(m->spec, &(pb_hid_replay_options){.as_fast_as_possible = 1}, &m->scrub, &pe);
    if (rc == 0)
        rc = pb_chanmap_create(m->map, m->scrub->channels, m->scrub->channel_count, m->skel, &m->scrub_cm, &pe);
    if (rc == 0 && !m->next_ch) {
        m->next_ch = calloc(m->scrub->channel_count + 1, sizeof *m->next_ch);
        m->next_val = calloc(m->scrub->channel_count + 1, sizeof *m->next_val);
        if (!m->next_ch || !m->next_val) {
            snprintf(err, err_size, "out of memory");
            return -1;
        }
    }
    if (rc < 0) {
        snprintf(err, err_size, "%s", pe.message[0] ? pe.message : "cannot replay the recording");
        return -1;
    }
    m->scrub_started = m->have_next = 0;
    m->scrub_last = 0;
    return 0;
}

/* Keep an update past the requested time for the next request (the source
 * owns its arrays only until the next read). */
static void hold_next(ex_motion *m, const pb_update *u)
{
    size_t n = u->count <= m->scrub->channel_count ? u->count : m->scrub->channel_count;
    memcpy(m->next_ch, u->channels, n * sizeof *m->next_ch);
    memcpy(m->next_val, u->values, n * sizeof *m->next_val);
    m->next = (pb_update){.t_ns = u->t_ns, .count = n, .channels = m->next_ch, .values = m->next_val};
    m->have_next = 1;
}

void ex_motion_close(ex_motion *m)
{
    if (!m)
        return;
    pb_runner_stop(m->runner, NULL); /* destroys a source it was given */
    scrub_close(m);
    if (!m->runner)
        pb_source_destroy(m->src);
    pb_pose_free(&m->pose);
    pb_retarget_free(m->rt);
    pb_rig_skel_free(m->skel);
    pb_mapping_free(m->map);
    pb_clip_free(m->clip);
    free(m->lq);
    free(m->lt);
    free(m->next_ch);
    free(m->next_val);
    free(m);
}

long ex_motion_frame_count(const ex_motion *m)
{
    return m->clip ? (long)m->clip->frame_count : -1;
}

double ex_motion_frame_time(const ex_motion *m)
{
    return m->clip ? m->clip->frame_time : 0.0;
}

int ex_motion_set_frame(ex_motion *m, pose_state *st, long frame, char *err, size_t err_size)
{
    if (!m->clip) {
        snprintf(err, err_size, "%s: a device source or recording has no frames to pick; pick recorded "
                                "times (--times), or play it live (pose-view, pose-bridge)", m->name);
        return -1;
    }
    if (frame < 0 || (size_t)frame >= m->clip->frame_count) {
        snprintf(err, err_size, "%s: frame %ld is out of range (0..%zu)", m->clip->path, frame,
                 m->clip->frame_count - 1);
        return -1;
    }
    pb_clip_local(m->clip, pb_clip_frame(m->clip, (size_t)frame), m->lq, m->lt);
    pb_retarget_apply(m->rt, (const double(*)[4])m->lq, (const double(*)[3])m->lt, 0.0, &m->pose);
    if (pb_pose_apply_to_state(&m->pose, st, NULL) < 0) {
        snprintf(err, err_size, "cannot apply frame %ld: %s", frame, pose_last_error());
        return -1;
    }
    return 0;
}

int ex_motion_set_time(ex_motion *m, pose_state *st, double t_s, char *err, size_t err_size)
{
    if (m->clip) {
        double f = floor(t_s / m->clip->frame_time + 1e-9);
        if (f >= (double)m->clip->frame_count) {
            snprintf(err, err_size, "%s: %.3f s is past the end of the clip (%.3f s)", m->name, t_s,
                     (double)(m->clip->frame_count - 1) * m->clip->frame_time);
            return -1;
        }
        return ex_motion_set_frame(m, st, (long)f, err, err_size);
    }
    if (!ends_with(m->spec, ".hid") && !ends_with(m->spec, ".log")) {
        snprintf(err, err_size, "%s: a live device has no recorded time to pick; play it live (pose-view)", m->name);
        return -1;
    }
    const int64_t want = (int64_t)(t_s * 1e9 + 0.5);
    if ((!m->scrub || (m->scrub_started && want < m->scrub_last)) && scrub_open(m, err, err_size) < 0)
        return -1;
    /* Feed every update up to the requested time; faults the replay reports
     * (a silent node, bus-off) are the recording's and play on, as live. */
    for (int misses = 0;;) {
        pb_update u;
        if (m->have_next) {
            u = m->next;
        } else {
            int got = pb_source_read(m->scrub, &u, 1000);
            if (got <= 0) {
                if (m->scrub->state == PB_SOURCE_ENDED || ++misses > 10000) {
                    snprintf(err, err_size, "%s: %.3f s is past the end of the recording (%.3f s)", m->name, t_s,
                             (double)m->scrub_last * 1e-9);
                    return -1;
                }
                continue;
            }
            misses = 0;
        }
        if (!m->scrub_started) {
            m->scrub_t0 = u.t_ns;
            m->scrub_started = 1;
        }
        if (u.t_ns - m->scrub_t0 > want) {
            if (!m->have_next)
                hold_next(m, &u);
            break;
        }
        m->have_next = 0;
        pb_chanmap_update(m->scrub_cm, &u);
        m->scrub_last = u.t_ns - m->scrub_t0;
    }
    pb_chanmap_pose(m->scrub_cm, &m->pose);
    m->pose.media_s = t_s;
    if (pb_pose_apply_to_state(&m->pose, st, NULL) < 0) {
        snprintf(err, err_size, "cannot apply the pose at %.3f s: %s", t_s, pose_last_error());
        return -1;
    }
    return 0;
}

int ex_motion_start(ex_motion *m, char *err, size_t err_size)
{
    pb_error pe = {{0}};
    pb_runner_options opt = {.speed = 1.0, .loop = 1};
    pose_status st = m->clip ? pb_runner_start_clip(m->clip, m->skel, m->map, &opt, &m->runner, &pe)
                             : pb_runner_start_source(m->src, m->skel, m->map, &opt, &m->runner, &pe);
    m->src = NULL; /* pb_runner_start_source always takes the source, even when it fails */
    if (st < 0) {
        snprintf(err, err_size, "%s", pe.message[0] ? pe.message : "cannot start the bridge thread");
        return -1;
    }
    return 0;
}

int ex_motion_poll(ex_motion *m, pose_state *st, char *err, size_t err_size)
{
    int fresh = 0;
    const pb_pose *p = m->runner ? pb_runner_latest(m->runner, &fresh) : NULL;
    if (!p || !fresh || p->seq == 0)
        return 0;
    if (pb_pose_apply_to_state(p, st, NULL) < 0) {
        snprintf(err, err_size, "cannot apply the pose: %s", pose_last_error());
        return -1;
    }
    return 1;
}

void ex_motion_pause(ex_motion *m, int paused)
{
    if (m->runner)
        pb_runner_pause(m->runner, paused);
    m->paused = paused;
}

int ex_motion_paused(const ex_motion *m)
{
    return m->paused;
}

void ex_motion_seek(ex_motion *m, double media_s)
{
    if (m->runner && m->clip)
        pb_runner_seek(m->runner, media_s < 0.0 ? 0.0 : media_s);
}

void ex_motion_step(ex_motion *m, int ticks)
{
    if (m->runner && m->clip) {
        ex_motion_pause(m, 1);
        pb_runner_step(m->runner, ticks);
    }
}

double ex_motion_time(const ex_motion *m)
{
    pb_runner_stats s;
    if (!m->runner)
        return 0.0;
    pb_runner_stats_get(m->runner, &s);
    return s.media_s;
}

const char *ex_motion_status(ex_motion *m)
{
    if (!m->runner)
        return m->status;
    pb_runner_stats s;
    pb_runner_stats_get(m->runner, &s);
    if (m->clip)
        snprintf(m->status, sizeof m->status, "%s  frame %ld/%zu  %.0f poses/s  lag %.2f ms  %s%s", m->name,
                 s.frame, m->clip->frame_count, s.fps, s.lag_ms, pb_source_state_name(s.state),
                 m->paused ? " (paused)" : "");
    else
        snprintf(m->status, sizeof m->status, "%s  %llu poses, %.0f/s  %s", m->name, (unsigned long long)s.ticks,
                 s.fps, pb_source_state_name(s.state));
    return m->status;
}
