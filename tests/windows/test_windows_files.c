/* SPDX-License-Identifier: Apache-2.0 */
/* What only Windows has: a rig file whose UTF-8 name is not in the ANSI code
 * page (platform_map_win32.c opens it as UTF-16), mapped and read; and the
 * error message staying per thread (error.c's _Thread_local under mingw). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <wchar.h>

#include <cmocka.h>

#include "pose/pose.h"
#include "rt_thread.h"
#include "tiny_rig.h"

/* "rig-\u00fc\u4f53.rig" in the test's temporary folder, as UTF-8 and UTF-16. */
static void unicode_path(char *utf8, size_t n8, wchar_t *utf16, size_t n16)
{
    const char *dir = getenv("POSE_TEST_TMP");
    assert_non_null(dir);
    snprintf(utf8, n8, "%s/rig-\xc3\xbc\xe4\xbd\x93.rig", dir);
    size_t len = strlen(dir);
    assert_true(len + 16 < n16);
    for (size_t i = 0; i < len; i++)
        utf16[i] = (wchar_t)(unsigned char)dir[i]; /* the folder is ASCII */
    wcscpy(utf16 + len, L"/rig-\u00fc\u4f53.rig");
}

static void test_unicode_path_maps_and_reads(void **state)
{
    (void)state;
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    void *image;
    size_t size;
    assert_int_equal(pose_rig_write_memory(&t.desc, NULL, &image, &size), POSE_OK);
    char path[512];
    wchar_t wpath[512];
    unicode_path(path, sizeof path, wpath, sizeof wpath / sizeof wpath[0]);
    FILE *f = _wfopen(wpath, L"wb");
    assert_non_null(f);
    assert_int_equal(fwrite(image, 1, size, f), size);
    assert_int_equal(fclose(f), 0);
    free(image);

    const uint32_t flags[2] = {0, POSE_LOAD_NO_MMAP};
    for (int i = 0; i < 2; i++) {
        pose_load_options o = {.size = sizeof o, .flags = flags[i]};
        pose_rig *rig;
        if (pose_rig_load_ex(path, &o, &rig) != POSE_OK)
            fail_msg("%s: %s", path, pose_last_error());
        assert_int_equal(pose_rig_joint_count(rig), t.desc.joint_count);
        pose_rig_free(rig);
    }
    assert_int_equal(_wremove(wpath), 0); /* no view left open */
}

static void test_missing_and_folder(void **state)
{
    (void)state;
    pose_rig *rig;
    char path[512];
    snprintf(path, sizeof path, "%s/missing.rig", getenv("POSE_TEST_TMP"));
    assert_int_equal(pose_rig_load(path, &rig), POSE_ERR_IO);
    assert_non_null(strstr(pose_last_error(), "cannot open"));
    assert_int_equal(pose_rig_load(getenv("POSE_TEST_TMP"), &rig), POSE_ERR_IO);
    assert_null(rig);
}

static void *fail_on_thread(void *arg)
{
    pose_rig *rig;
    *(pose_status *)arg = pose_rig_load("missing-on-a-thread.rig", &rig);
    return NULL;
}

static void test_error_is_per_thread(void **state)
{
    (void)state;
    pose_set_last_error("main thread");
    pose_status st = POSE_OK;
    pose__thread t;
    assert_int_equal(pose__thread_start(&t, fail_on_thread, &st), 0);
    pose__thread_join(&t);
    assert_int_equal(st, POSE_ERR_IO);
    assert_string_equal(pose_last_error(), "main thread");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_unicode_path_maps_and_reads),
        cmocka_unit_test(test_missing_and_folder),
        cmocka_unit_test(test_error_is_per_thread),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
