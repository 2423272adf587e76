/* SPDX-License-Identifier: Apache-2.0
 *
 * pp_tetrahedralize: bad inputs first, then a box (exact volume, positive
 * tets, labels equal to the voxel labels, Kuhn quality), a cylinder with a
 * bone, the size budget, and the TetGen backend on the same cases when it
 * is built in.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "mesh_io.h"
#include "pp_assert.h"
#include "pp_shapes.h"
#include "embed_hash.h"
#include "tetmesh.h"
#include "voxelize.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void test_bad_inputs(void **state)
{
    (void)state;
    char err[256] = "";
    pp_tetmesh t;
    pp_voxels empty = {0};
    assert_int_equal(pp_tetrahedralize(&empty, NULL, NULL, &t, NULL, err, sizeof err),
                     POSE_ERR_INVALID_ARGUMENT);
    uint16_t zeros[27] = {0};
    pp_voxels none = {3, 3, 3, {0, 0, 0}, 0.01f, zeros};
    assert_int_equal(pp_tetrahedralize(&none, NULL, NULL, &t, NULL, err, sizeof err),
                     POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(err, "no body voxel"));
    assert_null(t.tets);
    pp_tet_backend b;
    assert_int_equal(pp_tet_backend_parse("lattice", &b), 0);
    assert_int_equal(b, PP_TET_LATTICE);
    assert_int_equal(pp_tet_backend_parse("tetgen", &b), 0);
    assert_int_equal(b, PP_TET_TETGEN);
    assert_int_equal(pp_tet_backend_parse("delaunay", &b), -1);
    assert_string_equal(pp_tet_backend_name(PP_TET_DEFAULT), "lattice");
    assert_int_equal(pp_tet_backend_available(PP_TET_LATTICE), 1);
#ifndef POSE_HAVE_TETGEN
    uint16_t one[27] = {0};
    one[13] = 1;
    pp_voxels single = {3, 3, 3, {0, 0, 0}, 0.01f, one};
    pp_tet_options o = {.backend = PP_TET_TETGEN};
    assert_int_equal(pp_tetrahedralize(&single, NULL, &o, &t, NULL, err, sizeof err),
                     POSE_ERR_UNSUPPORTED);
    assert_non_null(strstr(err, "POSE_WITH_TETGEN"));
#endif
}

/* Every tet positive, labels in range, summed volume returned. */
static double check_mesh(const pp_tetmesh *t, uint16_t max_label)
{
    double vol = 0.0;
    for (size_t i = 0; i < t->tet_count; i++) {
        double v = pp_tet_volume(t, i);
        assert_true(v > 0.0);
        vol += v;
        assert_true(t->labels[i] <= max_label);
        for (int k = 0; k < 4; k++)
            assert_true(t->tets[4 * i + k] < t->vertex_count);
    }
    return vol;
}

static void centroid(const pp_tetmesh *t, size_t i, float c[3])
{
    for (int k = 0; k < 3; k++) {
        c[k] = 0.0f;
        for (int q = 0; q < 4; q++)
            c[k] += 0.25f * t->positions[3 * (size_t)t->tets[4 * i + q] + k];
    }
}

/* Vertices of `skin` outside the mesh (more than 1 um from every tet): the
 * snapped lattice encloses the skin (tet_cells.h, pp_cells_dilate). */
static size_t skin_outside(const pp_tetmesh *t, const pp_mesh *skin)
{
    pp_tet_hash *h = NULL;
    char err[256];
    assert_int_equal(pp_tet_hash_build(t, 0.0, &h, err, sizeof err), 0);
    uint32_t *tet = malloc(skin->vertex_count * sizeof *tet);
    float *bary = malloc(4 * skin->vertex_count * sizeof *bary);
    assert_non_null(tet);
    assert_non_null(bary);
    pp_embed_report r = {0};
    assert_int_equal(pp_embed_points(h, skin->positions, skin->vertex_count, -1, 0.0, 1, tet, bary, &r),
                     0);
    free(tet);
    free(bary);
    pp_tet_hash_free(h);
    return r.outside;
}

static void box_case(pp_tet_backend backend)
{
    char err[256] = "";
    float lo[3] = {0.013f, -0.021f, 0.1f}, hi[3] = {0.113f, 0.039f, 0.18f};
    pp_mesh box;
    shape_box(&box, lo, hi);
    pp_voxels v;
    assert_int_equal(pp_voxelize(&box, NULL, NULL, 0, 0.01f, &v, NULL, err, sizeof err), POSE_OK);
    pp_tet_options o = {.backend = backend};
    pp_tetmesh t;
    pp_tet_quality q;
    assert_int_equal(pp_tetrahedralize(&v, &box, &o, &t, &q, err, sizeof err), POSE_OK);
    double exact = 0.1 * 0.06 * 0.08;
    double vol = check_mesh(&t, 0);
    /* The body grows by one cell and snaps back inward, no further than
     * 0.15 cells outside the box and only as far as the tets allow (a cell
     * is 1/6 to 1/10 of this box): the box is enclosed, with at most about
     * one cell layer to spare. TetGen grades its tets down towards the
     * boundary, so the quality guard refuses more of its moves. */
    assert_int_equal(skin_outside(&t, &box), 0);
    assert_true(vol >= exact);
    assert_true(vol <= (backend == PP_TET_LATTICE ? 1.3 : 1.45) * exact);
    assert_near(q.total_volume, vol, 1e-9);
    assert_int_equal(q.inverted_count, 0);
    assert_int_equal(q.tet_count, t.tet_count);
    assert_true(q.min_volume > 0.0);
    assert_true(q.min_dihedral_deg > 5.0);
    pp_tetmesh_free(&t);
    pp_tetmesh_free(&t);
    pp_voxels_free(&v);
    pp_mesh_free(&box);
}

static void test_box_lattice(void **state)
{
    (void)state;
    box_case(PP_TET_LATTICE);
}

static void test_lattice_follows_voxels(void **state)
{
    (void)state;
    char err[256] = "";
    pp_mesh skin, bone;
    shape_cylinder(&skin, 0, 0, 0.05f, 0.0f, 0.2f, 48);
    shape_cylinder(&bone, 0, 0, 0.015f, 0.03f, 0.17f, 24);
    uint16_t lab = 4;
    pp_voxels v;
    const float h = 0.005f;
    assert_int_equal(pp_voxelize(&skin, &bone, &lab, 1, h, &v, NULL, err, sizeof err), POSE_OK);
    size_t body = 0;
    for (size_t i = 0; i < (size_t)v.nx * v.ny * v.nz; i++)
        body += v.labels[i] != 0;

    /* uniform, unsnapped: one cell per voxel, six congruent Kuhn tets each */
    pp_tet_options o = {.no_snap = 1, .grading = -1};
    pp_tetmesh t;
    pp_tet_quality q;
    assert_int_equal(pp_tetrahedralize(&v, &skin, &o, &t, &q, err, sizeof err), POSE_OK);
    assert_int_equal(t.tet_count, 6 * body);
    double vol = check_mesh(&t, 5);
    assert_near(vol, body * (double)h * h * h, 1e-9);
    assert_near(q.min_dihedral_deg, 45.0, 1e-3);
    assert_near(q.max_dihedral_deg, 90.0, 1e-3);
    assert_near(q.max_radius_edge, sqrt(3.0) / 2.0, 1e-4);
    assert_near(q.min_volume, h * h * h / 6.0, 1e-12);
    size_t bone_tets = 0;
    for (size_t i = 0; i < t.tet_count; i++) {
        float c[3];
        centroid(&t, i, c);
        uint16_t l = pp_voxels_sample(&v, c);
        assert_int_equal(t.labels[i], l - 1); /* voxel 1 -> 0, voxel 2 + j -> j + 1 */
        bone_tets += t.labels[i] == 5;
    }
    assert_true(bone_tets > 0);
    pp_tetmesh_free(&t);

    /* snapped: encloses the cylinder (polygon prism) with less than one
     * 5 mm layer to spare (+20 %), bone tets unchanged */
    o.no_snap = 0;
    assert_int_equal(pp_tetrahedralize(&v, &skin, &o, &t, &q, err, sizeof err), POSE_OK);
    double prism = pp_mesh_volume(&skin);
    vol = check_mesh(&t, 5);
    assert_int_equal(skin_outside(&t, &skin), 0);
    assert_true(vol >= prism && vol <= 1.2 * prism);
    size_t bone_after = 0;
    for (size_t i = 0; i < t.tet_count; i++)
        bone_after += t.labels[i] == 5;
    assert_int_equal(bone_after, bone_tets);
    assert_true(q.min_dihedral_deg > 5.0);
    pp_tetmesh_free(&t);
    pp_voxels_free(&v);
    pp_mesh_free(&bone);
    pp_mesh_free(&skin);
}

static void test_lattice_budget(void **state)
{
    (void)state;
    char err[256] = "";
    float c[3] = {0, 0, 0};
    pp_mesh s;
    shape_sphere(&s, c, 0.1f, 3);
    pp_voxels v;
    assert_int_equal(pp_voxelize(&s, NULL, NULL, 0, 0.004f, &v, NULL, err, sizeof err), POSE_OK);
    const size_t targets[] = {2000, 20000};
    for (int i = 0; i < 2; i++) {
        pp_tet_options o = {.target_vertices = targets[i]};
        pp_tetmesh t;
        assert_int_equal(pp_tetrahedralize(&v, &s, &o, &t, NULL, err, sizeof err), POSE_OK);
        assert_near((double)t.vertex_count, (double)targets[i], 0.15 * targets[i]);
        double vol = check_mesh(&t, 0), sv = pp_mesh_volume(&s);
        /* enclosed; the 2000-vertex mesh has 15 mm cells on a 100 mm sphere */
        assert_int_equal(skin_outside(&t, &s), 0);
        assert_true(vol >= sv && vol <= (i == 0 ? 1.6 : 1.25) * sv);
        pp_tetmesh_free(&t);
    }
    pp_voxels_free(&v);
    pp_mesh_free(&s);
}


typedef struct tri_key {
    uint32_t v[3];
} tri_key;

static int cmp_tri(const void *a, const void *b)
{
    return memcmp(a, b, sizeof(tri_key));
}

/* Faces used by one tet (boundary); fails on a face used by three or more
 * (a non-conforming mesh shows up as unmatched faces inside, counted too). */
static size_t boundary_faces(const pp_tetmesh *t)
{
    size_t n = 4 * t->tet_count, b = 0;
    tri_key *f = malloc(n * sizeof *f);
    assert_non_null(f);
    for (size_t i = 0; i < t->tet_count; i++)
        for (int k = 0; k < 4; k++) {
            int j = 0;
            for (int q = 0; q < 4; q++)
                if (q != k)
                    f[4 * i + k].v[j++] = t->tets[4 * i + q];
            for (int a = 0; a < 2; a++)
                for (int c = 0; c < 2 - a; c++)
                    if (f[4 * i + k].v[c] > f[4 * i + k].v[c + 1]) {
                        uint32_t x = f[4 * i + k].v[c];
                        f[4 * i + k].v[c] = f[4 * i + k].v[c + 1];
                        f[4 * i + k].v[c + 1] = x;
                    }
        }
    qsort(f, n, sizeof *f, cmp_tri);
    for (size_t i = 0; i < n;) {
        size_t j = i;
        while (j < n && memcmp(&f[i], &f[j], sizeof *f) == 0)
            j++;
        assert_true(j - i <= 2);
        b += j - i == 1;
        i = j;
    }
    free(f);
    return b;
}

static void test_graded_octree(void **state)
{
    (void)state;
    char err[256] = "";
    pp_mesh skin, bone;
    float c[3] = {0, 0, 0};
    shape_sphere(&skin, c, 0.1f, 3);
    shape_cylinder(&bone, 0, 0, 0.02f, -0.06f, 0.06f, 24);
    uint16_t lab = 2;
    pp_voxels v;
    const float h = 0.004f;
    assert_int_equal(pp_voxelize(&skin, &bone, &lab, 1, h, &v, NULL, err, sizeof err), POSE_OK);
    size_t body = 0;
    for (size_t i = 0; i < (size_t)v.nx * v.ny * v.nz; i++)
        body += v.labels[i] != 0;
    pp_tet_options uo = {.no_snap = 1, .grading = -1}, go = {.no_snap = 1}; /* default grading */
    pp_tetmesh u, g;
    pp_tet_quality uq, gq;
    assert_int_equal(pp_tetrahedralize(&v, &skin, &uo, &u, &uq, err, sizeof err), POSE_OK);
    assert_int_equal(pp_tetrahedralize(&v, &skin, &go, &g, &gq, err, sizeof err), POSE_OK);
    /* same body, same staircase boundary (one-cell leaves there), fewer vertices */
    double vol = check_mesh(&g, 3);
    assert_near(vol, body * (double)h * h * h, 1e-9);
    assert_int_equal(boundary_faces(&g), boundary_faces(&u));
    assert_true(g.vertex_count < 0.8 * u.vertex_count);
    /* transition tets: centre fans keep angles in 35-126 degrees */
    assert_true(gq.min_dihedral_deg > 35.0);
    assert_true(gq.max_dihedral_deg < 126.0);
    assert_true(gq.max_radius_edge < 1.2);
    assert_int_equal(gq.labels_lost, 0);
    double bone_u = 0.0, bone_g = 0.0;
    for (size_t i = 0; i < g.tet_count; i++) {
        float cc[3];
        centroid(&g, i, cc);
        assert_int_equal(g.labels[i], pp_voxels_sample(&v, cc) - 1);
        if (g.labels[i] == 3)
            bone_g += pp_tet_volume(&g, i);
    }
    for (size_t i = 0; i < u.tet_count; i++)
        if (u.labels[i] == 3)
            bone_u += pp_tet_volume(&u, i);
    assert_near(bone_g, bone_u, 1e-9);
    pp_tetmesh_free(&g);
    pp_tetmesh_free(&u);

    /* snapped and on a budget */
    go.no_snap = 0;
    go.target_vertices = 6000;
    assert_int_equal(pp_tetrahedralize(&v, &skin, &go, &g, &gq, err, sizeof err), POSE_OK);
    assert_near((double)g.vertex_count, 6000.0, 0.1 * 6000);
    vol = check_mesh(&g, 3);
    assert_int_equal(skin_outside(&g, &skin), 0);
    assert_true(vol >= pp_mesh_volume(&skin) && vol <= 1.4 * pp_mesh_volume(&skin));
    pp_tetmesh_free(&g);
    pp_voxels_free(&v);
    pp_mesh_free(&bone);
    pp_mesh_free(&skin);
}

#ifdef POSE_HAVE_TETGEN
static void test_box_tetgen(void **state)
{
    (void)state;
    box_case(PP_TET_TETGEN);
}

static void test_tetgen_labels(void **state)
{
    (void)state;
    char err[256] = "";
    pp_mesh skin, bone;
    shape_cylinder(&skin, 0, 0, 0.05f, 0.0f, 0.2f, 48);
    shape_cylinder(&bone, 0, 0, 0.015f, 0.03f, 0.17f, 24);
    uint16_t lab = 4;
    pp_voxels v;
    const float h = 0.008f;
    assert_int_equal(pp_voxelize(&skin, &bone, &lab, 1, h, &v, NULL, err, sizeof err), POSE_OK);
    size_t body = 0, bone_vox = 0;
    for (size_t i = 0; i < (size_t)v.nx * v.ny * v.nz; i++) {
        body += v.labels[i] != 0;
        bone_vox += v.labels[i] == PP_VOXEL_BONE0 + 4;
    }
    pp_tet_options o = {.backend = PP_TET_TETGEN, .no_snap = 1};
    pp_tetmesh t;
    pp_tet_quality q;
    assert_int_equal(pp_tetrahedralize(&v, &skin, &o, &t, &q, err, sizeof err), POSE_OK);
    /* unsnapped, the mesh fills the voxels exactly and conforms to the bone */
    double vol = check_mesh(&t, 5), bone_vol = 0.0;
    assert_near(vol, body * (double)h * h * h, 1e-6 * vol);
    for (size_t i = 0; i < t.tet_count; i++) {
        float c[3];
        centroid(&t, i, c);
        assert_int_equal(t.labels[i], pp_voxels_sample(&v, c) - 1);
        if (t.labels[i] == 5)
            bone_vol += pp_tet_volume(&t, i);
    }
    assert_near(bone_vol, bone_vox * (double)h * h * h, 1e-6 * bone_vol);
    assert_true(q.max_radius_edge < 2.5); /* -q 1.414 holds away from tight corners */
    pp_tetmesh_free(&t);
    pp_voxels_free(&v);
    pp_mesh_free(&bone);
    pp_mesh_free(&skin);
}
#endif

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_inputs),
        cmocka_unit_test(test_box_lattice),
        cmocka_unit_test(test_lattice_follows_voxels),
        cmocka_unit_test(test_lattice_budget),
        cmocka_unit_test(test_graded_octree),
#ifdef POSE_HAVE_TETGEN
        cmocka_unit_test(test_box_tetgen),
        cmocka_unit_test(test_tetgen_labels),
#endif
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
