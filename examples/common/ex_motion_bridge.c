/* SPDX-License-Identifier: Apache-2.0
 *
 * ex_motion over the bridge library: the clip is parsed by the bridge
 * (pb_clip_load), retargeted onto the rig by the bridge (pb_retarget_*) and
 * applied by the bridge (pb_pose_apply_to_state). This file only chooses
 * frames and blends between two of them for in-between times.
 */
#include "ex_motion.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bridge_apply.h"
#include "mapping.h"
#include "mocap.h"
#include "rig_skel.h"

struct ex_motion {
    pb_clip *clip;
    pb_mapping *map;
    pb_rig_skel *skel;
    pb_retarget *rt;
    pb_pose pose;
    double (*lq)[4], (*lt)[3];   /* clip local transforms of one frame */
    double (*lq2)[4], (*lt2)[3]; /* of the next frame, for blending */
    double last_t;
    int clamped;
    char status[256];
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

/* An AMC file's skeleton: the ASF beside it named by the subject ("01_01.amc" -> "01.asf"). */
static int find_asf(const char *amc, char *out, size_t out_size)
{
    struct stat sb;
    snprintf(out, out_size, "%s", amc);
    char *slash = strrchr(out, '/');
    char *base = slash ? slash + 1 : out;
    char *us = strchr(base, '_');
    if (!us)
        return -1;
    snprintf(us, out_size - (size_t)(us - out), ".asf");
    return stat(out, &sb) == 0 ? 0 : -1;
}

int ex_motion_open(const char *source, const char *map, const pose_rig *rig, ex_motion **out, char *err,
                   size_t err_size)
{
    pb_error pe = {{0}};
    char asf[4096];
    const char *skeleton = NULL;
    *out = NULL;
    if (!ends_with(source, ".bvh") && !ends_with(source, ".BVH") && !ends_with(source, ".amc")) {
        snprintf(err, err_size,
                 "%s: not a motion clip (.bvh, or .amc with its .asf beside it); recordings of HID and CAN "
                 "devices are replayed by pose-bridge",
                 source);
        return -1;
    }
    if (ends_with(source, ".amc")) {
        if (find_asf(source, asf, sizeof asf) < 0) {
            snprintf(err, err_size, "%s: no skeleton file (expected %s)", source, asf);
            return -1;
        }
        skeleton = asf;
    }
    ex_motion *m = calloc(1, sizeof *m);
    if (!m) {
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    if (pb_clip_load(source, skeleton, &m->clip, &pe) < 0 ||
        (map ? pb_mapping_load(map, &m->map, &pe) : pb_mapping_identity(&m->map, &pe)) < 0 ||
        pb_rig_skel_from_rig(rig, &m->skel, &pe) < 0 || pb_retarget_create(m->map, m->clip, m->skel, &m->rt, &pe) < 0) {
        snprintf(err, err_size, "%s", pe.message[0] ? pe.message : "cannot open the source");
        ex_motion_close(m);
        return -1;
    }
    if (m->clip->frame_count == 0) {
        snprintf(err, err_size, "%s: the clip has no frames", source);
        ex_motion_close(m);
        return -1;
    }
    size_t nj = (size_t)m->clip->joint_count;
    m->lq = calloc(nj, sizeof *m->lq);
    m->lt = calloc(nj, sizeof *m->lt);
    m->lq2 = calloc(nj, sizeof *m->lq2);
    m->lt2 = calloc(nj, sizeof *m->lt2);
    if (!m->lq || !m->lt || !m->lq2 || !m->lt2 || pb_pose_init(&m->pose, m->skel->joint_count) != 0) {
        snprintf(err, err_size, "out of memory");
        ex_motion_close(m);
        return -1;
    }
    m->last_t = -1.0;
    snprintf(m->status, sizeof m->status, "%s %s, %zu frames at %.0f Hz, %d joints mapped", m->clip->format,
             strrchr(source, '/') ? strrchr(source, '/') + 1 : source, m->clip->frame_count,
             1.0 / m->clip->frame_time, pb_retarget_mapped_count(m->rt));
    *out = m;
    return 0;
}

void ex_motion_close(ex_motion *m)
{
    if (!m)
        return;
    pb_pose_free(&m->pose);
    pb_retarget_free(m->rt);
    pb_rig_skel_free(m->skel);
    pb_mapping_free(m->map);
    pb_clip_free(m->clip);
    free(m->lq);
    free(m->lt);
    free(m->lq2);
    free(m->lt2);
    free(m);
}

long ex_motion_frame_count(const ex_motion *m)
{
    return (long)m->clip->frame_count;
}

double ex_motion_frame_time(const ex_motion *m)
{
    return m->clip->frame_time;
}

/* Retarget the clip transforms in m->lq/lt and set them on the state. */
static int apply(ex_motion *m, pose_state *st, double dt, char *err, size_t err_size)
{
    pb_retarget_apply(m->rt, (const double(*)[4])m->lq, (const double(*)[3])m->lt, dt, &m->pose);
    if (pb_pose_apply_to_state(&m->pose, st, &m->clamped) < 0) {
        snprintf(err, err_size, "cannot apply the pose: %s", pose_last_error());
        return -1;
    }
    return 0;
}

int ex_motion_set_frame(ex_motion *m, pose_state *st, long frame, char *err, size_t err_size)
{
    if (frame < 0 || (size_t)frame >= m->clip->frame_count) {
        snprintf(err, err_size, "%s: frame %ld is out of range (0..%zu)", m->clip->path, frame,
                 m->clip->frame_count - 1);
        return -1;
    }
    pb_clip_local(m->clip, pb_clip_frame(m->clip, (size_t)frame), m->lq, m->lt);
    m->last_t = -1.0; /* a jump: filters start afresh */
    return apply(m, st, 0.0, err, err_size);
}

int ex_motion_set_time(ex_motion *m, pose_state *st, double t, char *err, size_t err_size)
{
    double ft = m->clip->frame_time, pos = t / ft;
    size_t n = m->clip->frame_count;
    if (!(pos >= 0.0))
        pos = 0.0;
    size_t f = (size_t)pos;
    if (f >= n - 1) {
        f = n - 1;
        pos = (double)f;
    }
    double a = pos - (double)f;
    pb_clip_local(m->clip, pb_clip_frame(m->clip, f), m->lq, m->lt);
    if (a > 0.0) {
        /* Between two recorded frames: normalized lerp of rotations (sign-aligned), lerp of offsets. */
        pb_clip_local(m->clip, pb_clip_frame(m->clip, f + 1), m->lq2, m->lt2);
        for (int j = 0; j < m->clip->joint_count; j++) {
            double *q = m->lq[j], *q2 = m->lq2[j], d = q[0] * q2[0] + q[1] * q2[1] + q[2] * q2[2] + q[3] * q2[3];
            double s = d < 0.0 ? -a : a, len = 0.0;
            for (int k = 0; k < 4; k++) {
                q[k] = (1.0 - a) * q[k] + s * q2[k];
                len += q[k] * q[k];
            }
            len = sqrt(len);
            for (int k = 0; k < 4 && len > 0.0; k++)
                q[k] /= len;
            for (int k = 0; k < 3; k++)
                m->lt[j][k] = (1.0 - a) * m->lt[j][k] + a * m->lt2[j][k];
        }
    }
    double dt = m->last_t >= 0.0 && t >= m->last_t ? t - m->last_t : 0.0;
    m->last_t = t;
    return apply(m, st, dt, err, err_size);
}

const char *ex_motion_status(const ex_motion *m)
{
    return m->status;
}
