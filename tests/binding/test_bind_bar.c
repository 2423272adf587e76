/* SPDX-License-Identifier: Apache-2.0 */
/* Multi-anchor binding on a bent, twisted beam (pose/binding.h): one anchor
 * shows seams where neighbouring tets rotate differently, four blend them
 * away; rigid motions move bound points rigidly; the API's checks. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "bind_bar.h"
#include "pose/binding.h"

#define DEG 0.017453292519943295

/* A sleeve around the beam, off its faces by DELTA, over x in [X0, X1]:
 * four planar grids (y = -DELTA, y = 1 + DELTA, z = -DELTA, z = 1 + DELTA)
 * of spacing H. Outside the tet mesh, where a binding is what moves it. */
#define DELTA 0.05f
#define H 0.01f
#define X0 3.0f
#define X1 5.0f

typedef struct sleeve {
    int nu, nv;    /* grid points per face along x and across */
    size_t count;  /* 4 * nu * nv */
    float *xyz;
} sleeve;

static sleeve make_sleeve(void)
{
    sleeve s;
    s.nu = (int)lroundf((X1 - X0) / H) + 1;
    s.nv = (int)lroundf((1.0f + 2.0f * DELTA) / H) + 1;
    s.count = 4 * (size_t)s.nu * (size_t)s.nv;
    s.xyz = malloc(3 * s.count * sizeof(float));
    assert_non_null(s.xyz);
    size_t i = 0;
    for (int f = 0; f < 4; f++)
        for (int u = 0; u < s.nu; u++)
            for (int v = 0; v < s.nv; v++, i++) {
                float across = -DELTA + H * (float)v, fixed = (f & 1) ? 1.0f + DELTA : -DELTA;
                s.xyz[3 * i] = X0 + H * (float)u;
                s.xyz[3 * i + 1] = f < 2 ? fixed : across;
                s.xyz[3 * i + 2] = f < 2 ? across : fixed;
            }
    return s;
}

static void quat_axis(float q[4], double ax, double ay, double az, double deg)
{
    double n = sqrt(ax * ax + ay * ay + az * az), h = 0.5 * deg * DEG;
    q[0] = (float)(sin(h) * ax / n);
    q[1] = (float)(sin(h) * ay / n);
    q[2] = (float)(sin(h) * az / n);
    q[3] = (float)cos(h);
}

/* Bend 90 degrees about z and twist 90 about x, spread over joints 1..7. */
static void bend_twist(pose_state *st)
{
    float bend[4], twist[4], q[4];
    quat_axis(bend, 0, 0, 1, 90.0 / 7.0);
    quat_axis(twist, 1, 0, 0, 90.0 / 7.0);
    q[0] = bend[3] * twist[0] + bend[0] * twist[3] + bend[1] * twist[2] - bend[2] * twist[1];
    q[1] = bend[3] * twist[1] - bend[0] * twist[2] + bend[1] * twist[3] + bend[2] * twist[0];
    q[2] = bend[3] * twist[2] + bend[0] * twist[1] - bend[1] * twist[0] + bend[2] * twist[3];
    q[3] = bend[3] * twist[3] - bend[0] * twist[0] - bend[1] * twist[1] - bend[2] * twist[2];
    for (int j = 1; j <= 7; j++)
        assert_int_equal(pose_set_joint(st, j, q), POSE_OK);
    assert_int_equal(pose_set_method(st, POSE_DQS), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
}

static double dist3(const float *a, const float *b)
{
    double x = (double)a[0] - b[0], y = (double)a[1] - b[1], z = (double)a[2] - b[2];
    return sqrt(x * x + y * y + z * z);
}

typedef struct seam {
    double border;  /* largest excess stretch of an edge whose ends' nearest anchors differ */
    double all;     /* largest excess stretch of any edge */
    double dqs;     /* largest |l' - l'_dqs| / l: against DQS of the sleeve points */
    double plain;   /* largest |l'/l - 1| of any edge (bend and twist included) */
    size_t borders; /* edges across anchor borders */
} seam;

/* Excess stretch of an edge: its stretch under the binding minus the
 * stretch of the edge between its ends' feet (their nearest points on the
 * beam, moved by the tet mesh as the rig's tissues are), |l' - l'_feet| / l.
 * What the binding adds to the mesh's own deformation: the bend's stretch
 * of the outer side and the mesh's piecewise-linear kinks do not count, a
 * seam does. Edges whose feet coincide at rest (across the sleeve's corners,
 * both ends on the beam's edge) have no such reference and are skipped. */
static seam measure(const sleeve *s, const pose_binding *b, const float *bound, const float *feet_rest,
                    const float *feet, const float *dqs)
{
    seam m = {0};
    pose_binding_anchor a0[POSE_BINDING_MAX_ANCHORS], a1[POSE_BINDING_MAX_ANCHORS];
    for (int f = 0; f < 4; f++)
        for (int u = 0; u < s->nu; u++)
            for (int v = 0; v < s->nv; v++)
                for (int dir = 0; dir < 2; dir++) {
                    if ((dir == 0 && u + 1 >= s->nu) || (dir == 1 && v + 1 >= s->nv))
                        continue;
                    size_t i = ((size_t)f * s->nu + u) * s->nv + v;
                    size_t j = dir == 0 ? i + s->nv : i + 1;
                    double stretch = dist3(bound + 3 * i, bound + 3 * j) / H;
                    m.plain = fmax(m.plain, fabs(stretch - 1.0));
                    m.dqs = fmax(m.dqs, fabs(stretch - dist3(dqs + 3 * i, dqs + 3 * j) / H));
                    if (dist3(feet_rest + 3 * i, feet_rest + 3 * j) < 0.5 * H)
                        continue;
                    double excess = fabs(stretch - dist3(feet + 3 * i, feet + 3 * j) / H);
                    m.all = fmax(m.all, excess);
                    assert_int_equal(pose_binding_vertex_anchors(b, i, a0), POSE_OK);
                    assert_int_equal(pose_binding_vertex_anchors(b, j, a1), POSE_OK);
                    if (a0[0].index != a1[0].index) {
                        m.borders++;
                        m.border = fmax(m.border, excess);
                    }
                }
    return m;
}

static void seam_one_anchor_vs_four(void **unused)
{
    (void)unused;
    pose_rig *rig = bar_rig();
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    bend_twist(st);
    sleeve s = make_sleeve();
    float *dqs = malloc(3 * s.count * sizeof(float)), *out = malloc(3 * s.count * sizeof(float));
    float *feet_rest = malloc(3 * s.count * sizeof(float)), *feet = malloc(3 * s.count * sizeof(float));
    assert_non_null(dqs);
    assert_non_null(out);
    assert_non_null(feet_rest);
    assert_non_null(feet);
    for (size_t i = 0; i < s.count; i++) {
        bar_dqs(st, s.xyz + 3 * i, dqs + 3 * i);
        for (int d = 0; d < 3; d++) /* nearest point of the beam [0,8]x[0,1]x[0,1] */
            feet_rest[3 * i + d] = d == 0 ? s.xyz[3 * i] : fminf(fmaxf(s.xyz[3 * i + d], 0.0f), 1.0f);
    }
    /* points on the mesh bound to it follow the tets exactly (offset 0) */
    pose_binding *fb;
    assert_int_equal(pose_binding_create(rig, feet_rest, s.count, NULL, &fb), POSE_OK);
    assert_int_equal(pose_binding_apply(fb, st, feet), POSE_OK);
    pose_binding_free(fb);

    seam m[2];
    const unsigned n[2] = {1, 4};
    for (int k = 0; k < 2; k++) {
        pose_binding_options o = {.size = sizeof o, .anchors = n[k]};
        pose_binding *b;
        assert_int_equal(pose_binding_create(rig, s.xyz, s.count, &o, &b), POSE_OK);
        assert_int_equal(pose_binding_anchor_count(b), n[k]);
        assert_int_equal(pose_binding_vertex_count(b), s.count);
        assert_int_equal(pose_binding_apply(b, st, out), POSE_OK);
        m[k] = measure(&s, b, out, feet_rest, feet, dqs);
        printf("n = %u: %zu sleeve vertices, %zu edges across anchor borders; excess edge stretch "
               "max %.2f %% across borders, %.2f %% overall (against DQS of the points %.2f %%, "
               "plain stretch %.2f %%)\n",
               n[k], s.count, m[k].borders, 100.0 * m[k].border, 100.0 * m[k].all,
               100.0 * m[k].dqs, 100.0 * m[k].plain);
        pose_binding_free(b);
    }
    assert_true(m[0].borders > 100);
    assert_true(m[0].border > 0.10); /* the seam, clearly */
    assert_true(m[1].all < 0.05);    /* blended away */
    free(dqs);
    free(feet_rest);
    free(feet);
    free(out);
    free(s.xyz);
    pose_state_free(st);
    pose_rig_free(rig);
}

static void rotate(float out[3], const float q[4], const float v[3])
{
    float ux = q[0], uy = q[1], uz = q[2], w = q[3];
    float cx = uy * v[2] - uz * v[1], cy = uz * v[0] - ux * v[2], cz = ux * v[1] - uy * v[0];
    out[0] = v[0] + 2.0f * (w * cx + uy * cz - uz * cy);
    out[1] = v[1] + 2.0f * (w * cy + uz * cx - ux * cz);
    out[2] = v[2] + 2.0f * (w * cz + ux * cy - uy * cx);
}

/* A rigid motion of the whole beam moves every bound point rigidly: each
 * tet's rotation is the motion's, each foot moves with it. */
static void rigid_motion_is_exact(void **unused)
{
    (void)unused;
    pose_rig *rig = bar_rig();
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    float q[4];
    quat_axis(q, 1, 2, 3, 140.0);
    const float t[3] = {0.3f, -2.0f, 5.0f};
    assert_int_equal(pose_set_root(st, t, q), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    sleeve s = make_sleeve();
    float *out = malloc(3 * s.count * sizeof(float));
    assert_non_null(out);
    const uint32_t sources[3] = {POSE_BINDING_NODES, POSE_BINDING_BONES,
                                 POSE_BINDING_NODES | POSE_BINDING_BONES};
    for (int k = 0; k < 3; k++) {
        pose_binding_options o = {.size = sizeof o, .sources = sources[k]};
        pose_binding *b;
        assert_int_equal(pose_binding_create(rig, s.xyz, s.count, &o, &b), POSE_OK);
        assert_int_equal(pose_binding_apply(b, st, out), POSE_OK);
        double worst = 0.0;
        for (size_t i = 0; i < s.count; i++) {
            float e[3];
            rotate(e, q, s.xyz + 3 * i);
            for (int d = 0; d < 3; d++)
                e[d] += t[d];
            worst = fmax(worst, dist3(e, out + 3 * i));
        }
        printf("rigid motion, sources 0x%x: largest error %.3g (beam length 8)\n",
               (unsigned)sources[k], worst);
        assert_true(worst < 1e-5); /* a few float roundings of coordinates up to ~9 */
        pose_binding_free(b);
    }
    free(out);
    free(s.xyz);
    pose_state_free(st);
    pose_rig_free(rig);
}

/* Same pose, same result, whatever the binding posed before; at rest the
 * points stay where they are. */
static void deterministic_and_rest(void **unused)
{
    (void)unused;
    pose_rig *rig = bar_rig();
    pose_state *rest, *bent;
    assert_int_equal(pose_state_create(rig, &rest), POSE_OK);
    assert_int_equal(pose_state_create(rig, &bent), POSE_OK);
    assert_int_equal(pose_apply(rest), POSE_OK);
    bend_twist(bent);
    sleeve s = make_sleeve();
    float *a = malloc(3 * s.count * sizeof(float)), *b2 = malloc(3 * s.count * sizeof(float));
    assert_non_null(a);
    assert_non_null(b2);
    pose_binding *b;
    assert_int_equal(pose_binding_create(rig, s.xyz, s.count, NULL, &b), POSE_OK);
    assert_int_equal(pose_binding_apply(b, bent, a), POSE_OK);
    assert_int_equal(pose_binding_apply(b, rest, b2), POSE_OK);
    double worst = 0.0;
    for (size_t i = 0; i < s.count; i++)
        worst = fmax(worst, dist3(b2 + 3 * i, s.xyz + 3 * i));
    assert_true(worst < 1e-5);
    assert_int_equal(pose_binding_apply(b, bent, b2), POSE_OK);
    assert_memory_equal(a, b2, 3 * s.count * sizeof(float));
    pose_binding_free(b);
    free(a);
    free(b2);
    free(s.xyz);
    pose_state_free(rest);
    pose_state_free(bent);
    pose_rig_free(rig);
}

static void api_checks(void **unused)
{
    (void)unused;
    pose_rig *rig = bar_rig(), *other = bar_rig();
    pose_state *st;
    assert_int_equal(pose_state_create(other, &st), POSE_OK);
    const float p[6] = {1.0f, 0.5f, 0.5f, 2.0f, -0.1f, 0.5f};
    pose_binding *b = (pose_binding *)p;
    assert_int_equal(pose_binding_create(NULL, p, 2, NULL, &b), POSE_ERR_INVALID_ARGUMENT);
    assert_null(b);
    assert_int_equal(pose_binding_create(rig, p, 0, NULL, &b), POSE_ERR_INVALID_ARGUMENT);
    pose_binding_options o = {.size = sizeof o, .anchors = POSE_BINDING_MAX_ANCHORS + 1};
    assert_int_equal(pose_binding_create(rig, p, 2, &o, &b), POSE_ERR_INVALID_ARGUMENT);
    o = (pose_binding_options){.size = sizeof o, .sources = 4};
    assert_int_equal(pose_binding_create(rig, p, 2, &o, &b), POSE_ERR_INVALID_ARGUMENT);
    o = (pose_binding_options){.size = 4};
    assert_int_equal(pose_binding_create(rig, p, 2, &o, &b), POSE_ERR_INVALID_ARGUMENT);
    const float bad[3] = {NAN, 0.0f, 0.0f};
    assert_int_equal(pose_binding_create(rig, bad, 1, NULL, &b), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "not finite"));

    o = (pose_binding_options){.size = sizeof o, .anchors = 8, .sources = POSE_BINDING_BONES};
    assert_int_equal(pose_binding_create(rig, p, 2, &o, &b), POSE_OK);
    pose_binding_anchor an[POSE_BINDING_MAX_ANCHORS];
    assert_int_equal(pose_binding_vertex_anchors(b, 0, an), POSE_OK);
    assert_int_equal(an[0].kind, POSE_BINDING_BONES);
    /* point (1, .5, .5) lies on bones 0 (segment 0-1) and 1 (1-2): distance 0 */
    assert_true(an[0].index == 0 || an[0].index == 1);
    float sum = 0.0f;
    for (int k = 0; k < 8; k++)
        sum += an[k].weight;
    assert_true(fabsf(sum - 1.0f) < 1e-6f);
    assert_int_equal(pose_binding_vertex_anchors(b, 2, an), POSE_ERR_INVALID_ARGUMENT);
    float out[6];
    assert_int_equal(pose_binding_apply(b, st, out), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "another rig"));
    assert_int_equal(pose_binding_apply(b, NULL, out), POSE_ERR_INVALID_ARGUMENT);
    pose_binding_free(b);
    pose_binding_free(NULL);
    assert_int_equal(pose_binding_vertex_count(NULL), 0);
    pose_state_free(st);
    pose_rig_free(rig);
    pose_rig_free(other);
}

/* A mesh of flat tets only gives no frame: the host's binding says so, and
 * a rig whose tissue vertex lies outside such a mesh still loads (the
 * transfer keeps moving it). */
static void flat_mesh(void **unused)
{
    (void)unused;
    const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    const uint32_t tet[4] = {0, 1, 2, 3};
    const uint16_t label = 0, wj[4] = {0, 0, 0, 0};
    const float w[4] = {1, 1, 1, 1};
    const float vtx[3] = {2.0f, 0.0f, 0.0f}, bary[4] = {-1.0f, 2.0f, 0.0f, 0.0f};
    const uint32_t vtet = 0;
    pose_joint_desc j = {.name = "root", .parent = -1, .rest_model = {{0, 0, 0, 1}, {0, 0, 0}}};
    pose_tissue_desc t = {.name = "skin", .kind = POSE_TISSUE_SKIN, .joint = -1, .vertex_count = 1,
                          .positions = vtx, .tet = &vtet, .bary = bary};
    pose_rig_desc d = {.joint_count = 1, .joints = &j, .tet_vertex_count = 4, .tet_positions = pos,
                       .tet_count = 1, .tets = tet, .tet_labels = &label, .influences = 1,
                       .weight_joints = wj, .weights = w, .tissue_count = 1, .tissues = &t};
    pose_rig *rig;
    if (pose_rig_create(&d, NULL, &rig) != POSE_OK)
        fail_msg("%s", pose_last_error());
    pose_binding *b;
    assert_int_equal(pose_binding_create(rig, vtx, 1, NULL, &b), POSE_ERR_UNSUPPORTED);
    pose_binding_options o = {.size = sizeof o, .sources = POSE_BINDING_BONES};
    assert_int_equal(pose_binding_create(rig, vtx, 1, &o, &b), POSE_OK); /* a joint will do */
    pose_binding_free(b);
    pose_rig_free(rig);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(seam_one_anchor_vs_four),
        cmocka_unit_test(rigid_motion_is_exact),
        cmocka_unit_test(deterministic_and_rest),
        cmocka_unit_test(api_checks),
        cmocka_unit_test(flat_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
