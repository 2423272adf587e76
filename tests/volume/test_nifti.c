/* SPDX-License-Identifier: Apache-2.0
 * NIfTI input/output of the tools: the bundled CT and segmentation read
 * with their real values; round trips through NIfTI-1/-2, .nii/.nii.gz and
 * several datatypes; damaged headers refused with the file and field named. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vol_nifti.h"

static char tmp_path[1024];

static const char *tmp(const char *name)
{
    const char *d = getenv("POSE_TEST_TMP");
    snprintf(tmp_path, sizeof tmp_path, "%s/%s", d ? d : "/tmp", name);
    return tmp_path;
}

static void data_path(char *buf, size_t n, const char *name)
{
    const char *d = getenv("POSE_DATA_DIR");
    snprintf(buf, n, "%s/volume/%s", d ? d : "data", name);
}

static void test_reads_the_bundled_ct(void **state)
{
    (void)state;
    char p[1024], err[512];
    data_path(p, sizeof p, "example_ct.nii.gz");
    pv_image ct;
    assert_int_equal(pv_nifti_read(p, &ct, err, sizeof err), 0);
    assert_int_equal(ct.nx, 122);
    assert_int_equal(ct.ny, 101);
    assert_int_equal(ct.nz, 112);
    assert_int_equal(ct.datatype, 8); /* int32 */
    assert_int_equal(ct.nifti_version, 1);
    for (int k = 0; k < 3; k++)
        assert_true(fabs(ct.spacing[k] - 3.0) < 1e-3);
    /* The affine's columns have 3 mm length. */
    for (int c = 0; c < 3; c++) {
        double l = sqrt(ct.affine[0][c] * ct.affine[0][c] + ct.affine[1][c] * ct.affine[1][c] +
                        ct.affine[2][c] * ct.affine[2][c]);
        assert_true(fabs(l - 3.0) < 1e-3);
    }
    /* Air below -900 HU in the corner, bone above 300 somewhere, all integers. */
    size_t n = pv_image_voxels(&ct), bone = 0;
    float lo = ct.data[0], hi = ct.data[0];
    for (size_t i = 0; i < n; i++) {
        lo = fminf(lo, ct.data[i]);
        hi = fmaxf(hi, ct.data[i]);
        bone += ct.data[i] > 300.0f;
        assert_true(ct.data[i] == floorf(ct.data[i]));
    }
    assert_true(ct.data[0] < -900.0f);
    assert_true(lo >= -1300.0f && lo <= -900.0f);
    assert_true(hi > 1000.0f);
    assert_true(bone > 10000);
    printf("CT: HU %.0f .. %.0f, %zu voxels > 300 HU, affine source %d\n", lo, hi, bone,
           ct.affine_source);

    data_path(p, sizeof p, "example_seg.nii.gz");
    pv_image seg;
    assert_int_equal(pv_nifti_read(p, &seg, err, sizeof err), 0);
    assert_int_equal(seg.datatype, 64); /* float64 labels */
    assert_int_equal(seg.nx, ct.nx);
    assert_int_equal(seg.ny, ct.ny);
    assert_int_equal(seg.nz, ct.nz);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            assert_true(fabs(seg.affine[r][c] - ct.affine[r][c]) < 1e-3);
    size_t femur_l = 0, hip_l = 0, bad = 0;
    double hu_femur = 0;
    for (size_t i = 0; i < n; i++) {
        float v = seg.data[i];
        bad += !(v >= 0 && v <= 104 && v == floorf(v));
        if (v == 88.0f)
            femur_l++, hu_femur += ct.data[i];
        hip_l += v == 90.0f;
    }
    assert_int_equal(bad, 0);
    assert_true(femur_l > 500);
    assert_true(hip_l > 1000);
    hu_femur /= (double)femur_l;
    printf("seg: femur_left %zu voxels (mean %.0f HU), hip_left %zu voxels\n", femur_l,
           hu_femur, hip_l);
    assert_true(hu_femur > 150.0 && hu_femur < 1000.0); /* bone */
    pv_image_free(&ct);
    pv_image_free(&seg);
}

static pv_image small_image(void)
{
    pv_image im;
    memset(&im, 0, sizeof im);
    im.nx = 5, im.ny = 4, im.nz = 3;
    im.data = malloc(60 * sizeof *im.data);
    for (int i = 0; i < 60; i++)
        im.data[i] = (float)(i * 7 % 23) - 5.0f;
    /* Oblique, anisotropic: a rotation about z by 30 degrees, spacing 1, 2, 3. */
    double c = sqrt(3.0) / 2.0, s = 0.5;
    double a[3][4] = {{c * 1, -s * 2, 0, -10.5}, {s * 1, c * 2, 0, 20.25}, {0, 0, 3, 7}};
    memcpy(im.affine, a, sizeof a);
    im.spacing[0] = 1, im.spacing[1] = 2, im.spacing[2] = 3;
    im.sform_code = 2, im.qform_code = 1;
    im.xyz_units = 2; /* mm */
    im.intent_code = 1002; /* NIFTI_INTENT_LABEL */
    snprintf(im.intent_name, sizeof im.intent_name, "labels");
    snprintf(im.descrip, sizeof im.descrip, "pose test");
    return im;
}

static void round_trip(const char *name, int version, int datatype)
{
    pv_image im = small_image(), back;
    im.nifti_version = version;
    char err[512];
    const char *p = tmp(name);
    int rc = pv_nifti_write(p, &im, datatype, err, sizeof err);
    if (rc != 0)
        fail_msg("%s", err);
    rc = pv_nifti_read(p, &back, err, sizeof err);
    if (rc != 0)
        fail_msg("%s", err);
    assert_int_equal(back.nifti_version, version);
    assert_int_equal(back.datatype, datatype);
    assert_int_equal(back.nx, 5);
    assert_int_equal(back.ny, 4);
    assert_int_equal(back.nz, 3);
    float lo = datatype == 2 || datatype == 512 ? 0.0f : -1e9f; /* unsigned types clamp negatives */
    for (int i = 0; i < 60; i++)
        if (back.data[i] != fmaxf(im.data[i], lo))
            fail_msg("%s voxel %d: %g != %g", name, i, (double)back.data[i], (double)im.data[i]);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            assert_true(fabs(back.affine[r][c] - im.affine[r][c]) < 1e-5);
    assert_int_equal(back.affine_source, 2);
    assert_int_equal(back.sform_code, 2);
    assert_int_equal(back.qform_code, 1);
    assert_int_equal(back.xyz_units, 2);
    assert_int_equal(back.intent_code, 1002);
    assert_string_equal(back.intent_name, "labels");
    assert_string_equal(back.descrip, "pose test");
    /* The qform alone gives the same affine (sform/qform agree). */
    pv_image_free(&im);
    pv_image_free(&back);
}

static void test_round_trips(void **state)
{
    (void)state;
    round_trip("a.nii", 1, 16);
    round_trip("b.nii.gz", 1, 4);
    round_trip("c.nii", 2, 64);
    round_trip("d.nii.gz", 2, 8);
    round_trip("e.nii", 1, 2);
    round_trip("f.nii", 1, 256);
    round_trip("g.nii", 2, 1024);
    round_trip("h.nii", 1, 512);
}

/* A damaged copy of a small valid NIfTI-1 (or -2) file. */
static unsigned char *load(const char *p, size_t *n)
{
    FILE *f = fopen(p, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    *n = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc(*n);
    assert_int_equal(fread(b, 1, *n, f), *n);
    fclose(f);
    return b;
}

static void save(const char *p, const unsigned char *b, size_t n)
{
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, n, f), n);
    fclose(f);
}

static void put16(unsigned char *b, size_t off, int v) { int16_t x = (int16_t)v; memcpy(b + off, &x, 2); }
static void put32(unsigned char *b, size_t off, int v) { int32_t x = v; memcpy(b + off, &x, 4); }
static void putf(unsigned char *b, size_t off, float v) { memcpy(b + off, &v, 4); }
static void put64(unsigned char *b, size_t off, int64_t v) { memcpy(b + off, &v, 8); }

typedef struct damage {
    const char *field;   /* expected in the message */
    void (*apply)(unsigned char *b, size_t *n);
} damage;

static void d_sizeof(unsigned char *b, size_t *n) { (void)n; put32(b, 0, 349); }
static void d_magic(unsigned char *b, size_t *n) { (void)n; memcpy(b + 344, "abc", 4); }
static void d_dim0(unsigned char *b, size_t *n) { (void)n; put16(b, 40, 0); }
static void d_dim0_big(unsigned char *b, size_t *n) { (void)n; put16(b, 40, 9); }
static void d_dim1(unsigned char *b, size_t *n) { (void)n; put16(b, 42, -3); }
static void d_dim4(unsigned char *b, size_t *n) { (void)n; put16(b, 40, 4), put16(b, 48, 5); }
static void d_overflow(unsigned char *b, size_t *n)
{
    (void)n;
    put16(b, 42, 32767), put16(b, 44, 32767), put16(b, 46, 32767);
}
static void d_datatype(unsigned char *b, size_t *n) { (void)n; put16(b, 70, 999); }
static void d_complex(unsigned char *b, size_t *n) { (void)n; put16(b, 70, 32), put16(b, 72, 64); }
static void d_bitpix(unsigned char *b, size_t *n) { (void)n; put16(b, 72, 8); }
static void d_pixdim(unsigned char *b, size_t *n) { (void)n; putf(b, 80, 0.0f); }
static void d_pixdim_nan(unsigned char *b, size_t *n) { (void)n; putf(b, 84, NAN); }
static void d_vox_small(unsigned char *b, size_t *n) { (void)n; putf(b, 108, 100.0f); }
static void d_vox_neg(unsigned char *b, size_t *n) { (void)n; putf(b, 108, -352.0f); }
static void d_vox_far(unsigned char *b, size_t *n) { (void)n; putf(b, 108, 1e9f); }
static void d_truncated(unsigned char *b, size_t *n) { (void)b; *n -= 7; }
static void d_short_header(unsigned char *b, size_t *n) { (void)b; *n = 200; }
static void d_slope(unsigned char *b, size_t *n) { (void)n; putf(b, 112, INFINITY); }
static void d_srow(unsigned char *b, size_t *n) { (void)n; putf(b, 300, NAN); }
static void d_sform_code(unsigned char *b, size_t *n) { (void)n; put16(b, 254, 77); }

static void test_bad_headers_named(void **state)
{
    (void)state;
    pv_image im = small_image();
    im.nifti_version = 1;
    char err[512];
    char good[1024];
    snprintf(good, sizeof good, "%s", tmp("good.nii"));
    assert_int_equal(pv_nifti_write(good, &im, 16, err, sizeof err), 0);
    pv_image_free(&im);
    size_t n0;
    unsigned char *orig = load(good, &n0);
    const damage cases[] = {
        {"'sizeof_hdr'", d_sizeof},   {"'magic'", d_magic},         {"'dim[0]'", d_dim0},
        {"'dim[0]'", d_dim0_big},     {"'dim[1]'", d_dim1},         {"'dim[4]'", d_dim4},
        {"'dim[3]'", d_overflow},     {"'datatype'", d_datatype},   {"'datatype'", d_complex},
        {"'bitpix'", d_bitpix},       {"'pixdim[1]'", d_pixdim},    {"'pixdim[2]'", d_pixdim_nan},
        {"'vox_offset'", d_vox_small}, {"'vox_offset'", d_vox_neg}, {"'vox_offset'", d_vox_far},
        {"'vox_offset'", d_truncated}, {"'sizeof_hdr'", d_short_header},
        {"'scl_slope'", d_slope},     {"'srow_y'", d_srow},         {"'sform_code'", d_sform_code},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        unsigned char *b = malloc(n0);
        memcpy(b, orig, n0);
        size_t n = n0;
        cases[i].apply(b, &n);
        char name[64];
        snprintf(name, sizeof name, "bad%zu.nii", i);
        char p[1024];
        snprintf(p, sizeof p, "%s", tmp(name));
        save(p, b, n);
        pv_image out;
        int rc = pv_nifti_read(p, &out, err, sizeof err);
        printf("%-18s %s\n", cases[i].field, err);
        assert_int_equal(rc, -1);
        assert_null(out.data);
        assert_non_null(strstr(err, p));
        assert_non_null(strstr(err, cases[i].field));
        free(b);
    }
    free(orig);
}

/* A NIfTI-2 header damaged past the NIfTI-1 range: 64-bit dims overflow. */
static void test_bad_nifti2_dims(void **state)
{
    (void)state;
    pv_image im = small_image();
    im.nifti_version = 2;
    char err[512], p[1024];
    snprintf(p, sizeof p, "%s", tmp("good2.nii"));
    assert_int_equal(pv_nifti_write(p, &im, 16, err, sizeof err), 0);
    pv_image_free(&im);
    size_t n;
    unsigned char *b = load(p, &n);
    put64(b, 16 + 8, (int64_t)1 << 40);
    save(p, b, n);
    pv_image out;
    assert_int_equal(pv_nifti_read(p, &out, err, sizeof err), -1);
    printf("%s\n", err);
    assert_non_null(strstr(err, "'dim[1]'"));
    put64(b, 16 + 8, 5);
    put64(b, 168, 10); /* vox_offset inside the 540-byte header */
    save(p, b, n);
    assert_int_equal(pv_nifti_read(p, &out, err, sizeof err), -1);
    assert_non_null(strstr(err, "'vox_offset'"));
    free(b);
}

/* A gzip file cut short: the header checks pass, nifticlib's read fails. */
static void test_cut_gzip(void **state)
{
    (void)state;
    char p[1024], err[512];
    data_path(p, sizeof p, "example_seg.nii.gz");
    size_t n;
    unsigned char *b = load(p, &n);
    char q[1024];
    snprintf(q, sizeof q, "%s", tmp("cut.nii.gz"));
    save(q, b, n / 2);
    pv_image out;
    assert_int_equal(pv_nifti_read(q, &out, err, sizeof err), -1);
    printf("%s\n", err);
    assert_non_null(strstr(err, q));
    assert_null(out.data);
    assert_int_equal(pv_nifti_read(tmp("missing.nii"), &out, err, sizeof err), -1);
    assert_non_null(strstr(err, "missing.nii"));
    free(b);
}

/* A header/image pair (magic ni1: the voxels in the .img beside the .hdr)
 * reads like the single file it was made from; its .img cut short, or
 * missing, fails naming the header before nifticlib allocates the voxels
 * (fuzz_nifti found a 350-byte "pair" asking for 1.9 G voxels). */
static void test_pair(void **state)
{
    (void)state;
    pv_image im = small_image();
    im.nifti_version = 1;
    char err[512], single[1024], hdr[1024], img[1024];
    snprintf(single, sizeof single, "%s", tmp("pair_src.nii"));
    snprintf(hdr, sizeof hdr, "%s", tmp("pair.hdr"));
    snprintf(img, sizeof img, "%s", tmp("pair.img"));
    assert_int_equal(pv_nifti_write(single, &im, 16, err, sizeof err), 0);
    size_t n;
    unsigned char *b = load(single, &n);
    float vox;
    memcpy(&vox, b + 108, 4);
    const size_t off = (size_t)vox;
    assert_true(off >= 348 && off < n);
    memcpy(b + 344, "ni1", 4);
    putf(b, 108, 0.0f);
    save(hdr, b, 348);
    save(img, b + off, n - off);

    pv_image a, out;
    assert_int_equal(pv_nifti_read(single, &a, err, sizeof err), 0);
    if (pv_nifti_read(hdr, &out, err, sizeof err) != 0)
        fail_msg("%s", err);
    assert_int_equal(pv_image_voxels(&out), pv_image_voxels(&a));
    assert_memory_equal(out.data, a.data, pv_image_voxels(&a) * sizeof *a.data);
    pv_image_free(&out);

    save(img, b + off, n - off - 7);
    assert_int_equal(pv_nifti_read(hdr, &out, err, sizeof err), -1);
    printf("%s\n", err);
    assert_non_null(strstr(err, hdr));
    assert_non_null(strstr(err, "'vox_offset'"));

    remove(img);
    assert_int_equal(pv_nifti_read(hdr, &out, err, sizeof err), -1);
    printf("%s\n", err);
    assert_non_null(strstr(err, hdr));
    assert_non_null(strstr(err, "'magic'"));
    assert_null(out.data);

    /* the fuzzer's case: a .nii whose magic says pair, with 6 x 11782 x 26990
     * voxels (nifticlib takes the voxels from the .nii itself then) */
    char fake[1024];
    snprintf(fake, sizeof fake, "%s", tmp("pair_fake.nii"));
    put16(b, 42, 6), put16(b, 44, 11782), put16(b, 46, 26990);
    save(fake, b, 360);
    assert_int_equal(pv_nifti_read(fake, &out, err, sizeof err), -1);
    printf("%s\n", err);
    assert_non_null(strstr(err, fake));
    assert_non_null(strstr(err, "'vox_offset'"));
    pv_image_free(&a);
    pv_image_free(&im);
    free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reads_the_bundled_ct),
        cmocka_unit_test(test_round_trips),
        cmocka_unit_test(test_bad_headers_named),
        cmocka_unit_test(test_bad_nifti2_dims),
        cmocka_unit_test(test_cut_gzip),
        cmocka_unit_test(test_pair),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
