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
    const uint8_t joints[4] = {0, 1, 1, 0};
    const uint16_t weights[4] = {16384, 16384, 16384, 16384};
    pose__skin_mesh mesh = {.vertex_count = 2, .influences = 2, .rest = rest, .cor = cor,
                            .joints8 = joints, .weights = weights};
    for (int method = POSE__SKIN_DQS; method <= POSE__SKIN_COR; method++) {
        float out[6];
        pose__skin(method, &mesh, pal, 0, 2, out);
        for (int v = 0; v < 2; v++) {
            double p[3] = {rest[3 * v], rest[3 * v + 1], rest[3 * v + 2]}, e[3];
            dq_rot(e, q, p);
            for (int k = 0; k < 3; k++)
                assert_near(out[3 * v + k], e[k] + t[k], 1e-5);
        }
    }
}

/* LBS, DQS and CoR agree for a vertex bound to one joint (rigid), and the
 * 16-bit joint index path matches the 8-bit one. */
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
    const uint8_t j8[3] = {2, 0, 1};
    const uint16_t j16[3] = {2, 0, 1};
    const uint16_t w[3] = {32768, 0, 0};
    pose__skin_mesh m8 = {.vertex_count = 1, .influences = 3, .rest = rest, .cor = cor,
                          .joints8 = j8, .weights = w};
    pose__skin_mesh m16 = m8;
    m16.joints8 = NULL;
    m16.joints16 = j16;
    double xq[4] = {x[2].q[0], x[2].q[1], x[2].q[2], x[2].q[3]}, p[3] = {rest[0], rest[1], rest[2]}, e[3];
    dq_rot(e, xq, p);
    for (int method = 0; method < 3; method++) {
        float a[3], b[3];
        pose__skin(method, &m8, pal, 0, 1, a);
        pose__skin(method, &m16, pal, 0, 1, b);
        assert_memory_equal(a, b, sizeof a);
        for (int k = 0; k < 3; k++)
            assert_near(a[k], e[k] + x[2].t[k], 1e-5);
    }
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
    float moved[12];
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
    pose__transfer_mesh mesh = {.vertex_count = N, .tet_vertices = tv, .bary = bary, .normal_key = key};
    float pos[3 * N], nrm[3 * N];
    pose__transfer(&mesh, moved, 0, N, pos, nrm);
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
    float pos2[3 * N];
    pose__transfer(&mesh, moved, 0, N, pos2, NULL);
    assert_memory_equal(pos, pos2, sizeof pos);
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
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
