/* SPDX-License-Identifier: Apache-2.0
 *
 * pp_voxelize / pp_voxel_inside: bad inputs first, then analytic volumes
 * (cube, sphere), a holed sphere, a cylinder with an inner bone (labels,
 * a bone poking out of the skin), and the shared body.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "mesh_io.h"
#include "pp_assert.h"
#include "pp_shapes.h"
#include "voxelize.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void test_bad_inputs(void **state)
{
    (void)state;
    char err[256];
    float lo[3] = {0, 0, 0}, hi[3] = {0.1f, 0.1f, 0.1f};
    pp_mesh box, empty = {0};
    pp_voxels v;
    shape_box(&box, lo, hi);
    snprintf(empty.name, sizeof empty.name, "empty_skin");
    const float bad[] = {0.0f, -0.01f, NAN, INFINITY, 2.0f, 1e-5f};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        err[0] = '\0';
        assert_int_equal(pp_voxelize(&box, NULL, NULL, 0, bad[i], &v, NULL, err, sizeof err),
                         POSE_ERR_INVALID_ARGUMENT);
        assert_non_null(strstr(err, "spacing"));
        assert_null(v.labels);
    }
    /* a grid too large for the limit names the size and asks for more spacing */
    float big[3] = {100, 100, 100};
    pp_mesh huge;
    shape_box(&huge, lo, big);
    assert_int_equal(pp_voxelize(&huge, NULL, NULL, 0, 0.001f, &v, NULL, err, sizeof err),
                     POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "larger spacing"));
    pp_mesh_free(&huge);

    assert_int_equal(pp_voxelize(&empty, NULL, NULL, 0, 0.01f, &v, NULL, err, sizeof err),
                     POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "empty_skin"));

    pp_mesh bone;
    shape_box(&bone, lo, hi);
    snprintf(bone.name, sizeof bone.name, "l_tibia");
    bone.positions[7] = NAN;
    uint16_t lab = 0;
    assert_int_equal(pp_voxelize(&box, &bone, &lab, 1, 0.01f, &v, NULL, err, sizeof err),
                     POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "l_tibia"));
    assert_non_null(strstr(err, "non-finite"));
    pp_mesh_free(&bone);
    assert_int_equal(pp_voxelize(&box, NULL, &lab, 1, 0.01f, &v, NULL, err, sizeof err),
                     POSE_ERR_INVALID_ARGUMENT);

    /* a bone in millimetres next to a skin in metres: wholly outside */
    float blo[3] = {50, 50, 50}, bhi[3] = {60, 60, 60};
    shape_box(&bone, blo, bhi);
    snprintf(bone.name, sizeof bone.name, "r_femur_mm");
    assert_int_equal(pp_voxelize(&box, &bone, &lab, 1, 0.5f, &v, NULL, err, sizeof err),
                     POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(err, "r_femur_mm"));
    assert_non_null(strstr(err, "outside the skin"));
    assert_null(v.labels);
    pp_mesh_free(&bone);
    pp_mesh_free(&box);
}

static size_t count_label(const pp_voxels *v, uint16_t l)
{
    size_t n = 0;
    for (size_t i = 0; i < (size_t)v->nx * v->ny * v->nz; i++)
        n += v->labels[i] == l;
    return n;
}

static void test_cube_volume(void **state)
{
    (void)state;
    char err[256];
    /* a rotated cube: no face aligned with the grid */
    float lo[3] = {-0.05f, -0.04f, 0.2f}, hi[3] = {0.05f, 0.06f, 0.3f};
    pp_mesh box;
    shape_box(&box, lo, hi);
    shape_rotate_z(&box, 0.3f);
    const float h = 0.004f;
    pp_voxels v;
    pp_voxel_report r;
    assert_int_equal(pp_voxelize(&box, NULL, NULL, 0, h, &v, &r, err, sizeof err), POSE_OK);
    /* the voxel volume differs from the solid by at most area * h / 2, in
     * practice far less since errors cancel; take area * h / 4 */
    double exact = 0.001, area = 0.06;
    assert_near(r.body_volume, exact, area * h / 4);
    assert_near(r.skin_volume, r.body_volume, 1e-12);
    assert_int_equal(r.soft_voxels, count_label(&v, PP_VOXEL_SOFT));
    assert_int_equal(r.bone_voxels, 0);
    assert_int_equal(r.skin_boundary_edges, 0);
    assert_int_equal(r.ambiguous_voxels, 0);
    /* the grid has an outside layer on every side */
    for (int z = 0; z < v.nz; z++)
        for (int y = 0; y < v.ny; y++) {
            assert_int_equal(v.labels[(size_t)v.nx * ((size_t)y + (size_t)v.ny * z)], 0);
            assert_int_equal(v.labels[(size_t)(v.nx - 1) + (size_t)v.nx * ((size_t)y + (size_t)v.ny * z)], 0);
        }
    float centre[3] = {0.0f, 0.01f, 0.25f}, out[3] = {0.0f, 0.01f, 0.31f};
    shape_rotate_z(&box, 0.0f);
    assert_int_equal(pp_voxels_sample(&v, centre), PP_VOXEL_SOFT);
    assert_int_equal(pp_voxels_sample(&v, out), PP_VOXEL_OUTSIDE);
    float far[3] = {9, 9, 9};
    assert_int_equal(pp_voxels_sample(&v, far), PP_VOXEL_OUTSIDE);
    pp_voxels_free(&v);
    pp_voxels_free(&v);
    pp_mesh_free(&box);
}

static void test_sphere_volume_and_orientation(void **state)
{
    (void)state;
    char err[256];
    float c[3] = {0.01f, -0.02f, 0.5f};
    pp_mesh s;
    shape_sphere(&s, c, 0.1f, 4);
    double exact = pp_mesh_volume(&s); /* of the polyhedron */
    assert_near(exact, 4.0 / 3.0 * 3.14159265 * 0.001, 0.00005);
    const float h = 0.005f;
    double area = 4 * 3.14159265 * 0.01;
    pp_voxels v;
    pp_voxel_report r;
    assert_int_equal(pp_voxelize(&s, NULL, NULL, 0, h, &v, &r, err, sizeof err), POSE_OK);
    assert_near(r.body_volume, exact, area * h / 4);
    double first = r.body_volume;
    pp_voxels_free(&v);

    /* inward-facing normals: the same solid */
    for (size_t t = 0; t < s.triangle_count; t++) {
        uint32_t a = s.triangles[3 * t + 1];
        s.triangles[3 * t + 1] = s.triangles[3 * t + 2];
        s.triangles[3 * t + 2] = a;
    }
    assert_int_equal(pp_voxelize(&s, NULL, NULL, 0, h, &v, &r, err, sizeof err), POSE_OK);
    assert_near(r.body_volume, first, 1e-12);
    pp_voxels_free(&v);
    pp_mesh_free(&s);
}

static void test_open_mesh_is_solid(void **state)
{
    (void)state;
    char err[256];
    float c[3] = {0, 0, 0};
    pp_mesh s;
    shape_sphere(&s, c, 0.1f, 4);
    double exact = pp_mesh_volume(&s);
    /* cut a hole: the first 12 triangles of an icosphere form a patch */
    shape_drop_triangles(&s, 12);
    pp_mesh_topology topo;
    assert_int_equal(pp_mesh_topology_count(&s, &topo), POSE_OK);
    assert_true(topo.boundary_edges > 0);
    pp_voxels v;
    pp_voxel_report r;
    const float h = 0.005f;
    assert_int_equal(pp_voxelize(&s, NULL, NULL, 0, h, &v, &r, err, sizeof err), POSE_OK);
    assert_int_equal(r.skin_boundary_edges, topo.boundary_edges);
    assert_near(r.body_volume, exact, 4 * 3.14159265 * 0.01 * h / 4);
    /* every voxel of the ball 1 cm inside the surface is filled */
    size_t missing = 0;
    for (int z = 0; z < v.nz; z++)
        for (int y = 0; y < v.ny; y++)
            for (int x = 0; x < v.nx; x++) {
                double p[3] = {v.origin[0] + x * h, v.origin[1] + y * h, v.origin[2] + z * h};
                if (sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) < 0.09)
                    missing += v.labels[(size_t)x + (size_t)v.nx * ((size_t)y + (size_t)v.ny * z)] == 0;
            }
    assert_int_equal(missing, 0);
    pp_voxels_free(&v);

    /* the building block on a grid of its own agrees */
    uint8_t *in = malloc(44 * 44 * 44);
    float o[3] = {-0.1075f, -0.1075f, -0.1075f};
    size_t amb = 0;
    assert_int_equal(pp_voxel_inside(&s, o, 0.005f, 44, 44, 44, in, &amb), POSE_OK);
    size_t n = 0;
    for (size_t i = 0; i < 44 * 44 * 44; i++)
        n += in[i];
    assert_near(n * 0.005 * 0.005 * 0.005, exact, 4 * 3.14159265 * 0.01 * h / 4);
    /* a cap-sized hole: the rays through it are outvoted, not tied */
    assert_true(amb < 10);
    free(in);
    pp_mesh_free(&s);
}


static void test_winding_number_ties(void **state)
{
    (void)state;
    /* A cube without its +x, +y and +z faces: from inside, the rays towards
     * -x, -y, -z see a face and the others escape, so every voxel is a 3:3
     * tie and the winding number decides. Point reflection through the
     * centre swaps open and closed faces, so w(p) + w(-p) = 1: exactly half
     * of a centred, symmetric grid is inside. */
    float lo[3] = {-0.05f, -0.05f, -0.05f}, hi[3] = {0.05f, 0.05f, 0.05f};
    pp_mesh box;
    shape_box(&box, lo, hi);
    static const uint32_t keep[6] = {0, 1, 4, 5, 8, 9}; /* z-, y-, x- faces */
    uint32_t tri[18];
    for (int i = 0; i < 6; i++)
        memcpy(tri + 3 * i, box.triangles + 3 * keep[i], 3 * sizeof *tri);
    memcpy(box.triangles, tri, sizeof tri);
    box.triangle_count = 6;
    uint8_t in[1000];
    float o[3] = {-0.045f, -0.045f, -0.045f};
    size_t amb = 0;
    assert_int_equal(pp_voxel_inside(&box, o, 0.01f, 10, 10, 10, in, &amb), POSE_OK);
    assert_int_equal(amb, 1000);
    size_t n = 0;
    for (int i = 0; i < 1000; i++) {
        n += in[i];
        assert_int_equal(in[i] + in[999 - i], 1); /* index 999 - i is the reflection */
    }
    assert_int_equal(n, 500);
    /* the voxel next to the closed corner is in, the one at the open corner out */
    assert_int_equal(in[0], 1);
    assert_int_equal(in[999], 0);
    pp_mesh_free(&box);
}

static void test_cylinder_with_bone(void **state)
{
    (void)state;
    char err[256];
    pp_mesh skin, bones[2];
    shape_cylinder(&skin, 0, 0, 0.05f, 0.0f, 0.3f, 64);
    /* bone of joint 3 along the axis, poking 2 cm out of the bottom cap;
     * a second, thinner bone of joint 0 off the axis */
    shape_cylinder(&bones[0], 0, 0, 0.015f, -0.02f, 0.25f, 32);
    snprintf(bones[0].name, sizeof bones[0].name, "shaft");
    shape_cylinder(&bones[1], 0.03f, 0, 0.006f, 0.05f, 0.2f, 16);
    snprintf(bones[1].name, sizeof bones[1].name, "pin");
    uint16_t lab[2] = {3, 0};
    const float h = 0.004f;
    pp_voxels v;
    pp_voxel_report r;
    assert_int_equal(pp_voxelize(&skin, bones, lab, 2, h, &v, &r, err, sizeof err), POSE_OK);
    float axis[3] = {0, 0, 0.15f}, soft[3] = {-0.035f, 0, 0.15f}, pin[3] = {0.03f, 0, 0.1f},
          out[3] = {0.06f, 0, 0.15f}, tip[3] = {0, 0, -0.012f}, above[3] = {0, 0, 0.27f};
    assert_int_equal(pp_voxels_sample(&v, axis), PP_VOXEL_BONE0 + 3);
    assert_int_equal(pp_voxels_sample(&v, soft), PP_VOXEL_SOFT);
    assert_int_equal(pp_voxels_sample(&v, pin), PP_VOXEL_BONE0 + 0);
    assert_int_equal(pp_voxels_sample(&v, out), PP_VOXEL_OUTSIDE);
    assert_int_equal(pp_voxels_sample(&v, above), PP_VOXEL_SOFT);
    /* the part outside the skin is bone, promoted into the body */
    assert_int_equal(pp_voxels_sample(&v, tip), PP_VOXEL_BONE0 + 3);
    double pi = 3.14159265;
    double shaft_out = pi * 0.015 * 0.015 * 0.02;
    assert_near(r.bone_voxels_outside_skin * (double)h * h * h, shaft_out, 0.3 * shaft_out);
    size_t shaft = count_label(&v, PP_VOXEL_BONE0 + 3), pinv = count_label(&v, PP_VOXEL_BONE0);
    double shaft_vol = pi * 0.015 * 0.015 * 0.27, pin_vol = pi * 0.006 * 0.006 * 0.15;
    assert_near(shaft * (double)h * h * h, shaft_vol, 0.15 * shaft_vol);
    assert_near(pinv * (double)h * h * h, pin_vol, 0.35 * pin_vol);
    assert_int_equal(r.bone_voxels, shaft + pinv);
    assert_int_equal(r.overlap_voxels, 0);
    assert_int_equal(r.empty_joints, 0);
    assert_int_equal(r.open_bone_meshes, 0);
    pp_voxels_free(&v);

    /* a bone thinner than a voxel is kept by its vertices */
    pp_mesh_free(&bones[1]);
    shape_cylinder(&bones[1], 0.03f, 0, 0.0005f, 0.05f, 0.2f, 8);
    assert_int_equal(pp_voxelize(&skin, bones, lab, 2, h, &v, &r, err, sizeof err), POSE_OK);
    assert_int_equal(r.thin_bones, 1);
    assert_true(count_label(&v, PP_VOXEL_BONE0) > 0);
    assert_int_equal(r.empty_joints, 0);
    pp_voxels_free(&v);
    pp_mesh_free(&bones[0]);
    pp_mesh_free(&bones[1]);
    pp_mesh_free(&skin);
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void test_shared_body(void **state)
{
    (void)state;
    char err[512], path[512];
    pp_mesh skin;
    assert_int_equal(pp_mesh_load(shape_data("anatomy/skin.obj", path, sizeof path), &skin, err,
                                  sizeof err),
                     POSE_OK);
    DIR *d = opendir(shape_data("anatomy/bones", path, sizeof path));
    assert_non_null(d);
    char *names[128];
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d)) && n < 128)
        if (strstr(e->d_name, ".obj"))
            names[n++] = strdup(e->d_name);
    closedir(d);
    assert_int_equal(n, 102);
    qsort(names, n, sizeof *names, cmp_str);
    pp_mesh *bones = calloc(n, sizeof *bones);
    uint16_t *lab = calloc(n, sizeof *lab);
    for (size_t i = 0; i < n; i++) {
        char rel[300];
        snprintf(rel, sizeof rel, "anatomy/bones/%s", names[i]);
        assert_int_equal(pp_mesh_load(shape_data(rel, path, sizeof path), &bones[i], err, sizeof err),
                         POSE_OK);
        lab[i] = (uint16_t)i;
        free(names[i]);
    }
    pp_voxels v;
    pp_voxel_report r;
    assert_int_equal(pp_voxelize(&skin, bones, lab, n, 0.008f, &v, &r, err, sizeof err), POSE_OK);
    assert_true(r.body_volume > 0.06 && r.body_volume < 0.09);
    /* the skin is closed: its voxel volume is its enclosed volume */
    assert_near(r.skin_volume, 0.06706, 0.0005);
    assert_int_equal(r.skin_boundary_edges, 0);
    assert_int_equal(r.open_bone_meshes, 26);
    assert_true(r.bone_voxels_outside_skin > 0); /* skull, scapulae, ... */
    assert_true(r.ambiguous_voxels > 0);         /* open bones: winding-number fallback used */
    assert_int_equal(r.empty_joints, 0);
    /* bones are ~8-12 % of body volume */
    double frac = (double)r.bone_voxels / (double)r.body_voxels;
    assert_true(frac > 0.05 && frac < 0.2);
    /* the femur shaft: 40 cm above the sole, 9 cm right of the midline */
    for (size_t i = 0; i < n; i++) {
        if (strcmp(bones[i].name, "r_femur") != 0)
            continue;
        float lo[3], hi[3];
        pp_mesh_bounds(&bones[i], lo, hi);
        assert_true(hi[2] > 0.7f && lo[2] < 0.5f);
    }
    pp_voxels_free(&v);
    for (size_t i = 0; i < n; i++)
        pp_mesh_free(&bones[i]);
    free(bones);
    free(lab);
    pp_mesh_free(&skin);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_inputs),
        cmocka_unit_test(test_cube_volume),
        cmocka_unit_test(test_sphere_volume_and_orientation),
        cmocka_unit_test(test_open_mesh_is_solid),
        cmocka_unit_test(test_winding_number_ties),
        cmocka_unit_test(test_cylinder_with_bone),
        cmocka_unit_test(test_shared_body),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
