/* SPDX-License-Identifier: Apache-2.0 */
/* The synthetic rig generator: options, weights, embedding, CoR, validity. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pose_synth.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static pose_synth_rig *bar(void)
{
    pose_synth_rig *r = NULL;
    assert_int_equal(pose_synth_bar(NULL, &r), POSE_OK);
    assert_non_null(r);
    return r;
}

static void test_invalid_options(void **state)
{
    (void)state;
    pose_synth_rig *r = (pose_synth_rig *)1;
    const pose_synth_bar_options bad[] = {
        {.bones = -1}, {.bones = 65}, {.layers_per_bone = 12}, {.rings = 3},
        {.sectors = 4}, {.influences = 9}, {.sigma = 0.2f}, {.radius = -1.0f},
        {.bone_length = NAN}, {.cor = (pose_synth_cor_mode)7},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(pose_synth_bar(&bad[i], &r), POSE_ERR_INVALID_ARGUMENT);
        assert_null(r);
    }
    assert_int_equal(pose_synth_bar(NULL, NULL), POSE_ERR_INVALID_ARGUMENT);
    pose_synth_body_options tiny = {.target_tets = 10};
    assert_int_equal(pose_synth_body(&tiny, &r), POSE_ERR_INVALID_ARGUMENT);
    float cor[3];
    assert_int_equal(pose_synth_compute_cor(NULL, 0.1f, POSE_SYNTH_COR_EXACT, cor),
                     POSE_ERR_INVALID_ARGUMENT);
    pose_synth_free(NULL);
}

/* Default bar: 4 bones x 16 layers, 4 rings x 16 sectors. */
static void test_bar_counts(void **state)
{
    (void)state;
    pose_synth_rig *r = bar();
    const pose_rig_desc *d = pose_synth_desc(r);
    assert_int_equal(d->joint_count, 4);
    assert_int_equal(d->tet_vertex_count, 65 * 65);
    assert_int_equal(d->tet_count, 64 * (16 + 3 * 32) * 3);
    assert_int_equal(d->influences, 4);
    assert_int_equal(d->tissue_count, 5);
    assert_string_equal(d->tissues[0].name, "skin");
    assert_int_equal(d->tissues[0].kind, POSE_TISSUE_SKIN);
    assert_string_equal(d->tissues[3].name, "bone2");
    assert_int_equal(d->tissues[3].joint, 2);
    assert_int_equal(d->joints[0].parent, -1);
    for (int j = 1; j < 4; j++) {
        assert_int_equal(d->joints[j].parent, j - 1);
        assert_float_equal(d->joints[j].rest_model.translation[0], (float)j, 1e-6);
        assert_float_equal(d->joints[j].limit_max_deg[1], 150.0f, 0.0f);
    }
    assert_int_equal(pose_synth_cor(r), POSE_SYNTH_COR_EXACT);
    pose_synth_free(r);
}

static void test_weights_partition_of_unity(void **state)
{
    (void)state;
    pose_synth_rig *r = bar();
    const pose_rig_desc *d = pose_synth_desc(r);
    size_t blended = 0;
    for (size_t v = 0; v < d->tet_vertex_count; v++) {
        const float *w = &d->weights[v * d->influences];
        float sum = 0.0f;
        for (unsigned k = 0; k < d->influences; k++) {
            assert_true(w[k] >= 0.0f);
            assert_true(d->weight_joints[v * d->influences + k] < d->joint_count);
            if (k)
                assert_true(w[k] <= w[k - 1]); /* largest first */
            sum += w[k];
        }
        assert_float_equal(sum, 1.0f, 1e-6);
        blended += w[1] > 0.0f;
    }
    /* Gaps are a quarter of the bar: a real share of vertices blends. */
    assert_true(blended > d->tet_vertex_count / 10);
    assert_true(blended < d->tet_vertex_count / 2);
    /* Every vertex of a bone tet belongs to that bone alone. */
    for (size_t t = 0; t < d->tet_count; t++) {
        if (!d->tet_labels[t])
            continue;
        for (int k = 0; k < 4; k++) {
            uint32_t v = d->tets[4 * t + k];
            assert_int_equal(d->weight_joints[v * d->influences], d->tet_labels[t] - 1);
            assert_float_equal(d->weights[v * d->influences], 1.0f, 0.0f);
        }
    }
    pose_synth_free(r);
}

static void check_embedding(const pose_rig_desc *d, double tolerance)
{
    for (size_t t = 0; t < d->tissue_count; t++) {
        const pose_tissue_desc *ts = &d->tissues[t];
        size_t on_vertex = 0;
        for (size_t v = 0; v < ts->vertex_count; v++) {
            const float *b = &ts->bary[4 * v];
            assert_true(ts->tet[v] < d->tet_count);
            assert_float_equal(b[0] + b[1] + b[2] + b[3], 1.0f, 1e-5);
            double p[3] = {0, 0, 0};
            float bmax = 0.0f;
            for (int k = 0; k < 4; k++) {
                const float *x = &d->tet_positions[3 * d->tets[4 * ts->tet[v] + k]];
                for (int i = 0; i < 3; i++)
                    p[i] += (double)b[k] * x[i];
                assert_true(b[k] > -1e-4f); /* inside (or on) its tet */
                bmax = b[k] > bmax ? b[k] : bmax;
            }
            for (int i = 0; i < 3; i++)
                assert_float_equal(p[i], ts->positions[3 * v + i], tolerance);
            on_vertex += bmax > 1.0f - 1e-4f;
            if (ts->kind == POSE_TISSUE_BONE) /* bones sit in their own bone tets */
                assert_int_equal(d->tet_labels[ts->tet[v]], ts->joint + 1);
        }
        /* Tissue vertices are not tet vertices, except the skin caps' centres
         * on the axis at both ends. */
        assert_true(on_vertex <= 2);
        for (size_t i = 0; i < 3 * ts->triangle_count; i++)
            assert_true(ts->triangles[i] < ts->vertex_count);
    }
}

static void test_embedding_reconstructs_vertices(void **state)
{
    (void)state;
    pose_synth_rig *r = bar();
    check_embedding(pose_synth_desc(r), 1e-5);
    pose_synth_free(r);
}

/* Closed and outward: the divergence theorem gives the cylinder's volume. */
static void test_skin_is_closed_and_outward(void **state)
{
    (void)state;
    pose_synth_rig *r = bar();
    const pose_tissue_desc *s = &pose_synth_desc(r)->tissues[0];
    double vol = 0.0;
    for (size_t t = 0; t < s->triangle_count; t++) {
        const float *a = &s->positions[3 * s->triangles[3 * t]];
        const float *b = &s->positions[3 * s->triangles[3 * t + 1]];
        const float *c = &s->positions[3 * s->triangles[3 * t + 2]];
        vol += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
                a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
                a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) / 6.0;
    }
    /* 24-gon prism of circumradius 0.25, length 4. */
    double expect = 4.0 * 0.5 * 24 * 0.25 * 0.25 * sin(2.0 * M_PI / 24);
    assert_float_equal(vol, expect, 1e-4);
    pose_synth_free(r);
}

static void test_cor_single_weight_is_rest_position(void **state)
{
    (void)state;
    pose_synth_rig *r = bar();
    const pose_rig_desc *d = pose_synth_desc(r);
    assert_non_null(d->cor);
    size_t single = 0;
    for (size_t v = 0; v < d->tet_vertex_count; v++)
        if (d->weights[v * d->influences + 1] == 0.0f) {
            for (int i = 0; i < 3; i++)
                assert_float_equal(d->cor[3 * v + i], d->tet_positions[3 * v + i], 0.0f);
            single++;
        }
    assert_true(single > 0);
    pose_synth_free(r);
}

/* At the middle of the gap between bones 0 and 1 (x = 1), every vertex is
 * weighted half and half, and the similar tets form a slab symmetric about
 * the axis and about the plane x = 1: the centre lies on the axis at x = 1. */
static void test_cor_symmetric_junction_on_axis(void **state)
{
    (void)state;
    pose_synth_rig *r = bar();
    const pose_rig_desc *d = pose_synth_desc(r);
    size_t checked = 0;
    for (size_t v = 0; v < d->tet_vertex_count; v++) {
        const float *p = &d->tet_positions[3 * v];
        if (fabsf(p[0] - 1.0f) > 1e-6f)
            continue;
        const float *w = &d->weights[v * d->influences];
        assert_float_equal(w[0], 0.5f, 1e-5);
        assert_float_equal(w[1], 0.5f, 1e-5);
        const float *c = &d->cor[3 * v];
        assert_float_equal(c[0], 1.0f, 2e-3);
        assert_true(hypotf(c[1], c[2]) < 2e-3f);
        checked++;
    }
    assert_int_equal(checked, 65);
    pose_synth_free(r);
}

static void test_cor_clustered_close_to_exact(void **state)
{
    (void)state;
    pose_synth_rig *r = bar();
    const pose_rig_desc *d = pose_synth_desc(r);
    float *cor = malloc(d->tet_vertex_count * 3 * sizeof(float));
    assert_non_null(cor);
    assert_int_equal(pose_synth_compute_cor(d, 0.1f, POSE_SYNTH_COR_CLUSTERED, cor), POSE_OK);
    double worst = 0.0;
    for (size_t i = 0; i < 3 * d->tet_vertex_count; i++)
        worst = fmax(worst, fabs((double)cor[i] - d->cor[i]));
    printf("bar: clustered CoR differs from exact by at most %.3g (radius 0.25)\n", worst);
    assert_true(worst < 0.01);
    free(cor);
    pose_synth_free(r);
}

/* The sparse implementation against the formula of design §2 written out
 * densely over every tet, for a sample of blend vertices. */
static void test_cor_exact_matches_formula(void **state)
{
    (void)state;
    pose_synth_rig *r = bar();
    const pose_rig_desc *d = pose_synth_desc(r);
    const unsigned K = d->influences;
    const size_t J = d->joint_count;
    const double sigma2 = 0.1 * 0.1;
    size_t checked = 0;
    for (size_t p = 0; p < d->tet_vertex_count && checked < 12; p += 23) {
        double wp[8] = {0};
        for (unsigned k = 0; k < K; k++)
            wp[d->weight_joints[p * K + k]] += d->weights[p * K + k];
        if (d->weights[p * K + 1] == 0.0f)
            continue;
        double num[3] = {0, 0, 0}, den = 0.0;
        for (size_t t = 0; t < d->tet_count; t++) {
            const uint32_t *tv = &d->tets[4 * t];
            double ws[8] = {0}, c[3] = {0, 0, 0};
            for (int v = 0; v < 4; v++) {
                for (unsigned k = 0; k < K; k++)
                    ws[d->weight_joints[tv[v] * K + k]] += 0.25 * d->weights[tv[v] * K + k];
                for (int i = 0; i < 3; i++)
                    c[i] += 0.25 * d->tet_positions[3 * tv[v] + i];
            }
            double s = 0.0;
            for (size_t i = 0; i < J; i++)
                for (size_t j = 0; j < J; j++)
                    if (i != j) {
                        double e = wp[i] * ws[j] - ws[i] * wp[j];
                        s += wp[i] * wp[j] * ws[i] * ws[j] * exp(-e * e / sigma2);
                    }
            const float *a = &d->tet_positions[3 * tv[0]];
            double m[3][3];
            for (int k = 0; k < 3; k++)
                for (int i = 0; i < 3; i++)
                    m[k][i] = (double)d->tet_positions[3 * tv[k + 1] + i] - a[i];
            double vol = fabs(m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                              m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                              m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])) / 6.0;
            den += s * vol;
            for (int i = 0; i < 3; i++)
                num[i] += s * vol * c[i];
        }
        assert_true(den > 0.0);
        for (int i = 0; i < 3; i++)
            assert_float_equal(d->cor[3 * p + i], num[i] / den, 1e-5);
        checked++;
    }
    assert_int_equal(checked, 12);
    pose_synth_free(r);
}

/* Through a file and back, every array is bit-identical. */
static void test_bar_file_round_trip(void **state)
{
    (void)state;
    pose_synth_rig *r = bar();
    const pose_rig_desc *d = pose_synth_desc(r);
    char path[1024];
    snprintf(path, sizeof path, "%s/bar.rig", getenv("POSE_TEST_TMP") ? getenv("POSE_TEST_TMP")
                                                                     : "/tmp");
    assert_int_equal(pose_rig_write_file(d, path), POSE_OK);
    pose_rig *rig;
    assert_int_equal(pose_rig_load(path, &rig), POSE_OK);
    pose_tet_info ti;
    assert_int_equal(pose_rig_tet_info(rig, &ti), POSE_OK);
    assert_memory_equal(ti.rest_positions, d->tet_positions, d->tet_vertex_count * 12);
    assert_memory_equal(ti.tets, d->tets, d->tet_count * 16);
    assert_memory_equal(ti.labels, d->tet_labels, d->tet_count * 2);
    assert_memory_equal(ti.weights, d->weights, d->tet_vertex_count * d->influences * 4);
    assert_memory_equal(ti.weight_joints, d->weight_joints, d->tet_vertex_count * d->influences * 2);
    assert_memory_equal(ti.cor, d->cor, d->tet_vertex_count * 12);
    for (size_t t = 0; t < d->tissue_count; t++) {
        pose_tissue_info info;
        assert_int_equal(pose_rig_tissue_info(rig, (int)t, &info), POSE_OK);
        assert_memory_equal(info.rest_positions, d->tissues[t].positions,
                            d->tissues[t].vertex_count * 12);
        assert_memory_equal(info.triangles, d->tissues[t].triangles,
                            d->tissues[t].triangle_count * 12);
    }
    assert_string_equal(pose_rig_metadata(rig), d->metadata);
    pose_rig_free(rig);
    pose_synth_free(r);
}

static void test_rigs_validate(void **state)
{
    (void)state;
    pose_synth_rig *r = bar();
    pose_rig *rig = NULL;
    assert_int_equal(pose_rig_create(pose_synth_desc(r), NULL, &rig), POSE_OK);
    assert_int_equal(pose_rig_joint_count(rig), 4);
    assert_int_equal(pose_rig_find_tissue(rig, "skin"), 0);
    assert_non_null(strstr(pose_rig_metadata(rig), "cor: exact"));
    pose_rig_free(rig);
    pose_synth_free(r);

    pose_synth_bar_options o = {.bones = 2, .cor = POSE_SYNTH_COR_NONE, .influences = 2};
    assert_int_equal(pose_synth_bar(&o, &r), POSE_OK);
    assert_null(pose_synth_desc(r)->cor);
    assert_int_equal(pose_rig_create(pose_synth_desc(r), NULL, &rig), POSE_OK);
    pose_rig_free(rig);
    pose_synth_free(r);

    assert_int_equal(pose_synth_medium(&r), POSE_OK);
    const pose_rig_desc *d = pose_synth_desc(r);
    assert_int_equal(d->joint_count, 22);
    assert_true(d->tet_count > 40000 && d->tet_count < 60000);
    check_embedding(d, 1e-5);
    assert_int_equal(pose_rig_create(d, NULL, &rig), POSE_OK);
    assert_int_equal(pose_rig_find_joint(rig, "arm_l_joint0") >= 0, 1);
    pose_rig_free(rig);
    pose_synth_free(r);

    pose_synth_body_options b = {.target_tets = 20000};
    assert_int_equal(pose_synth_body(&b, &r), POSE_OK);
    assert_int_equal(pose_synth_cor(r), POSE_SYNTH_COR_CLUSTERED);
    assert_non_null(strstr(pose_synth_desc(r)->metadata, "APPROXIMATE"));
    assert_int_equal(pose_rig_create(pose_synth_desc(r), NULL, &rig), POSE_OK);
    pose_rig_free(rig);
    pose_synth_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_invalid_options),
        cmocka_unit_test(test_bar_counts),
        cmocka_unit_test(test_weights_partition_of_unity),
        cmocka_unit_test(test_embedding_reconstructs_vertices),
        cmocka_unit_test(test_skin_is_closed_and_outward),
        cmocka_unit_test(test_cor_single_weight_is_rest_position),
        cmocka_unit_test(test_cor_symmetric_junction_on_axis),
        cmocka_unit_test(test_cor_clustered_close_to_exact),
        cmocka_unit_test(test_cor_exact_matches_formula),
        cmocka_unit_test(test_bar_file_round_trip),
        cmocka_unit_test(test_rigs_validate),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
