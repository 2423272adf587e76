/* SPDX-License-Identifier: Apache-2.0
 * pose.h's 0.2 additions for hosts and bindings: options structs that carry
 * their size (and the 0.1 entry points kept for programs built before it),
 * bounding boxes of rest and posed tissues, the rig format version. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fixture.h"
#include "pose/pose.h"

/* A program built against the 0.1 headers: these names, these layouts. */
#undef pose_rig_load_memory
#undef pose_state_create_ex
typedef struct load_options_0_1 {
    pose_allocator allocator;
    uint32_t flags;
} load_options_0_1;
typedef struct state_options_0_1 {
    pose_allocator allocator;
    int threads;
    pose_method method;
} state_options_0_1;
pose_status pose_rig_load_memory(const void *data, size_t size, const load_options_0_1 *options, pose_rig **out);
pose_status pose_state_create_ex(const pose_rig *rig, const state_options_0_1 *options, pose_state **out);

static void test_format_version(void **unused)
{
    (void)unused;
    assert_int_equal(POSE_RIG_FORMAT_VERSION, 1);
    assert_int_equal(pose_rig_format_version(NULL), POSE_RIG_FORMAT_VERSION);
    fx_options o = fx_defaults();
    pose_rig *rig = fx_bar(&o);
    assert_int_equal(pose_rig_format_version(rig), POSE_RIG_FORMAT_VERSION);
    pose_rig_free(rig);
}

static void test_options_size(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    pose_rig *rig = fx_bar(&o);
    pose_state *st = NULL;
    pose_state_options full = {.size = sizeof full, .threads = 1, .method = POSE_DQS};
    assert_int_equal(pose_state_create_ex_sized(rig, &full, &st), POSE_OK);
    assert_int_equal(pose_get_method(st), POSE_DQS);
    pose_state_free(st);
    /* size 0 still reads the 0.1 fields: the method is taken, a bad thread count refused. */
    pose_state_options zero = {.method = POSE_COR};
    assert_int_equal(pose_state_create_ex_sized(rig, &zero, &st), POSE_OK);
    assert_int_equal(pose_get_method(st), POSE_COR);
    pose_state_free(st);
    zero.threads = -1;
    assert_int_equal(pose_state_create_ex_sized(rig, &zero, &st), POSE_ERR_INVALID_ARGUMENT);
    /* A size below the 0.2 layout is a caller's mistake, named. */
    pose_state_options small = {.size = POSE_STATE_OPTIONS_SIZE_0_2 - 1};
    assert_int_equal(pose_state_create_ex_sized(rig, &small, &st), POSE_ERR_INVALID_ARGUMENT);
    assert_null(st);
    assert_non_null(strstr(pose_last_error(), "options.size"));

    /* Loading: the size is checked before the file is looked at. */
    pose_rig *loaded = NULL;
    pose_load_options lo = {.size = 1};
    assert_int_equal(pose_rig_load_ex_sized("/no/such.rig", &lo, &loaded), POSE_ERR_INVALID_ARGUMENT);
    lo.size = sizeof lo;
    assert_int_equal(pose_rig_load_ex_sized("/no/such.rig", &lo, &loaded), POSE_ERR_IO);
    assert_null(loaded);
    pose_rig_free(rig);
}

static void test_0_1_entry_points(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    pose_rig *rig = fx_bar(&o);
    /* The 0.1 symbol reads the 0.1 layout: method and threads land where they were. */
    state_options_0_1 old = {.threads = 2, .method = POSE_DQS};
    pose_state *st = NULL;
    assert_int_equal(pose_state_create_ex(rig, &old, &st), POSE_OK);
    assert_int_equal(pose_get_method(st), POSE_DQS);
    pose_state_free(st);
    old.threads = -3;
    assert_int_equal(pose_state_create_ex(rig, &old, &st), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "threads = -3"));
    /* ... and the load flags: a borrowed buffer must be aligned, so POSE_LOAD_BORROW was read. */
    static _Alignas(64) unsigned char buffer[128];
    load_options_0_1 borrow = {.flags = POSE_LOAD_BORROW};
    pose_rig *loaded = NULL;
    assert_int_equal(pose_rig_load_memory(buffer + 1, 64, &borrow, &loaded), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "aligned"));
    pose_rig_free(rig);
}

static void test_bounds(void **unused)
{
    (void)unused;
    fx_options o = fx_defaults();
    pose_rig *rig = fx_bar(&o);
    float lo[3], hi[3];
    /* The skin has a vertex on every corner of the 4 x 1 x 1 bar. */
    assert_int_equal(pose_rig_bounds(rig, 0, lo, hi), POSE_OK);
    const float want_lo[3] = {0, 0, 0}, want_hi[3] = {4, 1, 1};
    for (int k = 0; k < 3; k++) {
        assert_true(lo[k] == want_lo[k]);
        assert_true(hi[k] == want_hi[k]);
    }
    /* Every tissue: the inner points lie inside the skin's box. */
    float all_lo[3], all_hi[3];
    assert_int_equal(pose_rig_bounds(rig, -1, all_lo, all_hi), POSE_OK);
    assert_memory_equal(all_lo, lo, sizeof lo);
    assert_memory_equal(all_hi, hi, sizeof hi);
    assert_int_equal(pose_rig_bounds(rig, 2, lo, hi), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_rig_bounds(rig, -2, lo, hi), POSE_ERR_INVALID_ARGUMENT);

    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_int_equal(pose_state_bounds(st, -1, lo, hi), POSE_OK); /* rest before the first apply */
    assert_memory_equal(lo, all_lo, sizeof lo);
    assert_memory_equal(hi, all_hi, sizeof hi);
    /* Bend the second joint 90 degrees about z: the far cubes swing out of the rest box in y. */
    const float bend[3] = {0, 0, 90};
    assert_int_equal(pose_set_joint_euler(st, 1, bend, POSE_EULER_XYZ), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    assert_int_equal(pose_state_bounds(st, 0, lo, hi), POSE_OK);
    size_t n;
    const float *xyz = pose_tissue_positions(st, 0, &n);
    float ref_lo[3] = {INFINITY, INFINITY, INFINITY}, ref_hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < n; v++)
        for (int k = 0; k < 3; k++) {
            ref_lo[k] = fminf(ref_lo[k], xyz[3 * v + k]);
            ref_hi[k] = fmaxf(ref_hi[k], xyz[3 * v + k]);
        }
    assert_memory_equal(lo, ref_lo, sizeof lo);
    assert_memory_equal(hi, ref_hi, sizeof hi);
    assert_true(hi[1] > 2.0f || lo[1] < -1.0f); /* the bent part reaches well out of [0, 1] in y */
    assert_true(hi[0] < 3.5f);                  /* and no longer to x = 4 */
    assert_int_equal(pose_state_bounds(NULL, 0, lo, hi), POSE_ERR_INVALID_ARGUMENT);
    pose_state_free(st);
    pose_rig_free(rig);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_format_version),
        cmocka_unit_test(test_options_size),
        cmocka_unit_test(test_0_1_entry_points),
        cmocka_unit_test(test_bounds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
