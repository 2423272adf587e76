/* SPDX-License-Identifier: Apache-2.0
 *
 * pp_mesh_load and the mesh helpers: bad inputs first (each message must
 * name the file), then a written cube in two formats, then the shared skin.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "mesh_io.h"
#include "pp_assert.h"
#include "pp_shapes.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void test_missing_file(void **state)
{
    (void)state;
    char err[256] = "", path[512];
    pp_mesh m;
    shape_tmp("does_not_exist.obj", path, sizeof path);
    assert_int_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_ERR_IO);
    assert_non_null(strstr(err, "does_not_exist.obj"));
    assert_non_null(strstr(err, "No such file"));
    assert_null(m.positions);
    assert_int_equal(pp_mesh_load("", &m, err, sizeof err), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pp_mesh_load(NULL, &m, err, sizeof err), POSE_ERR_INVALID_ARGUMENT);
}

static void test_empty_and_faceless(void **state)
{
    (void)state;
    char err[256] = "", path[512];
    pp_mesh m;
    shape_tmp("empty.obj", path, sizeof path);
    write_text(path, "");
    assert_int_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_ERR_FORMAT);
    assert_non_null(strstr(err, "empty.obj"));

    shape_tmp("points_only.obj", path, sizeof path);
    write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    err[0] = '\0';
    assert_int_not_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_OK);
    assert_non_null(strstr(err, "points_only.obj"));

    shape_tmp("garbage.stl", path, sizeof path);
    write_text(path, "this is not a mesh at all\n\x01\x02\x03");
    err[0] = '\0';
    assert_int_not_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_OK);
    assert_non_null(strstr(err, "garbage.stl"));

    shape_tmp("degenerate.obj", path, sizeof path);
    write_text(path, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    err[0] = '\0';
    assert_int_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_ERR_FORMAT);
    assert_non_null(strstr(err, "degenerate.obj"));
}

static void test_non_finite(void **state)
{
    (void)state;
    char err[256] = "", path[512];
    pp_mesh m;
    shape_tmp("nan.obj", path, sizeof path);
    write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1e999 0\nf 1 2 3\n");
    assert_int_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_ERR_FORMAT);
    assert_non_null(strstr(err, "nan.obj"));
    assert_non_null(strstr(err, "non-finite"));

    /* in-memory meshes get the same check, naming the mesh */
    float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    shape_box(&m, lo, hi);
    m.positions[4] = NAN;
    assert_int_equal(pp_mesh_validate(&m, "r_femur", err, sizeof err), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "r_femur"));
    m.positions[4] = 0.0f;
    m.triangles[5] = 8;
    assert_int_equal(pp_mesh_validate(&m, "r_femur", err, sizeof err), POSE_ERR_INVALID_ARGUMENT);
    m.triangles[5] = 3;
    assert_int_equal(pp_mesh_validate(&m, "r_femur", err, sizeof err), POSE_OK);
    pp_mesh_free(&m);
    pp_mesh_free(&m); /* double free is harmless */
    pp_mesh_free(NULL);
}

static void test_cube_obj_and_stl(void **state)
{
    (void)state;
    char err[256] = "", path[512];
    float lo[3] = {-0.5f, 0.0f, 1.0f}, hi[3] = {0.5f, 2.0f, 1.5f};
    pp_mesh box, m;
    shape_box(&box, lo, hi);
    shape_tmp("unit_box.obj", path, sizeof path);
    assert_int_equal(shape_write_obj(&box, path), 0);
    assert_int_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_OK);
    assert_string_equal(m.name, "unit_box");
    assert_int_equal(m.vertex_count, 8);
    assert_int_equal(m.triangle_count, 12);
    assert_near(pp_mesh_volume(&m), 1.0 * 2.0 * 0.5, 1e-6);
    pp_mesh_topology topo;
    assert_int_equal(pp_mesh_topology_count(&m, &topo), POSE_OK);
    assert_int_equal(topo.boundary_edges, 0);
    assert_int_equal(topo.nonmanifold_edges, 0);
    assert_int_equal(topo.inconsistent_edges, 0);
    float blo[3], bhi[3];
    pp_mesh_bounds(&m, blo, bhi);
    for (int k = 0; k < 3; k++) {
        assert_near(blo[k], lo[k], 0.0f);
        assert_near(bhi[k], hi[k], 0.0f);
    }
    pp_mesh_free(&m);

    /* ASCII STL repeats every corner per facet: the weld must bring it back to 8. */
    shape_tmp("unit_box.stl", path, sizeof path);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "solid box\n");
    for (size_t t = 0; t < box.triangle_count; t++) {
        fprintf(f, "facet normal 0 0 0\nouter loop\n");
        for (int c = 0; c < 3; c++) {
            const float *p = box.positions + 3 * box.triangles[3 * t + c];
            fprintf(f, "vertex %g %g %g\n", (double)p[0], (double)p[1], (double)p[2]);
        }
        fprintf(f, "endloop\nendfacet\n");
    }
    fprintf(f, "endsolid box\n");
    fclose(f);
    assert_int_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_OK);
    assert_int_equal(m.vertex_count, 8);
    assert_int_equal(m.triangle_count, 12);
    assert_near(pp_mesh_volume(&m), 1.0, 1e-6);

    pp_mesh_free(&m);

    /* ASCII PLY, and two OBJ objects merged into one mesh */
    shape_tmp("unit_box.ply", path, sizeof path);
    f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
               "property float z\nelement face 12\nproperty list uchar int vertex_indices\n"
               "end_header\n");
    for (int i = 0; i < 8; i++)
        fprintf(f, "%g %g %g\n", (double)box.positions[3 * i], (double)box.positions[3 * i + 1],
                (double)box.positions[3 * i + 2]);
    for (size_t t = 0; t < 12; t++)
        fprintf(f, "3 %u %u %u\n", box.triangles[3 * t], box.triangles[3 * t + 1],
                box.triangles[3 * t + 2]);
    fclose(f);
    assert_int_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_OK);
    assert_int_equal(m.vertex_count, 8);
    assert_int_equal(m.triangle_count, 12);
    assert_near(pp_mesh_volume(&m), 1.0, 1e-6);
    pp_mesh_free(&m);
    shape_tmp("two_boxes.obj", path, sizeof path);
    f = fopen(path, "w");
    assert_non_null(f);
    for (int b = 0; b < 2; b++) {
        fprintf(f, "o box%d\n", b);
        for (int i = 0; i < 8; i++)
            fprintf(f, "v %g %g %g\n", (double)box.positions[3 * i] + 3.0 * b,
                    (double)box.positions[3 * i + 1], (double)box.positions[3 * i + 2]);
        for (size_t t = 0; t < 12; t++)
            fprintf(f, "f %u %u %u\n", box.triangles[3 * t] + 1 + 8 * b,
                    box.triangles[3 * t + 1] + 1 + 8 * b, box.triangles[3 * t + 2] + 1 + 8 * b);
    }
    fclose(f);
    assert_int_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_OK);
    assert_int_equal(m.vertex_count, 16);
    assert_int_equal(m.triangle_count, 24);
    assert_near(pp_mesh_volume(&m), 2.0, 1e-6);
    pp_mesh_free(&m);
    assert_int_equal(pp_mesh_load(shape_tmp("unit_box.stl", path, sizeof path), &m, err, sizeof err),
                     POSE_OK);

    /* a hole shows up as boundary edges */
    shape_drop_triangles(&m, 1);
    assert_int_equal(pp_mesh_topology_count(&m, &topo), POSE_OK);
    assert_int_equal(topo.boundary_edges, 3);
    pp_mesh_free(&m);
    pp_mesh_free(&box);
}

static void test_append_and_normals(void **state)
{
    (void)state;
    float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, lo2[3] = {2, 0, 0}, hi2[3] = {3, 1, 1};
    pp_mesh a, b, all = {0};
    shape_box(&a, lo, hi);
    shape_box(&b, lo2, hi2);
    assert_int_equal(pp_mesh_append(&all, &a), POSE_OK);
    assert_int_equal(pp_mesh_append(&all, &b), POSE_OK);
    assert_int_equal(all.vertex_count, 16);
    assert_int_equal(all.triangle_count, 24);
    assert_near(pp_mesh_volume(&all), 2.0, 1e-6);
    float n[48];
    pp_mesh_vertex_normals(&all, n);
    /* corner (0,0,0) of the first box: normal along -(1,1,1)/sqrt3 by symmetry
     * of the area weights (each face contributes two triangles there or one) */
    for (int i = 0; i < 16; i++) {
        double l = sqrt((double)n[3 * i] * n[3 * i] + (double)n[3 * i + 1] * n[3 * i + 1] +
                        (double)n[3 * i + 2] * n[3 * i + 2]);
        assert_near(l, 1.0, 1e-5);
        /* normals point away from the box centre */
        const float *p = all.positions + 3 * i;
        float cx = i < 8 ? 0.5f : 2.5f;
        double d = (p[0] - cx) * n[3 * i] + (p[1] - 0.5) * n[3 * i + 1] + (p[2] - 0.5) * n[3 * i + 2];
        assert_true(d > 0.0);
    }
    pp_mesh copy;
    assert_int_equal(pp_mesh_copy(&copy, &all), POSE_OK);
    assert_memory_equal(copy.positions, all.positions, 48 * sizeof(float));
    pp_mesh_free(&copy);
    pp_mesh_free(&all);
    pp_mesh_free(&a);
    pp_mesh_free(&b);
}

static void test_shared_skin(void **state)
{
    (void)state;
    char err[256] = "", path[512];
    pp_mesh m;
    shape_data("anatomy/skin.obj", path, sizeof path);
    assert_int_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_OK);
    assert_string_equal(m.name, "skin");
    assert_int_equal(m.vertex_count, 13388);
    assert_int_equal(m.triangle_count, 26772);
    /* data/anatomy/README.md: closed 2-manifold, 67.06 L */
    assert_near(pp_mesh_volume(&m), 0.06706, 0.00001);
    pp_mesh_topology topo;
    assert_int_equal(pp_mesh_topology_count(&m, &topo), POSE_OK);
    assert_int_equal(topo.boundary_edges, 0);
    assert_int_equal(topo.nonmanifold_edges, 0);
    float lo[3], hi[3];
    pp_mesh_bounds(&m, lo, hi);
    assert_near(lo[2], 0.0f, 1e-3f);
    assert_near(hi[2], 1.705f, 1e-3f);
    pp_mesh_free(&m);

    /* an open bone: thorax, 630 boundary edges per the README */
    shape_data("anatomy/bones/thorax.obj", path, sizeof path);
    assert_int_equal(pp_mesh_load(path, &m, err, sizeof err), POSE_OK);
    assert_int_equal(m.vertex_count, 10953);
    assert_int_equal(m.triangle_count, 21216);
    assert_int_equal(pp_mesh_topology_count(&m, &topo), POSE_OK);
    assert_int_equal(topo.boundary_edges, 630);
    pp_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_missing_file),      cmocka_unit_test(test_empty_and_faceless),
        cmocka_unit_test(test_non_finite),        cmocka_unit_test(test_cube_obj_and_stl),
        cmocka_unit_test(test_append_and_normals), cmocka_unit_test(test_shared_skin),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
