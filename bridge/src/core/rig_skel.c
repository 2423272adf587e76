/* SPDX-License-Identifier: Apache-2.0 */
#include "rig_skel.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pb_math.h"

static pb_rig_skel *skel_alloc(int n)
{
    pb_rig_skel *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->joints = calloc(n > 0 ? (size_t)n : 1, sizeof *s->joints);
    if (!s->joints) {
        free(s);
        return NULL;
    }
    s->joint_count = n;
    return s;
}

/* local = parent_rest^-1 * rest */
static void compute_locals(pb_rig_skel *s)
{
    for (int j = 0; j < s->joint_count; j++) {
        pb_rig_joint *J = &s->joints[j];
        if (J->parent < 0) {
            pb_quat_copy(J->local_q, J->rest_q);
            memcpy(J->local_p, J->rest_p, sizeof J->local_p);
            continue;
        }
        const pb_rig_joint *P = &s->joints[J->parent];
        double pi[4], d[3] = {J->rest_p[0] - P->rest_p[0], J->rest_p[1] - P->rest_p[1], J->rest_p[2] - P->rest_p[2]};
        pb_quat_conj(P->rest_q, pi);
        pb_quat_mul(pi, J->rest_q, J->local_q);
        pb_quat_normalize(J->local_q);
        pb_quat_rotate(pi, d, J->local_p);
    }
}

static pose_status check_joint(const pb_rig_skel *s, int j, const char *name, int parent, pb_error *err)
{
    if (!name || !name[0] || strlen(name) >= PB_NAME_MAX)
        return pb_fail(err, POSE_ERR_INVALID_DATA, "rig joint %d: name empty or longer than %d bytes", j,
                       PB_NAME_MAX - 1);
    if (parent >= j || parent < -1)
        return pb_fail(err, POSE_ERR_INVALID_DATA, "rig joint %d (%s): parent %d does not precede it", j, name, parent);
    (void)s;
    return POSE_OK;
}

pose_status pb_rig_skel_from_desc(const pose_joint_desc *joints, size_t count, pb_rig_skel **out, pb_error *err)
{
    if (!out || (!joints && count))
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_rig_skel_from_desc: NULL argument");
    *out = NULL;
    if (count > PB_MAX_JOINTS)
        return pb_fail(err, POSE_ERR_INVALID_DATA, "rig has %zu joints, more than %d", count, PB_MAX_JOINTS);
    pb_rig_skel *s = skel_alloc((int)count);
    if (!s)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    for (size_t j = 0; j < count; j++) {
        pose_status st = check_joint(s, (int)j, joints[j].name, joints[j].parent, err);
        if (st) {
            pb_rig_skel_free(s);
            return st;
        }
        pb_rig_joint *J = &s->joints[j];
        snprintf(J->name, sizeof J->name, "%s", joints[j].name);
        J->parent = joints[j].parent;
        for (int k = 0; k < 4; k++)
            J->rest_q[k] = joints[j].rest_model.rotation[k];
        pb_quat_normalize(J->rest_q);
        for (int k = 0; k < 3; k++)
            J->rest_p[k] = joints[j].rest_model.translation[k];
        J->limit_flags = joints[j].limit_flags;
        for (int k = 0; k < 3; k++) {
            J->limit_min_deg[k] = joints[j].limit_min_deg[k];
            J->limit_max_deg[k] = joints[j].limit_max_deg[k];
        }
    }
    compute_locals(s);
    *out = s;
    return POSE_OK;
}

pose_status pb_rig_skel_from_clip(const pb_clip *clip, double scale, pb_rig_skel **out, pb_error *err)
{
    if (!out || !clip)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_rig_skel_from_clip: NULL argument");
    *out = NULL;
    int n = clip->joint_count;
    pb_rig_skel *s = skel_alloc(n);
    double *scratch = malloc((size_t)(n > 0 ? n : 1) * 14 * sizeof *scratch);
    if (!s || !scratch) {
        pb_rig_skel_free(s);
        free(scratch);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
    double (*wq)[4] = (double (*)[4])(scratch + 7 * (size_t)n);
    double (*wp)[3] = (double (*)[3])(scratch + 11 * (size_t)n);
    pb_clip_fk(clip, NULL, scratch, wq, wp);
    for (int j = 0; j < n; j++) {
        pb_rig_joint *J = &s->joints[j];
        memcpy(J->name, clip->joints[j].name, sizeof J->name);
        J->parent = clip->joints[j].parent;
        pb_quat_identity(J->rest_q);
        for (int k = 0; k < 3; k++)
            J->rest_p[k] = wp[j][k] * scale;
    }
    free(scratch);
    compute_locals(s);
    *out = s;
    return POSE_OK;
}

void pb_rig_skel_free(pb_rig_skel *s)
{
    if (!s)
        return;
    free(s->joints);
    free(s);
}

int pb_rig_skel_hinge_axis(const pb_rig_skel *s, int j, int along)
{
    const pb_rig_joint *J = &s->joints[j];
    if (along < 0 || along > 2 || (J->limit_flags & 7u) != 7u)
        return -1;
    int a = (along + 1) % 3, b = (along + 2) % 3;
    double ra = (double)J->limit_max_deg[a] - J->limit_min_deg[a], rb = (double)J->limit_max_deg[b] - J->limit_min_deg[b];
    if (ra >= 60.0 && rb <= 30.0)
        return a;
    if (rb >= 60.0 && ra <= 30.0)
        return b;
    return -1;
}

int pb_rig_skel_find(const pb_rig_skel *s, const char *name)
{
    for (int j = 0; j < s->joint_count; j++)
        if (strcmp(s->joints[j].name, name) == 0)
            return j;
    return -1;
}

void pb_rig_skel_fk(const pb_rig_skel *s, const float (*q)[4], const float root_t[3], const float root_q[4],
                    double (*wq)[4], double (*wp)[3])
{
    double rq[4] = {0, 0, 0, 1}, rt[3] = {0, 0, 0};
    if (root_q) {
        for (int k = 0; k < 4; k++)
            rq[k] = root_q[k];
        pb_quat_normalize(rq);
    }
    if (root_t)
        for (int k = 0; k < 3; k++)
            rt[k] = root_t[k];
    for (int j = 0; j < s->joint_count; j++) {
        const pb_rig_joint *J = &s->joints[j];
        double r[4] = {0, 0, 0, 1};
        if (q) {
            for (int k = 0; k < 4; k++)
                r[k] = q[j][k];
            pb_quat_normalize(r);
        }
        double base_q[4], base_p[3];
        if (J->parent < 0) {
            pb_quat_mul(rq, J->rest_q, base_q);
            pb_quat_rotate(rq, J->rest_p, base_p);
            for (int k = 0; k < 3; k++)
                base_p[k] += rt[k];
        } else {
            double v[3];
            pb_quat_mul(wq[J->parent], J->local_q, base_q);
            pb_quat_rotate(wq[J->parent], J->local_p, v);
            for (int k = 0; k < 3; k++)
                base_p[k] = wp[J->parent][k] + v[k];
        }
        pb_quat_mul(base_q, r, wq[j]);
        memcpy(wp[j], base_p, sizeof base_p);
    }
}
