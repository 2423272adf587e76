/* SPDX-License-Identifier: Apache-2.0 */
/* Rig file v1: round trips through every loading path, and one test per
 * class of damage, each asserting its status code and that the message
 * names the section and the byte offset. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pose/pose.h"
#include "rig_bytes.h"
#include "tiny_rig.h"

/* ------------------------------------------------------------- helpers */

typedef struct image {
    uint8_t *data;
    size_t size;
} image;

static image write_image(const pose_rig_desc *d)
{
    image im = {NULL, 0};
    void *data = NULL;
    assert_int_equal(pose_rig_write_memory(d, NULL, &data, &im.size), POSE_OK);
    assert_non_null(data);
    assert_int_equal((uintptr_t)data % 64, 0);
    im.data = data;
    return im;
}

static image tiny_image(int with_cor, int with_metadata)
{
    tiny_rig t;
    tiny_rig_init(&t, with_cor, with_metadata);
    return write_image(&t.desc);
}

static const char *tmp_path(const char *name)
{
    static char path[1024];
    const char *dir = getenv("POSE_TEST_TMP");
    snprintf(path, sizeof path, "%s/%s", dir ? dir : "/tmp", name);
    return path;
}

/* Load a (damaged) copy and check status, NULL rig and message contents. */
static void expect_load_error(const uint8_t *data, size_t size, pose_status want, int count, ...)
{
    pose_rig *rig = (pose_rig *)1;
    pose_status st = pose_rig_load_memory(data, size, NULL, &rig);
    if (st != want)
        fail_msg("status %d (%s), expected %d; message: %s", st, pose_status_string(st), want,
                 pose_last_error());
    assert_null(rig);
    const char *msg = pose_last_error();
    va_list ap;
    va_start(ap, count);
    for (int i = 0; i < count; i++) {
        const char *needle = va_arg(ap, const char *);
        if (!strstr(msg, needle))
            fail_msg("message \"%s\" lacks \"%s\"", msg, needle);
    }
    va_end(ap);
}

static char at_byte[64];
static const char *at(uint64_t offset)
{
    snprintf(at_byte, sizeof at_byte, "at byte %llu:", (unsigned long long)offset);
    return at_byte;
}

/* Every public array of `rig` equals the description's, bit for bit. */
static void assert_rig_matches(const pose_rig *rig, const pose_rig_desc *d)
{
    assert_int_equal(pose_rig_joint_count(rig), d->joint_count);
    for (size_t j = 0; j < d->joint_count; j++) {
        pose_joint_info ji;
        assert_int_equal(pose_rig_joint_info(rig, (int)j, &ji), POSE_OK);
        assert_string_equal(ji.name, d->joints[j].name);
        assert_int_equal(ji.parent, d->joints[j].parent);
        assert_memory_equal(&ji.rest_model, &d->joints[j].rest_model, sizeof ji.rest_model);
        assert_int_equal(ji.limit_flags, d->joints[j].limit_flags);
        assert_int_equal(ji.limit_order, d->joints[j].limit_order);
        assert_memory_equal(ji.limit_min_deg, d->joints[j].limit_min_deg, 12);
        assert_memory_equal(ji.limit_max_deg, d->joints[j].limit_max_deg, 12);
        assert_int_equal(pose_rig_find_joint(rig, d->joints[j].name), (int)j);
    }
    pose_tet_info ti;
    assert_int_equal(pose_rig_tet_info(rig, &ti), POSE_OK);
    assert_int_equal(ti.vertex_count, d->tet_vertex_count);
    assert_int_equal(ti.tet_count, d->tet_count);
    assert_int_equal(ti.influences, d->influences);
    assert_memory_equal(ti.rest_positions, d->tet_positions, d->tet_vertex_count * 12);
    assert_memory_equal(ti.tets, d->tets, d->tet_count * 16);
    assert_memory_equal(ti.labels, d->tet_labels, d->tet_count * 2);
    assert_memory_equal(ti.weight_joints, d->weight_joints, d->tet_vertex_count * d->influences * 2);
    assert_memory_equal(ti.weights, d->weights, d->tet_vertex_count * d->influences * 4);
    if (d->cor)
        assert_memory_equal(ti.cor, d->cor, d->tet_vertex_count * 12);
    else
        assert_null(ti.cor);
    assert_int_equal(pose_rig_tissue_count(rig), d->tissue_count);
    for (size_t t = 0; t < d->tissue_count; t++) {
        const pose_tissue_desc *td = &d->tissues[t];
        pose_tissue_info info;
        assert_int_equal(pose_rig_tissue_info(rig, (int)t, &info), POSE_OK);
        assert_string_equal(info.name, td->name);
        assert_int_equal(info.kind, td->kind);
        assert_int_equal(info.joint, td->joint);
        assert_int_equal(info.vertex_count, td->vertex_count);
        assert_int_equal(info.triangle_count, td->triangle_count);
        assert_memory_equal(info.rest_positions, td->positions, td->vertex_count * 12);
        assert_memory_equal(info.triangles, td->triangles, td->triangle_count * 12);
        assert_int_equal(pose_rig_find_tissue(rig, td->name), (int)t);
    }
    assert_string_equal(pose_rig_metadata(rig), d->metadata ? d->metadata : "");
}

/* Counting allocator: every block freed, and really used. */
typedef struct counter {
    size_t allocs, frees;
    long fail_at; /* fail the n-th allocation (0-based), -1 never */
} counter;

static void *count_alloc(size_t size, size_t align, void *user)
{
    counter *c = user;
    if (c->fail_at >= 0 && (long)c->allocs == c->fail_at)
        return NULL;
    void *p = NULL;
    if (posix_memalign(&p, align < sizeof(void *) ? sizeof(void *) : align, size) != 0)
        return NULL;
    c->allocs++;
    return p;
}

static void count_free(void *p, void *user)
{
    counter *c = user;
    c->frees++;
    free(p);
}

/* ------------------------------------------------------------- arguments */

static void test_invalid_arguments(void **state)
{
    (void)state;
    pose_rig *rig = (pose_rig *)1;
    assert_int_equal(pose_rig_load(NULL, &rig), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_rig_load("x.rig", NULL), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_rig_load_memory(NULL, 10, NULL, &rig), POSE_ERR_INVALID_ARGUMENT);
    assert_null(rig);
    pose_load_options half = {.allocator = {.alloc = count_alloc}};
    assert_int_equal(pose_rig_load_ex("x.rig", &half, &rig), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_rig_create(NULL, NULL, &rig), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_rig_write_file(NULL, tmp_path("null.rig")), POSE_ERR_INVALID_ARGUMENT);
    void *data;
    size_t size;
    assert_int_equal(pose_rig_write_memory(NULL, NULL, &data, &size), POSE_ERR_INVALID_ARGUMENT);

    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    t.joints[1].name = "a-name-that-is-far-too-long-for-a-64-byte-slot-aaaaaaaaaaaaaaaaaaaa";
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "joint 1"));
    tiny_rig_init(&t, 1, 1);
    t.desc.influences = 9;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_ARGUMENT);
    tiny_rig_init(&t, 1, 1);
    t.desc.joint_count = 0;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_ARGUMENT);
    tiny_rig_init(&t, 1, 1);
    t.tissues[1].bary = NULL;
    assert_int_equal(pose_rig_write_memory(&t.desc, NULL, &data, &size), POSE_ERR_INVALID_ARGUMENT);

    pose_rig_free(NULL);
    assert_int_equal(pose_rig_joint_count(NULL), 0);
    assert_int_equal(pose_rig_find_joint(NULL, "root"), -1);
    assert_string_equal(pose_rig_metadata(NULL), "");

    image im = tiny_image(1, 1);
    assert_int_equal(pose_rig_load_memory(im.data, im.size, NULL, &rig), POSE_OK);
    pose_joint_info ji;
    pose_tissue_info tinfo;
    assert_int_equal(pose_rig_joint_info(rig, 3, &ji), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_rig_joint_info(rig, -1, &ji), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_rig_tissue_info(rig, 2, &tinfo), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_rig_find_joint(rig, "nope"), -1);
    assert_int_equal(pose_rig_find_tissue(rig, "nope"), -1);
    assert_int_equal(pose_rig_tet_info(rig, NULL), POSE_ERR_INVALID_ARGUMENT);
    pose_rig_free(rig);

    /* Borrowing needs the buffer 64-byte aligned. */
    uint8_t *odd = malloc(im.size + 64);
    assert_non_null(odd);
    uint8_t *mis = odd + (64 - (uintptr_t)odd % 64) % 64 + 8;
    memcpy(mis, im.data, im.size);
    pose_load_options borrow = {.flags = POSE_LOAD_BORROW};
    assert_int_equal(pose_rig_load_memory(mis, im.size, &borrow, &rig), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "aligned"));
    free(odd);
    free(im.data);
}

static void test_io_errors(void **state)
{
    (void)state;
    pose_rig *rig;
    const char *missing = tmp_path("does-not-exist.rig");
    assert_int_equal(pose_rig_load(missing, &rig), POSE_ERR_IO);
    assert_non_null(strstr(pose_last_error(), missing));
    assert_int_equal(pose_rig_load(getenv("POSE_TEST_TMP") ? getenv("POSE_TEST_TMP") : "/tmp",
                                   &rig), POSE_ERR_IO);
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    assert_int_equal(pose_rig_write_file(&t.desc, "/nonexistent-dir/x.rig"), POSE_ERR_IO);
    assert_non_null(strstr(pose_last_error(), "/nonexistent-dir/x.rig"));
    /* A file shorter than the header. */
    const char *path = tmp_path("short.rig");
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs("POSE", f);
    fclose(f);
    assert_int_equal(pose_rig_load(path, &rig), POSE_ERR_FORMAT);
    assert_non_null(strstr(pose_last_error(), "truncated"));
    assert_non_null(strstr(pose_last_error(), path));
    uint8_t zero = 0;
    expect_load_error(&zero, 0, POSE_ERR_FORMAT, 2, "section 'header'", "truncated");
}

/* ------------------------------------------------------------- round trips */

static void test_round_trip_all_paths(void **state)
{
    (void)state;
    for (int variant = 0; variant < 3; variant++) {
        tiny_rig t;
        tiny_rig_init(&t, variant != 1, variant != 2);
        image im = write_image(&t.desc);
        const char *path = tmp_path("tiny.rig");
        assert_int_equal(pose_rig_write_file(&t.desc, path), POSE_OK);

        /* The file holds exactly the bytes of the memory image. */
        FILE *f = fopen(path, "rb");
        assert_non_null(f);
        uint8_t *bytes = malloc(im.size + 1);
        assert_int_equal(fread(bytes, 1, im.size + 1, f), im.size);
        fclose(f);
        assert_memory_equal(bytes, im.data, im.size);
        free(bytes);

        pose_rig *rig;
        assert_int_equal(pose_rig_load(path, &rig), POSE_OK);
        assert_rig_matches(rig, &t.desc);
        pose_rig_free(rig);

        counter c = {0, 0, -1};
        pose_load_options o = {.allocator = {count_alloc, count_free, &c},
                               .flags = POSE_LOAD_NO_MMAP};
        assert_int_equal(pose_rig_load_ex(path, &o, &rig), POSE_OK);
        assert_rig_matches(rig, &t.desc);
        pose_rig_free(rig);
        assert_true(c.allocs >= 3); /* rig, image, tables */
        assert_int_equal(c.allocs, c.frees);

        o.flags = 0;
        assert_int_equal(pose_rig_load_memory(im.data, im.size, &o, &rig), POSE_OK);
        memset(im.data + 64, 0xAB, 32); /* the rig holds its own copy */
        assert_rig_matches(rig, &t.desc);
        pose_rig_free(rig);
        free(im.data);

        im = write_image(&t.desc);
        o.flags = POSE_LOAD_BORROW;
        assert_int_equal(pose_rig_load_memory(im.data, im.size, &o, &rig), POSE_OK);
        pose_tet_info ti;
        pose_rig_tet_info(rig, &ti);
        /* Borrowed: arrays point into the caller's buffer, no copy. */
        assert_true((const uint8_t *)ti.rest_positions > im.data &&
                    (const uint8_t *)ti.rest_positions < im.data + im.size);
        assert_int_equal((uintptr_t)ti.rest_positions % 64, 0);
        assert_int_equal((uintptr_t)ti.weights % 64, 0);
        assert_rig_matches(rig, &t.desc);
        pose_rig_free(rig);
        assert_int_equal(c.allocs, c.frees);

        assert_int_equal(pose_rig_create(&t.desc, &o.allocator, &rig), POSE_OK);
        assert_rig_matches(rig, &t.desc);
        pose_rig_free(rig);
        assert_int_equal(c.allocs, c.frees);
        free(im.data);
    }
}

static void test_rest_local_from_rest_model(void **state)
{
    (void)state;
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    pose_rig *rig;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_OK);
    pose_joint_info ji;
    pose_rig_joint_info(rig, 0, &ji);
    assert_memory_equal(&ji.rest_local, &ji.rest_model, sizeof ji.rest_local);
    /* elbow: parent at (0,0,.5) unrotated -> local = 90 deg about Z at (1,0,0) */
    pose_rig_joint_info(rig, 1, &ji);
    assert_float_equal(ji.rest_local.rotation[2], 0.70710678f, 1e-6);
    assert_float_equal(ji.rest_local.rotation[3], 0.70710678f, 1e-6);
    assert_float_equal(ji.rest_local.translation[0], 1.0f, 1e-6);
    assert_float_equal(ji.rest_local.translation[1], 0.0f, 1e-6);
    assert_float_equal(ji.rest_local.translation[2], 0.0f, 1e-6);
    /* wrist: same rotation as elbow -> identity; offset (1,0,0) seen from a
     * frame turned 90 degrees about Z is (0,-1,0) */
    pose_rig_joint_info(rig, 2, &ji);
    assert_float_equal(ji.rest_local.rotation[2], 0.0f, 1e-6);
    assert_float_equal(fabsf(ji.rest_local.rotation[3]), 1.0f, 1e-6);
    assert_float_equal(ji.rest_local.translation[0], 0.0f, 1e-6);
    assert_float_equal(ji.rest_local.translation[1], -1.0f, 1e-6);
    assert_float_equal(ji.rest_local.translation[2], 0.0f, 1e-6);
    assert_int_equal(ji.limit_flags, 0);
    pose_rig_joint_info(rig, 1, &ji);
    assert_int_equal(ji.limit_flags, POSE_LIMIT_Y);
    assert_int_equal(ji.limit_order, POSE_EULER_ZXY);
    assert_float_equal(ji.limit_max_deg[1], 140.0f, 0.0f);
    pose_rig_free(rig);
}

/* Every allocation failure is reported, and nothing leaks. */
static void test_allocation_failures(void **state)
{
    (void)state;
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    image im = write_image(&t.desc);
    for (long n = 0;; n++) {
        counter c = {0, 0, n};
        pose_load_options o = {.allocator = {count_alloc, count_free, &c}};
        pose_rig *rig;
        pose_status st = pose_rig_load_memory(im.data, im.size, &o, &rig);
        pose_rig_free(rig);
        assert_int_equal(c.allocs, c.frees);
        if (st == POSE_OK)
            break;
        assert_int_equal(st, POSE_ERR_OUT_OF_MEMORY);
        assert_true(n < 20);
    }
    free(im.data);
}

/* ------------------------------------------------------------- header damage */

static void test_bad_magic(void **state)
{
    (void)state;
    image im = tiny_image(1, 1);
    im.data[1] = 'X';
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 3, "memory buffer", "section 'header'",
                      "bad magic");
    free(im.data);
}

/* Policy (docs/rig-format.md, "Versions"): a reader takes the versions it
 * knows; anything else is refused with POSE_ERR_VERSION naming both numbers,
 * before any other field is trusted. */
static void test_future_version(void **state)
{
    (void)state;
    image im = tiny_image(1, 1);
    rb_put_u32(im.data + 8, 2);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_VERSION, 3, "file is version 2, this library reads 1",
                      "newer pose", at(8));
    rb_put_u32(im.data + 8, 0xFFFFFFFFu);
    expect_load_error(im.data, im.size, POSE_ERR_VERSION, 1, "file is version 4294967295");
    free(im.data);
}

static void test_old_version_zero(void **state)
{
    (void)state;
    image im = tiny_image(1, 1);
    rb_put_u32(im.data + 8, 0);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_VERSION, 2,
                      "file is version 0, this library reads 1", "development format");
    free(im.data);
}

static void test_header_crc_and_fields(void **state)
{
    (void)state;
    image im = tiny_image(1, 1);
    im.data[48] = 1; /* reserved byte, CRC not updated */
    expect_load_error(im.data, im.size, POSE_ERR_CHECKSUM, 2, "section 'header'", "header CRC32");
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "section 'header'", "reserved");
    free(im.data);

    im = tiny_image(1, 1);
    rb_put_u32(im.data + 16, 0); /* no sections */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "section count 0", at(16));
    rb_put_u32(im.data + 16, 1000);
    rb_put_u32(im.data + 60, rb_crc32(im.data, 60));
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 1, "section count 1000");
    free(im.data);

    im = tiny_image(1, 1);
    im.data[70] ^= 0x10; /* table entry, table CRC not updated */
    expect_load_error(im.data, im.size, POSE_ERR_CHECKSUM, 2, "section 'section table'", at(64));
    free(im.data);
}

/* ------------------------------------------------------------- truncation */

static void test_truncation_at_each_section(void **state)
{
    (void)state;
    image im = tiny_image(1, 1);
    static const char *const names[] = {"", "skeleton", "tetmesh", "weights", "cor", "tissues",
                                        "metadata"};
    uint32_t n = rb_section_count(im.data);
    assert_int_equal(n, 6);
    for (uint32_t i = 0; i < n; i++) {
        uint8_t *e = rb_entry(im.data, i);
        uint32_t type = rb_u32(e);
        uint64_t off = rb_u64(e + 8), len = rb_u64(e + 16);
        char section[64];
        snprintf(section, sizeof section, "section '%s'", names[type]);
        /* cut in the middle of the section and right at its start */
        size_t cuts[2] = {(size_t)(off + len / 2), (size_t)off};
        for (int c = 0; c < 2; c++) {
            if (c == 1 && i == 0)
                continue; /* a cut at the first section's start is reported as the table's */
            expect_load_error(im.data, cuts[c], POSE_ERR_FORMAT, 3, section, "truncated",
                              at(cuts[c]));
        }
    }
    expect_load_error(im.data, 100, POSE_ERR_FORMAT, 2, "section 'section table'", "truncated");
    expect_load_error(im.data, 63, POSE_ERR_FORMAT, 2, "section 'header'", "truncated");
    /* Trailing bytes are as wrong as missing ones. */
    uint8_t *longer = calloc(1, im.size + 64);
    memcpy(longer, im.data, im.size);
    expect_load_error(longer, im.size + 64, POSE_ERR_FORMAT, 2, "section 'header'", "header says");
    free(longer);
    free(im.data);
}

static void test_crc_mismatch_in_each_section(void **state)
{
    (void)state;
    image im = tiny_image(1, 1);
    static const char *const names[] = {"", "skeleton", "tetmesh", "weights", "cor", "tissues",
                                        "metadata"};
    for (uint32_t i = 0; i < rb_section_count(im.data); i++) {
        uint8_t *e = rb_entry(im.data, i);
        uint64_t off = rb_u64(e + 8), len = rb_u64(e + 16);
        im.data[off + len / 2] ^= 0x01;
        char section[64];
        snprintf(section, sizeof section, "section '%s'", names[rb_u32(e)]);
        expect_load_error(im.data, im.size, POSE_ERR_CHECKSUM, 3, section, "CRC32", at(off));
        /* the same bytes load when CRCs are skipped only if still valid; the
         * flipped bit may break content, so just check no crash */
        pose_load_options skip = {.flags = POSE_LOAD_SKIP_CRC};
        pose_rig *rig;
        if (pose_rig_load_memory(im.data, im.size, &skip, &rig) == POSE_OK)
            pose_rig_free(rig);
        im.data[off + len / 2] ^= 0x01;
    }
    pose_rig *rig;
    assert_int_equal(pose_rig_load_memory(im.data, im.size, NULL, &rig), POSE_OK);
    pose_rig_free(rig);
    free(im.data);
}

/* ------------------------------------------------------------- structure */

static void test_misaligned_and_overlapping_sections(void **state)
{
    (void)state;
    image im = tiny_image(1, 1);
    int w = rb_find(im.data, SEC_WEIGHTS);
    uint8_t *e = rb_entry(im.data, (uint32_t)w);
    uint64_t off = rb_u64(e + 8);
    rb_put_u64(e + 8, off + 8);
    rb_put_u64(e + 16, rb_u64(e + 16) - 8);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 3, "section 'weights'", "misaligned",
                      at(64 + 32 * (uint64_t)w));
    free(im.data);

    im = tiny_image(1, 1);
    int t = rb_find(im.data, SEC_TETMESH);
    w = rb_find(im.data, SEC_WEIGHTS);
    rb_put_u64(rb_entry(im.data, (uint32_t)w) + 8, rb_u64(rb_entry(im.data, (uint32_t)t) + 8));
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 3, "section 'weights'", "overlap",
                      "section 'tetmesh'");
    free(im.data);

    im = tiny_image(1, 1);
    e = rb_entry(im.data, 0);
    rb_put_u64(e + 16, im.size); /* runs past the end */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "section 'skeleton'", "outside");
    rb_put_u64(e + 8, 0); /* inside the header */
    rb_put_u64(e + 16, 64);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "section 'skeleton'", "outside");
    free(im.data);
}

static void test_section_table_entries(void **state)
{
    (void)state;
    /* duplicate type */
    image im = tiny_image(1, 1);
    rb_put_u32(rb_entry(im.data, (uint32_t)rb_find(im.data, SEC_METADATA)), SEC_COR);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "section 'cor'", "repeats");
    free(im.data);

    /* required section missing: drop the last entry (tissues, without metadata) */
    im = tiny_image(1, 0);
    assert_int_equal(rb_find(im.data, SEC_TISSUES), 4);
    rb_put_u32(im.data + 16, 4);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "section 'tissues'", "missing");

    /* unknown types: skipped when flagged optional, refused otherwise. The
     * 5-entry table has room for a sixth entry before the 64-byte boundary. */
    rb_put_u32(im.data + 16, 5);
    size_t grown = im.size + 64;
    uint8_t *img = calloc(1, grown);
    memcpy(img, im.data, im.size);
    memset(img + im.size, 0x5A, 64);
    uint8_t *e = rb_entry(img, 5);
    rb_put_u32(e, 12); /* reserved for future pose sections: unknown here */
    rb_put_u32(e + 4, 1);
    rb_put_u64(e + 8, im.size);
    rb_put_u64(e + 16, 64);
    rb_put_u32(img + 16, 6);
    rb_put_u64(img + 24, grown);
    rb_fix_crcs(img, grown);
    pose_rig *rig;
    assert_int_equal(pose_rig_load_memory(img, grown, NULL, &rig), POSE_OK);
    pose_rig_free(rig);
    rb_put_u32(e + 4, 0);
    rb_fix_crcs(img, grown);
    expect_load_error(img, grown, POSE_ERR_FORMAT, 2, "section 'unknown'", "not marked optional");
    rb_put_u32(e + 4, 2); /* unknown flag */
    rb_fix_crcs(img, grown);
    expect_load_error(img, grown, POSE_ERR_FORMAT, 2, "section 'section table'", "flags");
    rb_put_u32(e + 4, 1);
    rb_put_u32(e, 0x1234);
    rb_fix_crcs(img, grown);
    assert_int_equal(pose_rig_load_memory(img, grown, NULL, &rig), POSE_OK);
    pose_rig_free(rig);
    /* volumes (type 7) is known since 0.2: its content is checked, optional or not. */
    rb_put_u32(e, 7);
    rb_fix_crcs(img, grown);
    expect_load_error(img, grown, POSE_ERR_FORMAT, 2, "section 'volumes'", "volume count");
    free(img);
    free(im.data);
}

static void test_section_sizes_and_counts(void **state)
{
    (void)state;
    image im = tiny_image(1, 1);
    uint64_t sk = rb_offset(im.data, SEC_SKELETON);
    rb_put_u32(im.data + sk, 4); /* joint count no longer matches the size */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 3, "section 'skeleton'", "need exactly",
                      at(sk));
    rb_put_u32(im.data + sk, 0);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "joint count 0", at(sk));
    free(im.data);

    im = tiny_image(1, 1);
    uint64_t w = rb_offset(im.data, SEC_WEIGHTS);
    rb_put_u64(im.data + w, 13); /* weights for a different vertex count */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "section 'weights'",
                      "13 vertices, the tet mesh has 12");
    rb_put_u64(im.data + w, 12);
    rb_put_u32(im.data + w + 8, 9);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "influence count 9", at(w + 8));
    free(im.data);

    im = tiny_image(1, 1);
    uint64_t ts = rb_offset(im.data, SEC_TISSUES);
    rb_put_u64(im.data + ts + 64 + 88, 128); /* skin positions moved off the layout */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 3, "section 'tissues'", "positions",
                      at(ts + 64 + 88));
    free(im.data);

    im = tiny_image(1, 1);
    uint64_t md = rb_offset(im.data, SEC_METADATA);
    im.data[md + 64 + 3] = 0; /* NUL inside the text */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "section 'metadata'", "NUL");
    free(im.data);
}

/* ------------------------------------------------------------- content */

/* Loads the tiny image borrowed to learn where arrays are, then damages one
 * value, fixes the CRCs and checks status, section and exact byte offset. */
typedef struct where {
    image im;
    pose_tet_info ti;
    const uint8_t *joint_name[3];
    uint64_t skeleton, tissues;
} where;

static where locate(void)
{
    where w;
    w.im = tiny_image(1, 1);
    pose_load_options borrow = {.flags = POSE_LOAD_BORROW};
    pose_rig *rig;
    assert_int_equal(pose_rig_load_memory(w.im.data, w.im.size, &borrow, &rig), POSE_OK);
    pose_rig_tet_info(rig, &w.ti);
    for (int j = 0; j < 3; j++) {
        pose_joint_info ji;
        pose_rig_joint_info(rig, j, &ji);
        w.joint_name[j] = (const uint8_t *)ji.name;
    }
    pose_rig_free(rig);
    w.skeleton = rb_offset(w.im.data, SEC_SKELETON);
    w.tissues = rb_offset(w.im.data, SEC_TISSUES);
    return w;
}

static uint64_t off_of(const where *w, const void *p)
{
    return (uint64_t)((const uint8_t *)p - w->im.data);
}

static void damage_f32(where *w, uint64_t off, float v)
{
    memcpy(w->im.data + off, &v, 4);
    rb_fix_crcs(w->im.data, w->im.size);
}

static void damage_u32(where *w, uint64_t off, uint32_t v)
{
    rb_put_u32(w->im.data + off, v);
    rb_fix_crcs(w->im.data, w->im.size);
}

static void test_out_of_range_indices(void **state)
{
    (void)state;
    where w = locate();
    uint64_t o = off_of(&w, &w.ti.tets[5]);
    damage_u32(&w, o, 99);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'tetmesh'",
                      "vertex index 99 out of range", at(o));
    free(w.im.data);

    w = locate();
    o = off_of(&w, &w.ti.tets[5]);
    damage_u32(&w, o, w.ti.tets[4]);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 2, "appears twice", at(o));
    free(w.im.data);

    w = locate();
    o = off_of(&w, &w.ti.labels[3]);
    uint16_t label = 9;
    memcpy(w.im.data + o, &label, 2);
    rb_fix_crcs(w.im.data, w.im.size);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'tetmesh'",
                      "label 9", at(o));
    free(w.im.data);

    w = locate();
    o = off_of(&w, &w.ti.weight_joints[3]);
    uint16_t joint = 7;
    memcpy(w.im.data + o, &joint, 2);
    rb_fix_crcs(w.im.data, w.im.size);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'weights'",
                      "names joint 7", at(o));
    free(w.im.data);

    /* tissue 0's embedding tets, from its record (tet offset at +104) */
    w = locate();
    uint64_t tet = w.tissues + rb_u64(w.im.data + w.tissues + 64 + 104);
    damage_u32(&w, tet + 2 * 4, 12);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'tissues'",
                      "vertex 2 embedded in tet 12", at(tet + 8));
    free(w.im.data);

    w = locate();
    uint64_t tri = w.tissues + rb_u64(w.im.data + w.tissues + 64 + 96);
    damage_u32(&w, tri + 4, 4);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 2, "uses vertex 4", at(tri + 4));
    free(w.im.data);

    w = locate();
    damage_u32(&w, w.tissues + 64 + 128 + 68, 3); /* bone tissue's joint */
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 2, "joint 3 out of range",
                      at(w.tissues + 64 + 128 + 68));
    free(w.im.data);
}

static void test_parent_after_child(void **state)
{
    (void)state;
    where w = locate();
    uint64_t parents = w.skeleton + 64 + 3 * 64; /* names, then parents (spec) */
    damage_u32(&w, parents + 4, 2);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 4, "section 'skeleton'",
                      "joint 1 ('elbow'): parent 2", "parents must precede children",
                      at(parents + 4));
    damage_u32(&w, parents + 4, 1); /* its own parent */
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 1, "parent 1");
    damage_u32(&w, parents + 4, (uint32_t)-2);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 1, "parent -2");
    free(w.im.data);
}

static void test_bad_weights(void **state)
{
    (void)state;
    where w = locate();
    uint64_t o = off_of(&w, &w.ti.weights[4]);
    damage_f32(&w, o, NAN);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'weights'",
                      "vertex 2: weight 0 is nan", at(o));
    damage_f32(&w, o, INFINITY);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 1, "weight 0 is inf");
    damage_f32(&w, o, 0.9f); /* vertex 2 now sums to 0.9 */
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3,
                      "vertex 2: weights sum to 0.9", "expected 1", at(o));
    damage_f32(&w, o, 1.00005f); /* within the 1e-4 tolerance */
    pose_rig *rig;
    assert_int_equal(pose_rig_load_memory(w.im.data, w.im.size, NULL, &rig), POSE_OK);
    pose_rig_free(rig);
    free(w.im.data);

    w = locate();
    o = off_of(&w, &w.ti.weights[0]);
    damage_f32(&w, o, -0.5f);
    damage_f32(&w, o + 4, 1.5f);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 2, "weight 0 is -0.5", at(o));
    free(w.im.data);

    w = locate();
    o = off_of(&w, &w.ti.cor[7]);
    damage_f32(&w, o, NAN);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'cor'",
                      "vertex 2: centre of rotation", at(o - 4));
    free(w.im.data);
}

static void test_bad_barycentric_and_positions(void **state)
{
    (void)state;
    where w = locate();
    uint64_t bary = w.tissues + rb_u64(w.im.data + w.tissues + 64 + 112);
    float b;
    memcpy(&b, w.im.data + bary + 16, 4);
    damage_f32(&w, bary + 16, b + 0.01f); /* vertex 1 */
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'tissues'",
                      "tissue 0 ('skin'): vertex 1 barycentric coordinates sum to 1.01",
                      at(bary + 16));
    free(w.im.data);

    w = locate();
    uint64_t o = off_of(&w, &w.ti.rest_positions[7]);
    damage_f32(&w, o, INFINITY);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'tetmesh'",
                      "vertex 2: position is not finite", at(o - 4));
    free(w.im.data);

    w = locate();
    uint64_t rest = w.skeleton + 64 + 3 * 64 + 64; /* names, parents, rest transforms */
    damage_f32(&w, rest + 28 + 12, 0.5f);          /* elbow's w */
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'skeleton'",
                      "rest rotation has length", at(rest + 28));
    free(w.im.data);

    w = locate();
    uint64_t limits = w.skeleton + 64 + 3 * 64 + 64 + 128;
    damage_f32(&w, limits + 32 + 8 + 4, 500.0f); /* elbow's y minimum above its maximum */
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 2, "limit on axis y",
                      at(limits + 32));
    free(w.im.data);
}

static void test_bad_names(void **state)
{
    (void)state;
    where w = locate();
    uint64_t o = off_of(&w, w.joint_name[2]);
    memcpy(w.im.data + o, "root\0", 6);
    rb_fix_crcs(w.im.data, w.im.size);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'skeleton'",
                      "joint 2 has the same name 'root' as joint 0", at(o));
    memset(w.im.data + o, 'x', 64);
    rb_fix_crcs(w.im.data, w.im.size);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 2, "not NUL-terminated", at(o));
    memset(w.im.data + o, 0, 64);
    rb_fix_crcs(w.im.data, w.im.size);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 2, "joint 2: empty name", at(o));
    free(w.im.data);

    w = locate();
    uint64_t rec1 = w.tissues + 64 + 128;
    memcpy(w.im.data + rec1, "skin\0", 5);
    rb_fix_crcs(w.im.data, w.im.size);
    expect_load_error(w.im.data, w.im.size, POSE_ERR_INVALID_DATA, 3, "section 'tissues'",
                      "tissue 1 has the same name 'skin' as tissue 0", at(rec1));
    free(w.im.data);
}

/* pose_rig_create and the writers apply the loader's checks and say so. */
static void test_description_errors(void **state)
{
    (void)state;
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    t.weights[4] = 0.9f;
    pose_rig *rig = (pose_rig *)1;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_DATA);
    assert_null(rig);
    assert_string_equal(pose_last_error(), "rig description: section 'weights': vertex 2: "
                                           "weights sum to 0.9, expected 1 (tolerance 1e-4)");
    void *data = (void *)1;
    size_t size = 1;
    assert_int_equal(pose_rig_write_memory(&t.desc, NULL, &data, &size), POSE_ERR_INVALID_DATA);
    assert_null(data);
    assert_int_equal(size, 0);
    const char *path = tmp_path("refused.rig");
    remove(path);
    assert_int_equal(pose_rig_write_file(&t.desc, path), POSE_ERR_INVALID_DATA);
    FILE *f = fopen(path, "rb");
    assert_null(f); /* nothing written */

    tiny_rig_init(&t, 1, 1);
    t.joints[2].parent = 2;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(pose_last_error(), "parents must precede children"));
    tiny_rig_init(&t, 1, 1);
    t.tissues[1].name = "skin";
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_DATA);
    tiny_rig_init(&t, 1, 1);
    t.tissues[0].kind = (pose_tissue_kind)9;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(pose_last_error(), "kind 9"));
    tiny_rig_init(&t, 1, 1);
    t.joints[0].limit_order = (pose_euler_order)6;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_DATA);
    /* A success clears the previous message. */
    tiny_rig_init(&t, 1, 1);
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_OK);
    assert_string_equal(pose_last_error(), "");
    pose_rig_free(rig);
}

/* ------------------------------------------------------------- clinical */

/* pose_rig_joint_clinical returns the description's entry, names defaulted. */
static void assert_clinical_matches(const pose_rig *rig, const pose_joint_clinical *want)
{
    static const char *const defaults[3] = {"flexion", "abduction", "internal_rotation"};
    for (int j = 0; j < 3; j++) {
        pose_joint_clinical got;
        memset(&got, 0xCD, sizeof got);
        if (!want[j].flags) {
            assert_int_equal(pose_rig_joint_clinical(rig, j, &got), POSE_ERR_UNSUPPORTED);
            assert_non_null(strstr(pose_last_error(), "no clinical data"));
            continue;
        }
        assert_int_equal(pose_rig_joint_clinical(rig, j, &got), POSE_OK);
        assert_int_equal(got.flags, POSE_CLINICAL_DEFINED);
        assert_memory_equal(got.neutral, want[j].neutral, sizeof got.neutral);
        assert_memory_equal(got.axes, want[j].axes, sizeof got.axes);
        assert_int_equal(got.limit_flags, want[j].limit_flags);
        assert_memory_equal(got.limit_min_deg, want[j].limit_min_deg, 12);
        assert_memory_equal(got.limit_max_deg, want[j].limit_max_deg, 12);
        for (int k = 0; k < 3; k++)
            assert_string_equal(got.names[k], want[j].names[k] ? want[j].names[k] : defaults[k]);
    }
}

static void test_clinical_round_trip(void **state)
{
    (void)state;
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    tiny_rig_add_clinical(&t);
    image im = write_image(&t.desc);
    /* Section 8, flagged optional so that pose 0.1 readers skip it. */
    int e = rb_find(im.data, SEC_CLINICAL);
    assert_true(e >= 0);
    assert_int_equal(rb_u32(rb_entry(im.data, (uint32_t)e) + 4), 1);
    uint64_t cl = rb_offset(im.data, SEC_CLINICAL);
    assert_int_equal(rb_u64(rb_entry(im.data, (uint32_t)e) + 16), 64 + 3 * CLIN_RECORD);
    assert_int_equal(rb_u32(im.data + cl), 3);
    for (int i = 0; i < CLIN_RECORD; i++) /* root: no data, all zero */
        assert_int_equal(im.data[cl + 64 + i], 0);
    assert_string_equal((const char *)im.data + cl + 64 + 2 * CLIN_RECORD + CLIN_NAMES + 32,
                        "radial_deviation");

    const char *path = tmp_path("clinical.rig");
    assert_int_equal(pose_rig_write_file(&t.desc, path), POSE_OK);
    pose_rig *rig;
    assert_int_equal(pose_rig_load(path, &rig), POSE_OK);
    assert_rig_matches(rig, &t.desc);
    assert_clinical_matches(rig, t.clinical);
    pose_rig_free(rig);
    assert_int_equal(pose_rig_load_memory(im.data, im.size, NULL, &rig), POSE_OK);
    assert_clinical_matches(rig, t.clinical);
    pose_rig_free(rig);
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_OK);
    assert_clinical_matches(rig, t.clinical);
    pose_rig_free(rig);
    free(im.data);

    /* Without clinical data: no section, and every joint says so. */
    tiny_rig_init(&t, 1, 1);
    im = write_image(&t.desc);
    assert_int_equal(rb_find(im.data, SEC_CLINICAL), -1);
    assert_int_equal(pose_rig_load_memory(im.data, im.size, NULL, &rig), POSE_OK);
    memset(t.clinical, 0, sizeof t.clinical);
    assert_clinical_matches(rig, t.clinical);
    pose_joint_clinical c;
    assert_int_equal(pose_rig_joint_clinical(rig, 3, &c), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_rig_joint_clinical(NULL, 0, &c), POSE_ERR_INVALID_ARGUMENT);
    pose_rig_free(rig);
    free(im.data);
}

/* Rigs written before the clinical section existed (the committed seeds are
 * pose 0.1 files) load unchanged and have no clinical data. */
static void test_clinical_old_rigs_load(void **state)
{
    (void)state;
    static const char *const files[] = {"valid_tiny_full.rig", "valid_tiny_minimal.rig",
                                        "valid_tiny_no_cor.rig"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", POSE_RIG_CORPUS, files[i]);
        pose_rig *rig;
        if (pose_rig_load(path, &rig) != POSE_OK)
            fail_msg("%s: %s", path, pose_last_error());
        assert_int_equal(pose_rig_joint_count(rig), 3);
        pose_joint_clinical c;
        for (int j = 0; j < 3; j++)
            assert_int_equal(pose_rig_joint_clinical(rig, j, &c), POSE_ERR_UNSUPPORTED);
        pose_rig_free(rig);
    }
}

/* A clinical image and the file offset of joint j's record. */
static image clinical_image(void)
{
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    tiny_rig_add_clinical(&t);
    return write_image(&t.desc);
}

static uint64_t record_of(image *im, int j)
{
    return rb_offset(im->data, SEC_CLINICAL) + 64 + (uint64_t)j * CLIN_RECORD;
}

static void put_f32(image *im, uint64_t off, float v)
{
    memcpy(im->data + off, &v, 4);
    rb_fix_crcs(im->data, im->size);
}

static void test_clinical_damage(void **state)
{
    (void)state;
    image im = clinical_image();
    uint64_t r = record_of(&im, 1);
    put_f32(&im, r + CLIN_NEUTRAL + 12, 1.1f); /* w: |q| = 1.13 */
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 4, "section 'clinical'",
                      "joint 1 ('elbow'): neutral rotation has length 1.13", "unit quaternion",
                      at(r + CLIN_NEUTRAL));
    free(im.data);

    im = clinical_image();
    r = record_of(&im, 2);
    put_f32(&im, r + CLIN_AXES + 12, 0.1f); /* abduction axis leans towards flexion */
    put_f32(&im, r + CLIN_AXES + 16, 0.99498744f);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 4, "section 'clinical'",
                      "joint 2 ('wrist'): flexion and abduction axes are not orthogonal",
                      "dot product 0.1", at(r + CLIN_AXES + 12));
    put_f32(&im, r + CLIN_AXES + 12, 0.0f);
    put_f32(&im, r + CLIN_AXES + 16, 0.9f); /* short abduction axis */
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "abduction axis has length 0.9",
                      at(r + CLIN_AXES + 12));
    put_f32(&im, r + CLIN_AXES + 16, NAN);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "not finite", at(r + CLIN_NEUTRAL));
    free(im.data);

    im = clinical_image();
    r = record_of(&im, 2);
    memset(im.data + r + CLIN_NAMES + 32, 'x', 32);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 3, "section 'clinical'",
                      "name of the abduction angle is not NUL-terminated within 32 bytes",
                      at(r + CLIN_NAMES + 32));
    memset(im.data + r + CLIN_NAMES + 32, 0, 32);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2,
                      "joint 2 ('wrist'): empty name for the abduction angle", at(r + CLIN_NAMES + 32));
    free(im.data);

    im = clinical_image();
    r = record_of(&im, 2);
    put_f32(&im, r + CLIN_MIN + 8, 90.0f); /* pronation [90, 85] */
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 3, "range of rotation is [90, 85]",
                      "section 'clinical'", at(r + CLIN_MIN + 8));
    put_f32(&im, r + CLIN_MIN + 8, -80.0f);
    rb_put_u32(im.data + r + CLIN_LIMIT_FLAGS, 8);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "limit flags 0x8 unknown",
                      at(r + CLIN_LIMIT_FLAGS));
    rb_put_u32(im.data + r + CLIN_LIMIT_FLAGS, 7);
    rb_put_u32(im.data + r + CLIN_FLAGS, 3);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "flags 0x3 unknown", at(r));
    rb_put_u32(im.data + r + CLIN_FLAGS, 1);
    im.data[r + CLIN_RESERVED + 5] = 1;
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "reserved bytes",
                      at(r + CLIN_RESERVED));
    free(im.data);

    /* A joint without data must be all zero; counts and sizes must agree. */
    im = clinical_image();
    r = record_of(&im, 0);
    put_f32(&im, r + CLIN_MAX, 99.0f);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 3, "joint 0 ('root')",
                      "without clinical data (flags 0) has non-zero bytes", at(r));
    free(im.data);
    im = clinical_image();
    uint64_t cl = rb_offset(im.data, SEC_CLINICAL);
    rb_put_u32(im.data + cl, 4);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 3, "section 'clinical'",
                      "records for 4 joints, the skeleton has 3", at(cl));
    rb_put_u32(im.data + cl, 3);
    im.data[cl + 10] = 1;
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "reserved header bytes", at(cl + 4));
    im.data[cl + 10] = 0;
    uint8_t *entry = rb_entry(im.data, (uint32_t)rb_find(im.data, SEC_CLINICAL));
    rb_put_u64(entry + 16, 64 + 2 * CLIN_RECORD);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 3, "section 'clinical'",
                      "but its joint count need exactly 640", at(cl));
    free(im.data);
}

/* Descriptions get the same checks, named without byte offsets. */
static void test_clinical_description_errors(void **state)
{
    (void)state;
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    tiny_rig_add_clinical(&t);
    t.clinical[1].neutral[3] = 0.5f;
    pose_rig *rig = (pose_rig *)1;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_DATA);
    assert_null(rig);
    assert_string_equal(pose_last_error(),
                        "rig description: section 'clinical': joint 1 ('elbow'): neutral rotation "
                        "has length 0.563016, expected a unit quaternion (tolerance 1e-4)");
    tiny_rig_init(&t, 1, 1);
    tiny_rig_add_clinical(&t);
    t.clinical[2].names[2] = "a-name-of-exactly-32-bytes-xxxxx";
    void *data;
    size_t size;
    assert_int_equal(pose_rig_write_memory(&t.desc, NULL, &data, &size), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "joint 2 ('wrist'): name of angle 2 must be 1..31 bytes"));
    t.clinical[2].names[2] = "";
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_ARGUMENT);
    t.clinical[2].names[2] = "a-name-of-exactly-31-bytes-xxxx";
    t.clinical[2].limit_min_deg[0] = 100.0f;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(pose_last_error(), "range of flexion is [100, 80]"));
    t.clinical[2].limit_min_deg[0] = -70.0f;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_OK);
    pose_joint_clinical c;
    assert_int_equal(pose_rig_joint_clinical(rig, 2, &c), POSE_OK);
    assert_string_equal(c.names[2], "a-name-of-exactly-31-bytes-xxxx");
    pose_rig_free(rig);
}

/* The couplings section (type 10, optional): round trip, what a state
 * makes of it, damage named with its byte, and rigs without it. */
static void test_couplings(void **state)
{
    (void)state;
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    tiny_rig_add_couplings(&t);
    image im = write_image(&t.desc);
    int e = rb_find(im.data, SEC_COUPLINGS);
    assert_true(e >= 0);
    assert_int_equal(rb_u32(rb_entry(im.data, (uint32_t)e) + 4), 1); /* OPTIONAL: 0.1 skips it */
    assert_int_equal(rb_u64(rb_entry(im.data, (uint32_t)e) + 16), 64 + 64);
    const uint64_t sec = rb_offset(im.data, SEC_COUPLINGS), r1 = sec + 64 + 32;
    assert_int_equal(rb_u32(im.data + sec), 2);
    pose_rig *rig;
    assert_int_equal(pose_rig_load_memory(im.data, im.size, NULL, &rig), POSE_OK);
    pose_fem_coupling got[3];
    assert_int_equal(pose_rig_fem_couplings(rig, NULL, 0), 2);
    assert_int_equal(pose_rig_fem_couplings(rig, got, 3), 2);
    assert_memory_equal(got, t.couplings, sizeof t.couplings);
    /* A state takes the rig's couplings on the nodes the simulation moves:
     * vertices 9 and 10 are in soft tets only. */
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_int_equal(pose_fem_coupling_count(st), 2);
    pose_state_free(st);
    pose_rig_free(rig);
    assert_int_equal(pose_rig_fem_couplings(NULL, got, 3), 0);

    uint8_t *keep = malloc(im.size);
    assert_non_null(keep);
    memcpy(keep, im.data, im.size);
    rb_put_u32(im.data + r1, 12); /* node */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 3, "section 'couplings'",
                      "coupling 1: node 12 is not a tet vertex (12)", at(r1));
    memcpy(im.data, keep, im.size);
    rb_put_u32(im.data + r1, 9); /* node 9 twice */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "node 9 after node 9", at(r1));
    memcpy(im.data, keep, im.size);
    rb_put_u32(im.data + r1 + 4, 3); /* joint */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "coupling 1: joint 3", at(r1 + 4));
    memcpy(im.data, keep, im.size);
    put_f32(&im, r1 + 8, -1.0f);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "stiffness -1", at(r1 + 8));
    memcpy(im.data, keep, im.size);
    put_f32(&im, r1 + 20, NAN);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "anchor is not finite",
                      at(r1 + 20));
    memcpy(im.data, keep, im.size);
    rb_put_u32(im.data + r1 + 12, 1); /* flags */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "flags and reserved", at(r1 + 12));
    memcpy(im.data, keep, im.size);
    rb_put_u32(im.data + sec, 3); /* count: the size no longer matches */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 1, "section 'couplings'");
    memcpy(im.data, keep, im.size);
    rb_put_u32(im.data + sec, 0);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "0 couplings", at(sec));
    free(keep);
    free(im.data);

    /* Descriptions: couplings need fem; the checks run on pose_rig_create. */
    t.desc.fem = NULL;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_ARGUMENT);
    t.desc.fem = &t.fem;
    t.couplings[1].node = 9;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(pose_last_error(), "node 9 after node 9"));

    /* Without couplings: no section; the committed 0.1 seeds have none. */
    tiny_rig_init(&t, 1, 1);
    im = write_image(&t.desc);
    assert_int_equal(rb_find(im.data, SEC_COUPLINGS), -1);
    free(im.data);
    char path[1024];
    snprintf(path, sizeof path, "%s/valid_tiny_full.rig", POSE_RIG_CORPUS);
    assert_int_equal(pose_rig_load(path, &rig), POSE_OK);
    assert_int_equal(pose_rig_fem_couplings(rig, got, 3), 0);
    pose_rig_free(rig);
    /* the committed seeds with the section (tests/rigfile/make_seeds.c) */
    snprintf(path, sizeof path, "%s/valid_tiny_couplings.rig", POSE_RIG_CORPUS);
    assert_int_equal(pose_rig_load(path, &rig), POSE_OK);
    assert_int_equal(pose_rig_fem_couplings(rig, got, 3), 2);
    pose_rig_free(rig);
    snprintf(path, sizeof path, "%s/bad_coupling_node.rig", POSE_RIG_CORPUS);
    rig = (pose_rig *)1;
    assert_int_equal(pose_rig_load(path, &rig), POSE_ERR_INVALID_DATA);
    assert_null(rig);
    assert_non_null(strstr(pose_last_error(), "node 12 is not a tet vertex"));
}

/* The soft_couplings section (type 11, optional): round trip, what a state
 * makes of it, damage named with its record and byte, descriptions, and
 * rigs without it. */
static void test_soft_couplings(void **state)
{
    (void)state;
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    tiny_rig_add_soft_couplings(&t);
    image im = write_image(&t.desc);
    int e = rb_find(im.data, SEC_SOFT_COUPLINGS);
    assert_true(e >= 0);
    assert_int_equal(rb_u32(rb_entry(im.data, (uint32_t)e) + 4), 1); /* OPTIONAL: 0.1 skips it */
    assert_int_equal(rb_u64(rb_entry(im.data, (uint32_t)e) + 16), 64 + 128);
    const uint64_t sec = rb_offset(im.data, SEC_SOFT_COUPLINGS), r1 = sec + 64 + 40;
    assert_int_equal(rb_u32(im.data + sec), 2);
    pose_rig *rig;
    assert_int_equal(pose_rig_load_memory(im.data, im.size, NULL, &rig), POSE_OK);
    pose_fem_soft_coupling got[3];
    assert_int_equal(pose_rig_fem_soft_couplings(rig, NULL, 0, sizeof got[0]), 2);
    assert_int_equal(pose_rig_fem_soft_couplings(rig, got, 3, sizeof got[0]), 2);
    assert_memory_equal(got, t.soft_couplings, sizeof t.soft_couplings);
    assert_int_equal(pose_rig_fem_soft_couplings(rig, got, 3, sizeof got[0] - 1), 0);
    /* a later caller's larger element: the 0.2 part written, the rest left */
    struct {
        pose_fem_soft_coupling c;
        uint32_t later;
    } wide[2] = {{.later = 77}, {.later = 78}};
    assert_int_equal(pose_rig_fem_soft_couplings(rig, &wide[0].c, 2, sizeof wide[0]), 2);
    assert_memory_equal(&wide[1].c, &t.soft_couplings[1], sizeof wide[1].c);
    assert_int_equal(wide[0].later, 77);
    assert_int_equal(wide[1].later, 78);
    /* a state takes them: vertices 8-11 are in soft tets only */
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_int_equal(pose_fem_soft_coupling_count(st), 2);
    pose_state_free(st);
    pose_rig_free(rig);

    uint8_t *keep = malloc(im.size);
    assert_non_null(keep);
    memcpy(keep, im.data, im.size);
    rb_put_u32(im.data + r1, 12); /* node */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 3, "section 'soft_couplings'",
                      "soft coupling 1: node 12 is not a tet vertex (12)", at(r1));
    memcpy(im.data, keep, im.size);
    rb_put_u32(im.data + r1 + 8, 9); /* other[1] is the node */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "other node 1 (9) is the node",
                      at(r1 + 8));
    memcpy(im.data, keep, im.size);
    rb_put_u32(im.data + r1 + 8, 40); /* other[1] past the mesh */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "other node 1 (40)", at(r1 + 8));
    memcpy(im.data, keep, im.size);
    put_f32(&im, r1 + 24, NAN);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "weight 1 is not finite",
                      at(r1 + 24));
    memcpy(im.data, keep, im.size);
    put_f32(&im, r1 + 28, 0.25f);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "weights sum to 0.75", at(r1 + 20));
    memcpy(im.data, keep, im.size);
    put_f32(&im, r1 + 36, 0.0f);
    expect_load_error(im.data, im.size, POSE_ERR_INVALID_DATA, 2, "soft coupling 1: stiffness 0",
                      at(r1 + 36));
    memcpy(im.data, keep, im.size);
    rb_put_u32(im.data + sec, 4); /* count: the size no longer matches (3 fits the padding) */
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 1, "section 'soft_couplings'");
    memcpy(im.data, keep, im.size);
    rb_put_u32(im.data + sec, 0);
    rb_fix_crcs(im.data, im.size);
    expect_load_error(im.data, im.size, POSE_ERR_FORMAT, 2, "0 soft couplings", at(sec));
    free(keep);
    free(im.data);

    /* Descriptions: soft couplings need fem; the checks run on pose_rig_create. */
    t.desc.fem = NULL;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_ARGUMENT);
    t.desc.fem = &t.fem;
    t.soft_couplings[0].other[0] = 8;
    assert_int_equal(pose_rig_create(&t.desc, NULL, &rig), POSE_ERR_INVALID_DATA);
    assert_non_null(strstr(pose_last_error(), "soft coupling 0: other node 0 (8) is the node"));

    /* Without them: no section; the committed seeds. */
    tiny_rig_init(&t, 1, 1);
    im = write_image(&t.desc);
    assert_int_equal(rb_find(im.data, SEC_SOFT_COUPLINGS), -1);
    free(im.data);
    char path[1024];
    snprintf(path, sizeof path, "%s/valid_tiny_couplings.rig", POSE_RIG_CORPUS);
    assert_int_equal(pose_rig_load(path, &rig), POSE_OK);
    assert_int_equal(pose_rig_fem_soft_couplings(rig, got, 3, sizeof got[0]), 0);
    pose_rig_free(rig);
    snprintf(path, sizeof path, "%s/valid_tiny_soft_couplings.rig", POSE_RIG_CORPUS);
    assert_int_equal(pose_rig_load(path, &rig), POSE_OK);
    assert_int_equal(pose_rig_fem_soft_couplings(rig, got, 3, sizeof got[0]), 2);
    pose_rig_free(rig);
    snprintf(path, sizeof path, "%s/bad_soft_coupling_weights.rig", POSE_RIG_CORPUS);
    rig = (pose_rig *)1;
    assert_int_equal(pose_rig_load(path, &rig), POSE_ERR_INVALID_DATA);
    assert_null(rig);
    assert_non_null(strstr(pose_last_error(), "soft coupling 1: weights sum to 0.75"));
}

static void test_status_strings_and_version(void **state)
{
    (void)state;
    assert_string_equal(pose_status_string(POSE_OK), "success");
    assert_string_equal(pose_status_string(POSE_ERR_CHECKSUM), "checksum mismatch");
    assert_string_equal(pose_status_string((pose_status)-99), "unknown status");
    for (int s = -10; s <= 1; s++)
        assert_string_not_equal(pose_status_string((pose_status)s), "unknown status");
    assert_int_equal(pose_version(), POSE_VERSION_NUMBER);
    char v[32];
    snprintf(v, sizeof v, "%d.%d.%d", POSE_VERSION_MAJOR, POSE_VERSION_MINOR, POSE_VERSION_PATCH);
    assert_string_equal(pose_version_string(), v);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_invalid_arguments),
        cmocka_unit_test(test_io_errors),
        cmocka_unit_test(test_bad_magic),
        cmocka_unit_test(test_future_version),
        cmocka_unit_test(test_old_version_zero),
        cmocka_unit_test(test_header_crc_and_fields),
        cmocka_unit_test(test_truncation_at_each_section),
        cmocka_unit_test(test_crc_mismatch_in_each_section),
        cmocka_unit_test(test_misaligned_and_overlapping_sections),
        cmocka_unit_test(test_section_table_entries),
        cmocka_unit_test(test_section_sizes_and_counts),
        cmocka_unit_test(test_out_of_range_indices),
        cmocka_unit_test(test_parent_after_child),
        cmocka_unit_test(test_bad_weights),
        cmocka_unit_test(test_bad_barycentric_and_positions),
        cmocka_unit_test(test_bad_names),
        cmocka_unit_test(test_description_errors),
        cmocka_unit_test(test_round_trip_all_paths),
        cmocka_unit_test(test_rest_local_from_rest_model),
        cmocka_unit_test(test_allocation_failures),
        cmocka_unit_test(test_clinical_round_trip),
        cmocka_unit_test(test_clinical_old_rigs_load),
        cmocka_unit_test(test_clinical_damage),
        cmocka_unit_test(test_clinical_description_errors),
        cmocka_unit_test(test_couplings),
        cmocka_unit_test(test_soft_couplings),
        cmocka_unit_test(test_status_strings_and_version),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
