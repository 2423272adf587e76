/* SPDX-License-Identifier: Apache-2.0 */
/* The baked body's skin vertices outside its tet mesh keep their rest offset
 * to the mesh (within 0.5 mm) at deep poses, now that pose_apply places them
 * by multi-anchor binding; the extrapolated transfer they had before is
 * measured beside it. Offset: distance to the tet mesh's boundary surface. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pose/pose.h"
#include "tri_distance.h"

typedef struct face {
    uint32_t v[3]; /* sorted, for matching */
    uint32_t o[3]; /* as in the tet */
} face;

static int cmp_face(const void *a, const void *b)
{
    const face *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->v[k] != y->v[k])
            return x->v[k] < y->v[k] ? -1 : 1;
    return 0;
}

/* Faces of exactly one tet: the mesh's boundary, 3 indices each. */
static uint32_t *boundary(const pose_tet_info *t, size_t *count)
{
    static const int fv[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    face *f = malloc(4 * t->tet_count * sizeof *f);
    assert_non_null(f);
    for (size_t i = 0; i < t->tet_count; i++)
        for (int k = 0; k < 4; k++) {
            face *x = &f[4 * i + (size_t)k];
            for (int c = 0; c < 3; c++)
                x->o[c] = x->v[c] = t->tets[4 * i + (size_t)fv[k][c]];
            for (int a = 0; a < 2; a++) /* sort 3 */
                for (int b = 0; b < 2 - a; b++)
                    if (x->v[b] > x->v[b + 1]) {
                        uint32_t s = x->v[b];
                        x->v[b] = x->v[b + 1];
                        x->v[b + 1] = s;
                    }
        }
    qsort(f, 4 * t->tet_count, sizeof *f, cmp_face);
    uint32_t *out = malloc(3 * 4 * t->tet_count * sizeof(uint32_t));
    assert_non_null(out);
    size_t n = 0, all = 4 * t->tet_count;
    for (size_t i = 0; i < all;) {
        size_t j = i + 1;
        while (j < all && cmp_face(&f[i], &f[j]) == 0)
            j++;
        if (j == i + 1) {
            memcpy(out + 3 * n, f[i].o, 3 * sizeof(uint32_t));
            n++;
        }
        i = j;
    }
    free(f);
    *count = n;
    return out;
}

static double surface_distance(const float *p, const float *pos, const uint32_t *faces, size_t nf)
{
    double best = INFINITY;
    for (size_t f = 0; f < nf; f++) {
        const uint32_t *v = faces + 3 * f;
        const float *a = pos + 3 * (size_t)v[0], *b = pos + 3 * (size_t)v[1], *c = pos + 3 * (size_t)v[2];
        /* a bounding-sphere test first: most faces are far */
        double dx = (double)p[0] - a[0], dy = (double)p[1] - a[1], dz = (double)p[2] - a[2];
        double r = fmax(fmax(fabs((double)b[0] - a[0]), fabs((double)b[1] - a[1])), fabs((double)b[2] - a[2])) +
                   fmax(fmax(fabs((double)c[0] - a[0]), fabs((double)c[1] - a[1])), fabs((double)c[2] - a[2]));
        if (sqrt(dx * dx + dy * dy + dz * dz) - 2.0 * r > best)
            continue;
        best = fmin(best, tri_distance(p, a, b, c));
    }
    return best;
}

typedef struct pose_case {
    const char *label;
    const char *joint; /* NULL: the neutral posture (arms at the sides) */
    float deg[3];
} pose_case;

static void outside_skin_keeps_offset(void **unused)
{
    (void)unused;
    const char *path = getenv("POSE_BIND_RIG");
    assert_non_null(path);
    pose_rig *rig;
    if (pose_rig_load(path, &rig) != POSE_OK)
        fail_msg("%s", pose_last_error());
    pose_tet_info tets;
    assert_int_equal(pose_rig_tet_info(rig, &tets), POSE_OK);
    size_t nf;
    uint32_t *faces = boundary(&tets, &nf);

    int skin = -1;
    pose_tissue_info ti;
    for (int t = 0; t < (int)pose_rig_tissue_count(rig) && skin < 0; t++) {
        assert_int_equal(pose_rig_tissue_info(rig, t, &ti), POSE_OK);
        if (ti.kind == POSE_TISSUE_SKIN)
            skin = t;
    }
    assert_true(skin >= 0);
    const uint32_t *tet;
    const float *bary;
    assert_int_equal(pose_rig_tissue_embedding(rig, skin, &tet, &bary), POSE_OK);
    size_t *out = malloc(ti.vertex_count * sizeof *out), n = 0;
    assert_non_null(out);
    for (size_t v = 0; v < ti.vertex_count; v++) {
        const float *b = bary + 4 * v;
        if (b[0] < -1e-4f || b[1] < -1e-4f || b[2] < -1e-4f || b[3] < -1e-4f)
            out[n++] = v;
    }
    double *rest = malloc((n ? n : 1) * sizeof *rest), rest_max = 0.0;
    assert_non_null(rest);
    for (size_t i = 0; i < n; i++) {
        rest[i] = surface_distance(ti.rest_positions + 3 * out[i], tets.rest_positions, faces, nf);
        rest_max = fmax(rest_max, rest[i]);
    }
    printf("%zu of %zu skin vertices outside the tet mesh (%.2f %%), up to %.2f mm out; "
           "%zu boundary faces\n", n, ti.vertex_count, 100.0 * (double)n / (double)ti.vertex_count,
           1e3 * rest_max, nf);
    assert_true(n > 0);

    const pose_case cases[] = {
        {"knee flexion 120", "knee_r", {120, 0, 0}},   {"elbow flexion 120", "elbow_r", {120, 0, 0}},
        {"shoulder flexion 150", "shoulder_r", {150, 0, 0}}, {"hip flexion 90", "hip_r", {90, 0, 0}},
        {"arms at the sides", NULL, {0, 0, 0}},
    };
    const pose_method methods[2] = {POSE_DQS, POSE_LBS};
    const char *method_name[2] = {"DQS", "LBS"};
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    float *old = malloc(3 * (n ? n : 1) * sizeof(float));
    assert_non_null(old);
    double worst = 0.0;
    for (int m = 0; m < 2; m++)
        for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
            assert_int_equal(pose_reset(st), POSE_OK);
            assert_int_equal(pose_set_neutral(st) >= 0, 1);
            if (cases[c].joint) {
                int j = pose_rig_find_joint(rig, cases[c].joint);
                assert_true(j >= 0);
                assert_true(pose_set_joint_clinical(st, j, cases[c].deg) >= 0);
            }
            assert_int_equal(pose_set_method(st, methods[m]), POSE_OK);
            assert_int_equal(pose_apply(st), POSE_OK);
            size_t nv;
            const float *pos = pose_tissue_positions(st, skin, &nv), *tp = pose_tet_positions(st, NULL);
            double err_new = 0.0, err_old = 0.0;
            for (size_t i = 0; i < n; i++) {
                const uint32_t *tv = tets.tets + 4 * (size_t)tet[out[i]];
                const float *b = bary + 4 * out[i];
                for (int d = 0; d < 3; d++) /* the extrapolated transfer: one tet's affine map */
                    old[3 * i + d] = b[0] * tp[3 * (size_t)tv[0] + d] + b[1] * tp[3 * (size_t)tv[1] + d] +
                                     b[2] * tp[3 * (size_t)tv[2] + d] + b[3] * tp[3 * (size_t)tv[3] + d];
                err_new = fmax(err_new, fabs(surface_distance(pos + 3 * out[i], tp, faces, nf) - rest[i]));
                err_old = fmax(err_old, fabs(surface_distance(old + 3 * i, tp, faces, nf) - rest[i]));
            }
            printf("%s, %-20s: offset to the mesh changes by up to %.3f mm (one tet, "
                   "extrapolated: %.3f mm)\n", method_name[m], cases[c].label, 1e3 * err_new, 1e3 * err_old);
            worst = fmax(worst, err_new);
        }
    assert_true(worst <= 0.5e-3); /* metres */

    /* The outside vertices are placed inside the transfer's parts: the same
     * for any thread count, bit for bit. */
    pose_state *two;
    pose_state_options o = {.size = sizeof o, .threads = 2, .method = POSE_DQS};
    assert_int_equal(pose_state_create_ex(rig, &o, &two), POSE_OK);
    assert_int_equal(pose_set_threads(st, 1), POSE_OK);
    assert_int_equal(pose_set_method(st, POSE_DQS), POSE_OK);
    for (pose_state *s2[2] = {st, two}, **x = s2; x < s2 + 2; x++) {
        assert_int_equal(pose_reset(*x), POSE_OK);
        assert_true(pose_set_joint_clinical(*x, pose_rig_find_joint(rig, "elbow_r"), cases[1].deg) >= 0);
        assert_int_equal(pose_apply(*x), POSE_OK);
    }
    size_t nv;
    const float *a = pose_tissue_positions(st, skin, &nv), *b = pose_tissue_positions(two, skin, NULL);
    assert_memory_equal(a, b, 3 * nv * sizeof(float));
    pose_state_free(two);
    free(old);
    free(rest);
    free(out);
    free(faces);
    pose_state_free(st);
    pose_rig_free(rig);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(outside_skin_keeps_offset),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
