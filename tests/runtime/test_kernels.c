/* SPDX-License-Identifier: Apache-2.0 */
/* The runtime kernels on their own: DQS/CoR antipodality, transfer of affine
 * deformations (positions and normals), Euler round trips. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rt_euler.h"
#include "rt_skin.h"
#include "rt_transfer.h"
#include "test_math.h"

/* ---- blocked layouts (as rig_prepare builds them), from per-vertex arrays */
typedef struct packed_skin {
    pose__skin_mesh mesh;
    float *rest, *cor;
    uint8_t *active;
    uint16_t *j16, *w;
} packed_skin;

static void *zalloc(size_t n)
{
    void *p = aligned_alloc(64, (n + 64 + 63) & ~(size_t)63);
    assert_non_null(p);
    memset(p, 0, (n + 64 + 63) & ~(size_t)63);
    return p;
}

static packed_skin pack_skin(size_t n, unsigned K, const float *rest, const float *cor,
                             const uint16_t *joints, const uint16_t *weights)
{
    packed_skin p;
    size_t nb = (n + 7) / 8;
    p.rest = zalloc(nb * 24 * sizeof(float));
    p.cor = zalloc(nb * 24 * sizeof(float));
    p.active = zalloc(nb);
    p.j16 = zalloc(nb * K * 8 * 2);
    p.w = zalloc(nb * K * 8 * 2);
    for (size_t b = 0; b < nb; b++) {
        p.active[b] = 1;
        for (size_t l = 0; l < 8; l++) {
            size_t i = b * 8 + l, src = i < n ? i : 0;
            for (int c = 0; c < 3; c++) {
                p.rest[(b * 3 + (size_t)c) * 8 + l] = rest[3 * src + (size_t)c];
                p.cor[(b * 3 + (size_t)c) * 8 + l] = cor[3 * src + (size_t)c];
            }
            for (unsigned k = 0; k < K; k++) {
                size_t at = (b * K + k) * 8 + l;
                p.j16[at] = joints[src * K + k];
                p.w[at] = weights[src * K + k];
                if (weights[src * K + k] && k + 1 > p.active[b])
                    p.active[b] = (uint8_t)(k + 1);
            }
        }
    }
    p.mesh = (pose__skin_mesh){.vertex_count = n, .block_count = nb, .influences = K,
                               .rest = p.rest, .cor = p.cor, .active = p.active,
                               .joints = p.j16, .weights = p.w};
    return p;
}

static void free_skin(packed_skin *p)
{
    free(p->rest); free(p->cor); free(p->active); free(p->j16); free(p->w);
}

typedef struct packed_transfer {
    pose__transfer_mesh mesh;
    uint32_t *tv;
    float *bary;
    int16_t *key;
} packed_transfer;

static packed_transfer pack_transfer(size_t n, const uint32_t *tv4, const float *b3,
                                     const int16_t *key3)
{
    packed_transfer p;
    size_t nb = (n + 7) / 8;
    p.tv = zalloc(nb * 32 * sizeof(uint32_t));
    p.bary = zalloc(nb * 24 * sizeof(float));
    p.key = zalloc(nb * 24 * sizeof(int16_t));
    for (size_t i = 0; i < n; i++) {
        size_t b = i / 8, l = i % 8;
        for (size_t c = 0; c < 4; c++)
            p.tv[(b * 4 + c) * 8 + l] = tv4[4 * i + c];
        for (size_t c = 0; c < 3; c++) {
            p.bary[(b * 3 + c) * 8 + l] = b3[3 * i + c];
            p.key[(b * 3 + c) * 8 + l] = key3[3 * i + c];
        }
    }
    p.mesh = (pose__transfer_mesh){.vertex_count = n, .block_count = nb, .tet_vertices = p.tv,
                                   .bary = p.bary, .normal_key = p.key};
    return p;
}

static void free_transfer(packed_transfer *p)
{
    free(p->tv); free(p->bary); free(p->key);
}

/* Two joints holding the same rotation as q and -q: a 50/50 blend must be
 * that rotation, not a collapse (the antipodality DQS and CoR must handle). */
static void test_blend_antipodal_quaternions(void **unused)
{
    (void)unused;
    double q[4];
    dq_axis(q, 0.2, 0.1, 1.0, 170.0);
    pose__xform x[2];
    for (int k = 0; k < 4; k++) {
        x[0].q[k] = (float)q[k];
        x[1].q[k] = (float)-q[k];
    }
    const float t[3] = {0.3f, -0.2f, 1.0f};
    memcpy(x[0].t, t, sizeof t);
    memcpy(x[1].t, t, sizeof t);
    pose__skin_joint pal[2];
    pose__skin_palette(2, x, pal);
    const float rest[6] = {1.0f, 2.0f, 3.0f, -0.5f, 0.25f, 4.0f};
    const float cor[6] = {0.5f, 0.5f, 0.5f, 0.0f, 1.0f, 0.0f};
    const uint16_t joints[4] = {0, 1, 1, 0};
    const uint16_t weights[4] = {16384, 16384, 16384, 16384};
    packed_skin ps = pack_skin(2, 2, rest, cor, joints, weights);
    for (int method = POSE__SKIN_DQS; method <= POSE__SKIN_COR; method++) {
        float out[6];
        pose__skin(method, &ps.mesh, pal, 0, 1, out);
        for (int v = 0; v < 2; v++) {
            double p[3] = {rest[3 * v], rest[3 * v + 1], rest[3 * v + 2]}, e[3];
            dq_rot(e, q, p);
            for (int k = 0; k < 3; k++)
                assert_near(out[3 * v + k], e[k] + t[k], 1e-5);
        }
    }
    free_skin(&ps);
}

/* LBS, DQS and CoR agree for a vertex bound to one joint (rigid). */
static void test_single_joint_rigid_all_methods(void **unused)
{
    (void)unused;
    pose__xform x[3];
    double q[4];
    for (int j = 0; j < 3; j++) {
        dq_axis(q, 1.0, j, 2.0 - j, 30.0 + 50.0 * j);
        for (int k = 0; k < 4; k++)
            x[j].q[k] = (float)q[k];
        x[j].t[0] = (float)j;
        x[j].t[1] = 1.0f;
        x[j].t[2] = -2.0f * (float)j;
    }
    pose__skin_joint pal[3];
    pose__skin_palette(3, x, pal);
    const float rest[3] = {0.7f, -1.1f, 2.5f}, cor[3] = {9.0f, 9.0f, 9.0f};
    const uint16_t j16[3] = {2, 0, 1};
    const uint16_t w[3] = {32768, 0, 0};
    packed_skin p1 = pack_skin(1, 3, rest, cor, j16, w);
    double xq[4] = {x[2].q[0], x[2].q[1], x[2].q[2], x[2].q[3]}, p[3] = {rest[0], rest[1], rest[2]}, e[3];
    dq_rot(e, xq, p);
    for (int method = 0; method < 3; method++) {
        float a[3];
        pose__skin(method, &p1.mesh, pal, 0, 1, a);
        for (int k = 0; k < 3; k++)
            assert_near(a[k], e[k] + x[2].t[k], 1e-5);
    }
    free_skin(&p1);
}

/* Under an affine map of the tet vertices, barycentric transfer reproduces
 * the map at every point of the tet (inside or slightly outside), and
 * normals transform by the inverse transpose. */
static void test_transfer_affine_exact(void **unused)
{
    (void)unused;
    const float tet[12] = {0.1f, 0.0f, 0.2f, 1.3f, 0.1f, 0.0f, 0.2f, 0.9f, 0.1f, 0.3f, 0.2f, 1.1f};
    const double A[3][3] = {{1.2, 0.3, -0.4}, {0.1, 0.8, 0.5}, {-0.2, 0.4, 1.5}};
    const double off[3] = {2.0, -1.0, 0.5};
    float moved[16] = {0}; /* 16 bytes of slack after the 4 vertices */
    for (int v = 0; v < 4; v++)
        for (int r = 0; r < 3; r++)
            moved[3 * v + r] = (float)(A[r][0] * tet[3 * v] + A[r][1] * tet[3 * v + 1] +
                                       A[r][2] * tet[3 * v + 2] + off[r]);
    /* inverse transpose of A by cofactors: cof(A) = det(A) A^-T */
    double cof[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            cof[r][c] = A[r1][c1] * A[r2][c2] - A[r1][c2] * A[r2][c1];
        }
    enum { N = 64 };
    uint32_t tv[4 * N];
    float bary[3 * N];
    int16_t key[3 * N];
    double rest_p[N][3], n_rest[N][3];
    unsigned s = 7;
    for (int i = 0; i < N; i++) {
        double b[4], sum = 0;
        for (int k = 0; k < 4; k++) {
            s = s * 1664525u + 1013904223u;
            b[k] = (double)(s >> 8) / 16777216.0 * 1.2 - 0.1; /* a little outside too */
            sum += b[k];
        }
        for (int k = 0; k < 4; k++)
            b[k] /= sum;
        for (int k = 0; k < 4; k++)
            tv[4 * i + k] = (uint32_t)k;
        for (int k = 0; k < 3; k++)
            bary[3 * i + k] = (float)b[k + 1];
        for (int r = 0; r < 3; r++) {
            rest_p[i][r] = 0;
            for (int k = 0; k < 4; k++)
                rest_p[i][r] += b[k] * tet[3 * k + r];
        }
        /* a normal and its key sign(det D) D^T n, as rig_prepare builds it */
        double n[3] = {sin(i), cos(i), 0.3 * i - 9.0}, l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double e[3][3], m[3];
        for (int k = 0; k < 3; k++) {
            n_rest[i][k] = n[k] / l;
        }
        for (int k = 0; k < 3; k++) {
            for (int r = 0; r < 3; r++)
                e[k][r] = tet[3 * (k + 1) + r] - tet[r];
            m[k] = e[k][0] * n_rest[i][0] + e[k][1] * n_rest[i][1] + e[k][2] * n_rest[i][2];
        }
        double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                     e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        double big = fmax(fabs(m[0]), fmax(fabs(m[1]), fabs(m[2])));
        for (int k = 0; k < 3; k++)
            key[3 * i + k] = (int16_t)lround((det < 0 ? -m[k] : m[k]) / big * 32767.0);
    }
    packed_transfer pt = pack_transfer(N, tv, bary, key);
    float *pos = zalloc(3 * N * sizeof(float)), *nrm = zalloc(3 * N * sizeof(float));
    uint32_t flagged[N];
    assert_int_equal(pose__transfer(&pt.mesh, moved, 0, pt.mesh.block_count, pos, nrm, flagged), 0);
    for (int i = 0; i < N; i++) {
        double nn[3], l = 0;
        for (int r = 0; r < 3; r++) {
            double want = off[r];
            for (int c = 0; c < 3; c++)
                want += A[r][c] * rest_p[i][c];
            assert_near(pos[3 * i + r], want, 2e-6);
            nn[r] = cof[r][0] * n_rest[i][0] + cof[r][1] * n_rest[i][1] + cof[r][2] * n_rest[i][2];
            l += nn[r] * nn[r];
        }
        for (int r = 0; r < 3; r++)
            assert_near(nrm[3 * i + r], nn[r] / sqrt(l), 2e-4);
    }
    /* positions only (normals skipped) give the same positions */
    float *pos2 = zalloc(3 * N * sizeof(float));
    pose__transfer(&pt.mesh, moved, 0, pt.mesh.block_count, pos2, NULL, NULL);
    assert_memory_equal(pos, pos2, 3 * N * sizeof(float));
    free(pos);
    free(pos2);
    free(nrm);
    free_transfer(&pt);
}

/* The generic and AVX2 variants give bit-identical results (all methods,
 * multi-influence blocks, a partial last block, unaligned outputs). */
static void test_variants_identical(void **unused)
{
    (void)unused;
    enum { NV = 203, NJ = 9, K = 4, NT = 157 };
    float rest[3 * NV], cor[3 * NV], tp[3 * NV + 4];
    uint16_t joints[K * NV], weights[K * NV];
    unsigned s = 99;
    for (size_t i = 0; i < 3 * NV; i++) {
        s = s * 1664525u + 1013904223u;
        rest[i] = (float)(s >> 8) / 16777216.0f * 2.0f - 1.0f;
        cor[i] = rest[i] * 0.5f;
    }
    for (size_t i = 0; i < NV; i++) {
        unsigned left = 32768;
        for (unsigned k = 0; k < K; k++) {
            s = s * 1664525u + 1013904223u;
            joints[K * i + k] = (uint16_t)((s >> 10) % NJ);
            unsigned w = k + 1 == K ? left : (i % 3 == 0 ? (k == 0 ? left : 0) : left / 2);
            weights[K * i + k] = (uint16_t)w;
            left -= w;
        }
    }
    pose__xform x[NJ];
    for (int j = 0; j < NJ; j++) {
        double q[4];
        dq_axis(q, 1.0, j - 4.0, 0.5, 37.0 * j - 150.0);
        for (int k = 0; k < 4; k++)
            x[j].q[k] = (float)q[k];
        x[j].t[0] = 0.1f * j; x[j].t[1] = -0.2f; x[j].t[2] = 0.05f * j;
    }
    pose__skin_joint pal[NJ];
    pose__skin_palette(NJ, x, pal);
    packed_skin ps = pack_skin(NV, K, rest, cor, joints, weights);
    uint32_t tv[4 * NT];
    float bary[3 * NT];
    int16_t key[3 * NT];
    for (size_t i = 0; i < NT; i++) {
        for (int c = 0; c < 4; c++) {
            s = s * 1664525u + 1013904223u;
            tv[4 * i + (size_t)c] = (s >> 8) % NV;
        }
        for (int c = 0; c < 3; c++) {
            s = s * 1664525u + 1013904223u;
            bary[3 * i + (size_t)c] = (float)(s >> 8) / 16777216.0f * 0.5f;
            key[3 * i + (size_t)c] = (int16_t)((int)(s >> 16) - 32768);
        }
    }
    packed_transfer pt = pack_transfer(NT, tv, bary, key);
    float *out[2][3], *aligned[2][3];
    size_t flagged_count[2][3];
    for (int v = 0; v < 2; v++) {
        pose__kernels_force_generic(v);
        for (int method = 0; method < 3; method++) {
            out[v][method] = zalloc(3 * NV * sizeof(float) + 3 * 2 * NT * sizeof(float) + 64);
            float *o = out[v][method];
            pose__skin(method, &ps.mesh, pal, 0, ps.mesh.block_count, o);
            memcpy(tp, o, 3 * NV * sizeof(float));
            /* odd offsets: outputs not 32-byte aligned take the lane path */
            uint32_t fl[2][NT + 8];
            size_t nf = pose__transfer(&pt.mesh, tp, 0, pt.mesh.block_count, o + 3 * NV + 1,
                                       o + 3 * NV + 3 * NT + 1, fl[0]);
            /* and aligned ones take the vector (streaming) path */
            aligned[v][method] = zalloc(2 * 3 * NT * sizeof(float) + 64);
            float *a = aligned[v][method];
            size_t nf2 = pose__transfer(&pt.mesh, tp, 0, pt.mesh.block_count, a,
                                        a + ((3 * NT + 15) & ~15), fl[1]);
            assert_int_equal(nf, nf2);
            assert_memory_equal(fl[0], fl[1], nf * sizeof(uint32_t));
            flagged_count[v][method] = nf;
        }
    }
    pose__kernels_force_generic(0);
    for (int method = 0; method < 3; method++) {
        assert_memory_equal(out[0][method], out[1][method],
                            3 * NV * sizeof(float) + 3 * 2 * NT * sizeof(float) + 4);
        assert_memory_equal(aligned[0][method], aligned[1][method], 2 * 3 * NT * sizeof(float));
        assert_int_equal(flagged_count[0][method], flagged_count[1][method]);
        /* the unaligned and aligned paths agree too */
        assert_memory_equal(aligned[1][method], out[1][method] + 3 * NV + 1, 3 * NT * sizeof(float));
        free(out[0][method]);
        free(out[1][method]);
        free(aligned[0][method]);
        free(aligned[1][method]);
    }
    free_skin(&ps);
    free_transfer(&pt);
}

/* A vertex whose tet is turned inside out is listed, and gets the normal of
 * its triangle fan. */
static void test_inverted_tet_uses_triangle_normal(void **unused)
{
    (void)unused;
    /* tissue vertex 0 at the centre of a fan of 4 triangles in the plane z = 0 */
    const uint32_t tv[4] = {0, 1, 2, 3};
    const float b3[3] = {0.1f, 0.1f, 0.1f};
    const int16_t key[3] = {0, 0, 32767};
    packed_transfer pt = pack_transfer(1, tv, b3, key);
    const uint32_t fan_offset[2] = {0, 4};
    const uint32_t fan[8] = {1, 2, 2, 3, 3, 4, 4, 1}; /* neighbours 1..4 counter-clockwise */
    pt.mesh.fan_offset = fan_offset;
    pt.mesh.fan = fan;
    float good[16] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    float inverted[16] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, -1}; /* v3 pushed through */
    float *pos = zalloc(3 * sizeof(float)), *nrm = zalloc(3 * sizeof(float));
    uint32_t flagged[8];
    assert_int_equal(pose__transfer(&pt.mesh, good, 0, 1, pos, nrm, flagged), 0);
    assert_int_equal(pose__transfer(&pt.mesh, inverted, 0, 1, pos, nrm, flagged), 1);
    assert_int_equal(flagged[0], 0);
    /* positions of the fan: the vertex and a square around it, tilted about x */
    float surface[15] = {0, 0, 0, 1, 0, 0, 0, 0.8f, 0.6f, -1, 0, 0, 0, -0.8f, -0.6f};
    pose__transfer_fix_normals(&pt.mesh, surface, flagged, 1, nrm);
    assert_near(nrm[0], 0.0, 1e-6);
    assert_near(nrm[1], -0.6, 1e-6);
    assert_near(nrm[2], 0.8, 1e-6);
    free(pos);
    free(nrm);
    free_transfer(&pt);
}

/* Decomposition inverts composition for all orders, at gimbal lock too. */
static void test_euler_round_trip(void **unused)
{
    (void)unused;
    const float cases[][3] = {
        {10, 20, 30}, {-170, 80, 95}, {45, -89.5f, -120}, {0, 90, 0}, {30, -90, 0}, {0, 0, 0},
    };
    for (int order = 0; order < 6; order++) {
        for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
            int axes[3];
            pose__euler_axes(order, axes);
            float deg[3] = {0, 0, 0};
            /* cases give angles first/middle/last axis */
            for (int k = 0; k < 3; k++)
                deg[axes[k]] = cases[c][k];
            float q[4], back[3], q2[4];
            pose__euler_to_quat(deg, order, q);
            pose__quat_to_euler(q, order, back);
            pose__euler_to_quat(back, order, q2);
            double qd[4] = {q[0], q[1], q[2], q[3]};
            assert_true(dq_dist(qd, q2) < 2e-6);
            if (fabsf(cases[c][1]) < 89.0f)
                for (int k = 0; k < 3; k++)
                    assert_near(back[k], deg[k], 1e-3);
        }
    }
    float q[4];
    const float zero[3] = {0, 0, 0};
    pose__euler_to_quat(zero, 3, q);
    assert_true(q[0] == 0.0f && q[1] == 0.0f && q[2] == 0.0f && q[3] == 1.0f);
    assert_string_equal(pose__euler_name(4), "ZXY");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_blend_antipodal_quaternions),
        cmocka_unit_test(test_single_joint_rigid_all_methods),
        cmocka_unit_test(test_transfer_affine_exact),
        cmocka_unit_test(test_euler_round_trip),
        cmocka_unit_test(test_variants_identical),
        cmocka_unit_test(test_inverted_tet_uses_triangle_normal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
