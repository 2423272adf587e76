/* SPDX-License-Identifier: Apache-2.0 */
#include "recorder.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "pb_math.h"

struct pb_recorder {
    FILE *f;
    char path[256];
    const pb_rig_skel *rig;
    long frames;
    long count_pos;  /* file offset of the frame count field */
    double (*wq)[4]; /* rig world rotations, scratch */
    double (*dq)[4]; /* world rotation relative to rest, scratch */
    char *line;      /* one motion line */
    size_t line_cap;
};

/* Width of the in-place frame count: enough for any session. */
#define PB_COUNT_WIDTH 12

static void write_joint(pb_recorder *r, int j, int depth)
{
    const pb_rig_skel *s = r->rig;
    const pb_rig_joint *J = &s->joints[j];
    FILE *f = r->f;
    double off[3];
    if (J->parent < 0)
        memcpy(off, J->rest_p, sizeof off);
    else
        for (int k = 0; k < 3; k++)
            off[k] = J->rest_p[k] - s->joints[J->parent].rest_p[k];
    for (int i = 0; i < depth; i++)
        fputc('\t', f);
    fprintf(f, "%s %s\n", J->parent < 0 ? "ROOT" : "JOINT", J->name);
    for (int i = 0; i < depth; i++)
        fputc('\t', f);
    fprintf(f, "{\n");
    for (int i = 0; i <= depth; i++)
        fputc('\t', f);
    fprintf(f, "OFFSET %.6f %.6f %.6f\n", off[0], off[1], off[2]);
    for (int i = 0; i <= depth; i++)
        fputc('\t', f);
    if (J->parent < 0)
        fprintf(f, "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n");
    else
        fprintf(f, "CHANNELS 3 Zrotation Xrotation Yrotation\n");
    int children = 0;
    for (int k = j + 1; k < s->joint_count; k++)
        if (s->joints[k].parent == j) {
            write_joint(r, k, depth + 1);
            children++;
        }
    if (!children) { /* BVH wants an end site on leaves; a zero-length one */
        for (int i = 0; i <= depth; i++)
            fputc('\t', f);
        fprintf(f, "End Site\n");
        for (int i = 0; i <= depth; i++)
            fputc('\t', f);
        fprintf(f, "{\n");
        for (int i = 0; i <= depth + 1; i++)
            fputc('\t', f);
        fprintf(f, "OFFSET 0 0 0\n");
        for (int i = 0; i <= depth; i++)
            fputc('\t', f);
        fprintf(f, "}\n");
    }
    for (int i = 0; i < depth; i++)
        fputc('\t', f);
    fprintf(f, "}\n");
}

pose_status pb_recorder_open(const char *path, const pb_rig_skel *rig, double frame_time, pb_recorder **out,
                             pb_error *err)
{
    if (!path || !rig || !out || !(frame_time > 0))
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_recorder_open: bad argument");
    *out = NULL;
    int roots = 0;
    for (int j = 0; j < rig->joint_count; j++)
        roots += rig->joints[j].parent < 0;
    if (roots != 1)
        return pb_fail(err, POSE_ERR_UNSUPPORTED, "%s: BVH holds one root; the rig has %d", path, roots);
    pb_recorder *r = calloc(1, sizeof *r);
    if (!r)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    size_t n = (size_t)rig->joint_count;
    r->rig = rig;
    r->wq = malloc(n * sizeof *r->wq);
    r->dq = malloc(n * sizeof *r->dq);
    r->line_cap = 64 + n * 3 * 24 + 3 * 24;
    r->line = malloc(r->line_cap);
    snprintf(r->path, sizeof r->path, "%s", path);
    r->f = fopen(path, "wb");
    if (!r->wq || !r->dq || !r->line || !r->f) {
        int e = errno;
        pb_recorder_close(r, NULL);
        return pb_fail(err, POSE_ERR_IO, "%s: cannot create: %s", path, strerror(e));
    }
    fprintf(r->f, "HIERARCHY\n");
    write_joint(r, 0, 0);
    fprintf(r->f, "MOTION\nFrames: ");
    r->count_pos = ftell(r->f);
    fprintf(r->f, "%-*d\nFrame Time: %.7f\n", PB_COUNT_WIDTH, 0, frame_time);
    if (fflush(r->f) != 0 || r->count_pos < 0) {
        pb_recorder_close(r, NULL);
        return pb_fail(err, POSE_ERR_IO, "%s: write error", path);
    }
    *out = r;
    return POSE_OK;
}

pose_status pb_recorder_write(pb_recorder *r, const pb_pose *pose, pb_error *err)
{
    const pb_rig_skel *s = r->rig;
    if (pose->joint_count != s->joint_count)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "%s: pose has %d joints, the rig %d", r->path,
                       pose->joint_count, s->joint_count);
    /* model-space world rotations W_j, then D_j = W_j Rest_j^-1 (turn from
     * rest in model axes); the BVH channel of j is D_parent^-1 D_j. */
    size_t len = 0;
    for (int j = 0; j < s->joint_count; j++) {
        const pb_rig_joint *J = &s->joints[j];
        double R[4] = {pose->q[j][0], pose->q[j][1], pose->q[j][2], pose->q[j][3]}, ri[4], local[4], deg[3];
        pb_quat_normalize(R);
        if (J->parent < 0) {
            double rq[4] = {pose->root_q[0], pose->root_q[1], pose->root_q[2], pose->root_q[3]};
            if (!pose->has_root)
                pb_quat_identity(rq);
            pb_quat_normalize(rq);
            pb_quat_mul(rq, J->rest_q, r->wq[j]);
        } else {
            pb_quat_mul(r->wq[J->parent], J->local_q, r->wq[j]);
        }
        pb_quat_mul(r->wq[j], R, r->wq[j]);
        pb_quat_conj(J->rest_q, ri);
        pb_quat_mul(r->wq[j], ri, r->dq[j]);
        if (J->parent < 0) {
            pb_quat_copy(local, r->dq[j]);
            double p[3] = {J->rest_p[0], J->rest_p[1], J->rest_p[2]};
            if (pose->has_root) {
                double rq[4] = {pose->root_q[0], pose->root_q[1], pose->root_q[2], pose->root_q[3]};
                pb_quat_normalize(rq);
                pb_quat_rotate(rq, p, p);
                for (int k = 0; k < 3; k++)
                    p[k] += pose->root_t[k];
            }
            /* BVH adds the root's position channels to its OFFSET (the rest position) */
            len += (size_t)snprintf(r->line + len, r->line_cap - len, "%.6f %.6f %.6f", p[0] - J->rest_p[0],
                                    p[1] - J->rest_p[1], p[2] - J->rest_p[2]);
        } else {
            double pi[4];
            pb_quat_conj(r->dq[J->parent], pi);
            pb_quat_mul(pi, r->dq[j], local);
        }
        pb_quat_to_euler(local, POSE_EULER_ZXY, deg);
        len += (size_t)snprintf(r->line + len, r->line_cap - len, " %.6f %.6f %.6f", deg[2], deg[0], deg[1]);
    }
    r->frames++;
    if (fprintf(r->f, "%s\n", r->line) < 0 || fflush(r->f) != 0)
        return pb_fail(err, POSE_ERR_IO, "%s: write error at frame %ld", r->path, r->frames);
    long end = ftell(r->f);
    if (end < 0 || fseek(r->f, r->count_pos, SEEK_SET) != 0 ||
        fprintf(r->f, "%-*ld", PB_COUNT_WIDTH, r->frames) < 0 || fseek(r->f, end, SEEK_SET) != 0 ||
        fflush(r->f) != 0)
        return pb_fail(err, POSE_ERR_IO, "%s: cannot update the frame count", r->path);
    return POSE_OK;
}

long pb_recorder_frames(const pb_recorder *r) { return r ? r->frames : 0; }

pose_status pb_recorder_close(pb_recorder *r, pb_error *err)
{
    if (!r)
        return POSE_OK;
    pose_status s = POSE_OK;
    if (r->f && fclose(r->f) != 0)
        s = pb_fail(err, POSE_ERR_IO, "%s: error closing", r->path);
    free(r->wq);
    free(r->dq);
    free(r->line);
    free(r);
    return s;
}
