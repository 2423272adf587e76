/* SPDX-License-Identifier: Apache-2.0 */
#include "bind_bar.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

enum { NX = 32, NS = 4 }; /* cubes along x, across */
#define EDGE 0.25f

static uint32_t vid(int ix, int iy, int iz)
{
    return (uint32_t)((ix * (NS + 1) + iy) * (NS + 1) + iz);
}

/* The two joints around x and the second one's weight. */
static void hat(float x, int *j, float *t)
{
    int a = (int)floorf(x);
    a = a < 0 ? 0 : a > BAR_JOINTS - 2 ? BAR_JOINTS - 2 : a;
    *j = a;
    float s = x - (float)a;
    *t = s < 0.0f ? 0.0f : s > 1.0f ? 1.0f : s;
}

pose_rig *bar_rig(void)
{
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    const size_t nv = (size_t)(NX + 1) * (NS + 1) * (NS + 1), nt = (size_t)NX * NS * NS * 6;
    float *pos = calloc(3 * nv, sizeof(float));
    uint16_t *wj = calloc(2 * nv, sizeof(uint16_t));
    float *w = calloc(2 * nv, sizeof(float));
    uint32_t *tets = calloc(4 * nt, sizeof(uint32_t));
    uint16_t *labels = calloc(nt, sizeof(uint16_t));
    assert_non_null(pos);
    assert_non_null(tets);
    for (int ix = 0; ix <= NX; ix++)
        for (int iy = 0; iy <= NS; iy++)
            for (int iz = 0; iz <= NS; iz++) {
                size_t v = vid(ix, iy, iz);
                pos[3 * v] = EDGE * (float)ix;
                pos[3 * v + 1] = EDGE * (float)iy;
                pos[3 * v + 2] = EDGE * (float)iz;
                int j;
                float t;
                hat(pos[3 * v], &j, &t);
                wj[2 * v] = (uint16_t)j;
                wj[2 * v + 1] = (uint16_t)(j + 1);
                w[2 * v] = 1.0f - t;
                w[2 * v + 1] = t;
            }
    size_t at = 0;
    for (int ix = 0; ix < NX; ix++)
        for (int iy = 0; iy < NS; iy++)
            for (int iz = 0; iz < NS; iz++)
                for (int k = 0; k < 6; k++) {
                    int c[3] = {0, 0, 0};
                    tets[at++] = vid(ix, iy, iz);
                    for (int s = 0; s < 3; s++) {
                        c[perm[k][s]] = 1;
                        tets[at++] = vid(ix + c[0], iy + c[1], iz + c[2]);
                    }
                }
    static char names[BAR_JOINTS][8];
    pose_joint_desc joints[BAR_JOINTS] = {{0}};
    for (int j = 0; j < BAR_JOINTS; j++) {
        snprintf(names[j], sizeof names[j], "j%d", j);
        joints[j].name = names[j];
        joints[j].parent = j - 1;
        joints[j].rest_model.rotation[3] = 1.0f;
        joints[j].rest_model.translation[0] = (float)j;
        joints[j].rest_model.translation[1] = 0.5f;
        joints[j].rest_model.translation[2] = 0.5f;
    }
    pose_rig_desc d = {0};
    d.joint_count = BAR_JOINTS;
    d.joints = joints;
    d.tet_vertex_count = nv;
    d.tet_positions = pos;
    d.tet_count = nt;
    d.tets = tets;
    d.tet_labels = labels;
    d.influences = 2;
    d.weight_joints = wj;
    d.weights = w;
    pose_rig *rig = NULL;
    pose_status s = pose_rig_create(&d, NULL, &rig);
    if (s != POSE_OK)
        fail_msg("bar_rig: %s", pose_last_error());
    free(pos);
    free(wj);
    free(w);
    free(tets);
    free(labels);
    return rig;
}

static void qmul(float r[4], const float a[4], const float b[4])
{
    r[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    r[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    r[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    r[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
}

static void qrot(float out[3], const float q[4], const float v[3])
{
    float p[4] = {v[0], v[1], v[2], 0.0f}, c[4] = {-q[0], -q[1], -q[2], q[3]}, t[4], r[4];
    qmul(t, q, p);
    qmul(r, t, c);
    out[0] = r[0];
    out[1] = r[1];
    out[2] = r[2];
}

void bar_skin(const pose_state *st, int j, float q[4], float t[3])
{
    pose_transform wld;
    assert_int_equal(pose_joint_world(st, j, &wld), POSE_OK);
    const float rest[3] = {(float)j, 0.5f, 0.5f};
    float r[3];
    for (int k = 0; k < 4; k++)
        q[k] = wld.rotation[k];
    qrot(r, q, rest);
    for (int k = 0; k < 3; k++)
        t[k] = wld.translation[k] - r[k];
}

void bar_dqs(const pose_state *st, const float p[3], float out[3])
{
    int j;
    float s;
    hat(p[0], &j, &s);
    float qr[4] = {0}, qd[4] = {0}, first[4] = {0};
    for (int k = 0; k < 2; k++) {
        float q[4], t[3], w = k ? s : 1.0f - s;
        bar_skin(st, j + k, q, t);
        if (k == 0)
            for (int i = 0; i < 4; i++)
                first[i] = q[i];
        else if (q[0] * first[0] + q[1] * first[1] + q[2] * first[2] + q[3] * first[3] < 0.0f)
            w = -w; /* antipodality */
        float tq[4] = {t[0], t[1], t[2], 0.0f}, d[4];
        qmul(d, tq, q);
        for (int i = 0; i < 4; i++) {
            qr[i] += w * q[i];
            qd[i] += w * 0.5f * d[i];
        }
    }
    float n = sqrtf(qr[0] * qr[0] + qr[1] * qr[1] + qr[2] * qr[2] + qr[3] * qr[3]);
    for (int i = 0; i < 4; i++) {
        qr[i] /= n;
        qd[i] /= n;
    }
    float c[4] = {-qr[0], -qr[1], -qr[2], qr[3]}, tt[4];
    qmul(tt, qd, c);
    float r[3];
    qrot(r, qr, p);
    for (int k = 0; k < 3; k++)
        out[k] = r[k] + 2.0f * tt[k];
}
