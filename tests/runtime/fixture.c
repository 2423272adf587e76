/* SPDX-License-Identifier: Apache-2.0 */
#include "fixture.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

fx_options fx_defaults(void)
{
    fx_options o = {0};
    o.cubes = 4;
    o.joints = 2;
    o.with_cor = 1;
    o.child_rest_deg = 30.0f;
    o.limit_joint = -1;
    o.inner_points = 16;
    o.seed = 1;
    return o;
}

float fx_joint_x(const fx_options *o, int j)
{
    return (float)(j * o->cubes / o->joints);
}

static int vid(int ix, int iy, int iz)
{
    return ix * 4 + iy * 2 + iz;
}

/* The 6 Kuhn tets of a cube: path 000 -> e_a -> e_a + e_b -> 111. */
static const int k_perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

static void kuhn_tet(int cube, int t, uint32_t out[4])
{
    int c[3] = {0, 0, 0};
    out[0] = (uint32_t)vid(cube, 0, 0);
    for (int s = 0; s < 3; s++) {
        c[k_perm[t][s]] = 1;
        out[s + 1] = (uint32_t)vid(cube + c[0], c[1], c[2]);
    }
}

static uint32_t rnd(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static float rnd01(unsigned *s)
{
    return (float)(rnd(s) & 0xffff) / 65536.0f;
}

static void add_quad(uint32_t *tris, size_t *n, const float *pos, uint32_t a, uint32_t b,
                     uint32_t c, uint32_t d, const float out_dir[3])
{
    const float *pa = pos + 3 * a, *pb = pos + 3 * b, *pc = pos + 3 * c;
    float u[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
    float v[3] = {pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
    float nn[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    int flip = nn[0] * out_dir[0] + nn[1] * out_dir[1] + nn[2] * out_dir[2] < 0.0f;
    uint32_t q[4] = {a, b, c, d};
    if (flip) {
        q[1] = d;
        q[3] = b;
    }
    uint32_t *t = tris + 3 * *n;
    t[0] = q[0]; t[1] = q[1]; t[2] = q[2];
    t[3] = q[0]; t[4] = q[2]; t[5] = q[3];
    *n += 2;
}

pose_rig *fx_bar(const fx_options *o)
{
    const int n = o->cubes, J = o->joints;
    const size_t nv = (size_t)(n + 1) * 4, nt = (size_t)n * 6;
    float *pos = calloc(3 * nv, sizeof(float));
    float *cor = calloc(3 * nv, sizeof(float));
    uint16_t *wj = calloc(2 * nv, sizeof(uint16_t));
    float *w = calloc(2 * nv, sizeof(float));
    uint32_t *tets = calloc(4 * nt, sizeof(uint32_t));
    uint16_t *labels = calloc(nt, sizeof(uint16_t));
    for (int ix = 0; ix <= n; ix++)
        for (int iy = 0; iy < 2; iy++)
            for (int iz = 0; iz < 2; iz++) {
                size_t v = (size_t)vid(ix, iy, iz);
                pos[3 * v] = (float)ix;
                pos[3 * v + 1] = (float)iy;
                pos[3 * v + 2] = (float)iz;
                /* segment of joint j: [x_j, x_j+1); blend half/half at x_j */
                int seg = 0;
                for (int j = 0; j < J; j++)
                    if (fx_joint_x(o, j) <= (float)ix)
                        seg = j;
                wj[2 * v] = (uint16_t)seg;
                w[2 * v] = 1.0f;
                memcpy(cor + 3 * v, pos + 3 * v, 3 * sizeof(float));
                if (seg > 0 && fx_joint_x(o, seg) == (float)ix) {
                    wj[2 * v + 1] = (uint16_t)(seg - 1);
                    w[2 * v] = w[2 * v + 1] = 0.5f;
                    cor[3 * v] = (float)ix;
                    cor[3 * v + 1] = cor[3 * v + 2] = 0.5f;
                }
            }
    for (int c = 0; c < n; c++)
        for (int t = 0; t < 6; t++)
            kuhn_tet(c, t, tets + 4 * (size_t)(c * 6 + t));

    pose_joint_desc *joints = calloc((size_t)J, sizeof *joints);
    char names[8][16];
    for (int j = 0; j < J; j++) {
        snprintf(names[j % 8], sizeof names[0], "j%d", j);
        joints[j].name = strdup(names[j % 8]);
        joints[j].parent = j - 1;
        float half = j > 0 ? 0.5f * o->child_rest_deg * 0.017453292f : 0.0f;
        joints[j].rest_model.rotation[0] = sinf(half);
        joints[j].rest_model.rotation[3] = cosf(half);
        joints[j].rest_model.translation[0] = fx_joint_x(o, j);
        joints[j].rest_model.translation[1] = 0.5f;
        joints[j].rest_model.translation[2] = 0.5f;
        if (j == o->limit_joint) {
            joints[j].limit_flags = o->limit_flags;
            joints[j].limit_order = o->limit_order;
            memcpy(joints[j].limit_min_deg, o->limit_min, sizeof o->limit_min);
            memcpy(joints[j].limit_max_deg, o->limit_max, sizeof o->limit_max);
        }
    }

    /* tissue 0: one vertex per tet vertex, embedded with bary 1 at it */
    uint32_t *skin_tet = calloc(nv, sizeof(uint32_t));
    float *skin_bary = calloc(4 * nv, sizeof(float));
    for (size_t v = 0; v < nv; v++) {
        size_t tet = (size_t)-1;
        int corner = 0;
        for (size_t t = 0; t < nt && tet == (size_t)-1; t++)
            for (int k = 0; k < 4; k++)
                if (tets[4 * t + (size_t)k] == v) {
                    tet = t;
                    corner = k;
                    break;
                }
        skin_tet[v] = (uint32_t)tet;
        skin_bary[4 * v + (size_t)corner] = 1.0f;
    }
    size_t ntri = 0;
    uint32_t *tris = calloc(3 * (size_t)(8 * n + 4), sizeof(uint32_t));
    for (int c = 0; c < n; c++) {
        const float dy0[3] = {0, -1, 0}, dy1[3] = {0, 1, 0}, dz0[3] = {0, 0, -1}, dz1[3] = {0, 0, 1};
        add_quad(tris, &ntri, pos, vid(c, 0, 0), vid(c + 1, 0, 0), vid(c + 1, 0, 1), vid(c, 0, 1), dy0);
        add_quad(tris, &ntri, pos, vid(c, 1, 0), vid(c + 1, 1, 0), vid(c + 1, 1, 1), vid(c, 1, 1), dy1);
        add_quad(tris, &ntri, pos, vid(c, 0, 0), vid(c + 1, 0, 0), vid(c + 1, 1, 0), vid(c, 1, 0), dz0);
        add_quad(tris, &ntri, pos, vid(c, 0, 1), vid(c + 1, 0, 1), vid(c + 1, 1, 1), vid(c, 1, 1), dz1);
    }
    const float dx0[3] = {-1, 0, 0}, dx1[3] = {1, 0, 0};
    add_quad(tris, &ntri, pos, vid(0, 0, 0), vid(0, 1, 0), vid(0, 1, 1), vid(0, 0, 1), dx0);
    add_quad(tris, &ntri, pos, vid(n, 0, 0), vid(n, 1, 0), vid(n, 1, 1), vid(n, 0, 1), dx1);

    /* tissue 1: random points, located in their Kuhn tet */
    size_t np = (size_t)(o->inner_points > 0 ? o->inner_points : 1);
    float *ip = calloc(3 * np, sizeof(float));
    uint32_t *itet = calloc(np, sizeof(uint32_t));
    float *ibary = calloc(4 * np, sizeof(float));
    unsigned s = o->seed;
    for (size_t i = 0; i < np; i++) {
        int cube = (int)(rnd(&s) % (unsigned)n);
        float l[3] = {rnd01(&s), rnd01(&s), rnd01(&s)};
        int t = 0;
        for (int k = 0; k < 6; k++)
            if (l[k_perm[k][0]] >= l[k_perm[k][1]] && l[k_perm[k][1]] >= l[k_perm[k][2]])
                t = k;
        float la = l[k_perm[t][0]], lb = l[k_perm[t][1]], lc = l[k_perm[t][2]];
        itet[i] = (uint32_t)(cube * 6 + t);
        ibary[4 * i + 0] = 1.0f - la;
        ibary[4 * i + 1] = la - lb;
        ibary[4 * i + 2] = lb - lc;
        ibary[4 * i + 3] = lc;
        ip[3 * i] = (float)cube + l[0];
        ip[3 * i + 1] = l[1];
        ip[3 * i + 2] = l[2];
    }

    pose_tissue_desc tissues[2] = {
        {.name = "skin", .kind = POSE_TISSUE_SKIN, .joint = -1, .vertex_count = nv,
         .positions = pos, .triangle_count = ntri, .triangles = tris, .tet = skin_tet,
         .bary = skin_bary},
        {.name = "inner", .kind = POSE_TISSUE_OTHER, .joint = -1, .vertex_count = np,
         .positions = ip, .tet = itet, .bary = ibary},
    };
    pose_rig_desc d = {
        .joint_count = (size_t)J, .joints = joints, .tet_vertex_count = nv, .tet_positions = pos,
        .tet_count = nt, .tets = tets, .tet_labels = labels, .influences = 2,
        .weight_joints = wj, .weights = w, .cor = o->with_cor ? cor : NULL,
        .tissue_count = 2, .tissues = tissues, .metadata = "runtime test bar",
    };
    pose_rig *rig = NULL;
    pose_status st = pose_rig_create(&d, NULL, &rig);
    if (st != POSE_OK)
        print_error("fx_bar: %s\n", pose_last_error());
    assert_int_equal(st, POSE_OK);
    for (int j = 0; j < J; j++)
        free((void *)joints[j].name);
    free(joints);
    free(pos); free(cor); free(wj); free(w); free(tets); free(labels);
    free(skin_tet); free(skin_bary); free(tris); free(ip); free(itet); free(ibary);
    return rig;
}
