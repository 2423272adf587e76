/* SPDX-License-Identifier: Apache-2.0
 * Clip lifetime, lookup and forward kinematics. */
#include <stdlib.h>
#include <string.h>

#include "mocap.h"
#include "pb_math.h"

pb_clip *pb_clip_alloc(int joints)
{
    pb_clip *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    c->joints = calloc(joints > 0 ? (size_t)joints : 1, sizeof *c->joints);
    if (!c->joints) {
        free(c);
        return NULL;
    }
    c->frame_time = 1.0 / 120.0;
    c->length_unit = 1.0;
    return c;
}

void pb_clip_free(pb_clip *clip)
{
    if (!clip)
        return;
    free(clip->joints);
    free(clip->frames);
    free(clip);
}

int pb_clip_find_joint(const pb_clip *clip, const char *name)
{
    for (int j = 0; j < clip->joint_count; j++)
        if (strcmp(clip->joints[j].name, name) == 0)
            return j;
    return -1;
}

void pb_clip_local(const pb_clip *clip, const double *values, double (*q)[4], double (*t)[3])
{
    for (int j = 0; j < clip->joint_count; j++) {
        const pb_clip_joint *J = &clip->joints[j];
        double r[4], a[4];
        pb_quat_identity(r);
        t[j][0] = J->offset[0];
        t[j][1] = J->offset[1];
        t[j][2] = J->offset[2];
        for (int c = 0; c < J->chan_count; c++) {
            double v = values ? values[J->chan_first + c] : 0.0;
            int k = J->chan[c];
            if (k <= PB_CH_ZPOS) {
                t[j][k] += v;
            } else if (k <= PB_CH_ZROT) {
                pb_quat_axis_deg(k - PB_CH_XROT, v, a);
                if (J->extrinsic)
                    pb_quat_mul(a, r, r);
                else
                    pb_quat_mul(r, a, r);
            }
        }
        /* C R C^-1: the rotation expressed in the joint's axis frame */
        double ci[4];
        pb_quat_conj(J->axis_q, ci);
        pb_quat_mul(J->axis_q, r, r);
        pb_quat_mul(r, ci, q[j]);
    }
}

void pb_clip_world(const pb_clip *clip, const double (*lq)[4], const double (*lt)[3],
                   double (*wq)[4], double (*wp)[3])
{
    for (int j = 0; j < clip->joint_count; j++) {
        int p = clip->joints[j].parent;
        if (p < 0) {
            pb_quat_copy(wq[j], lq[j]);
            wp[j][0] = lt[j][0];
            wp[j][1] = lt[j][1];
            wp[j][2] = lt[j][2];
        } else {
            double v[3];
            pb_quat_rotate(wq[p], lt[j], v);
            wp[j][0] = wp[p][0] + v[0];
            wp[j][1] = wp[p][1] + v[1];
            wp[j][2] = wp[p][2] + v[2];
            pb_quat_mul(wq[p], lq[j], wq[j]);
        }
    }
}

void pb_clip_fk(const pb_clip *clip, const double *values, double *scratch,
                double (*wq)[4], double (*wp)[3])
{
    double (*lq)[4] = (double (*)[4])scratch;
    double (*lt)[3] = (double (*)[3])(scratch + 4 * (size_t)clip->joint_count);
    pb_clip_local(clip, values, lq, lt);
    pb_clip_world(clip, (const double (*)[4])lq, (const double (*)[3])lt, wq, wp);
}
