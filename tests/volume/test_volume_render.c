/* SPDX-License-Identifier: Apache-2.0
 * pose-render --slices on the CT baked by volume_ct_bake: the image gains
 * the axial, coronal and sagittal slices of the rig's scan beside the
 * model. At rest the slice panel is, pixel for pixel, what the shared
 * colouring (examples/volume/vol_slices*.c) makes of the scan posed by
 * libpose at rest, and it shows label colours; flexing hip_l changes it.
 * argv: pose-render RIG */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <pose/pose.h>

#include "ex_volume_posed.h"
#include "vol_slices.h"
#include "vol_slices_image.h"

#define SIZE 320
#define GAP 8 /* pose-render's SLICES_GAP */

static const char *render_bin, *rig_path;

typedef struct image {
    png_uint_32 w, h;
    unsigned char *px; /* RGBA */
} image;

static image render(const char *name, const char *pose)
{
    char path[2048], cmd[4096];
    snprintf(path, sizeof path, "%s/%s.png", getenv("POSE_TEST_TMP"), name);
    snprintf(cmd, sizeof cmd, "'%s' '%s' --slices --size %dx%d %s -o '%s' > /dev/null", render_bin, rig_path, SIZE,
             SIZE, pose, path);
    assert_int_equal(system(cmd), 0);
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    assert_true(png_image_begin_read_from_file(&pi, path));
    pi.format = PNG_FORMAT_RGBA;
    image im = {pi.width, pi.height, malloc(PNG_IMAGE_SIZE(pi))};
    assert_true(png_image_finish_read(&pi, NULL, im.px, 0, NULL));
    return im;
}

static const unsigned char *at(const image *im, int x, int y)
{
    return im->px + 4 * ((size_t)y * im->w + (size_t)x);
}

static void test_slices_beside_model(void **state)
{
    (void)state;
    /* The expected panel: the scan posed at rest, coloured alike. */
    pose_rig *rig;
    pose_state *st;
    assert_int_equal(pose_rig_load(rig_path, &rig), POSE_OK);
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    assert_int_equal(pose_apply(st), POSE_OK);
    ex_volume_posed v;
    char err[256];
    assert_int_equal(ex_volume_posed_open(&v, rig, 0, err, sizeof err), 0);
    assert_int_equal(ex_volume_posed_update(&v, st, err, sizeof err), 0);
    const int c[3] = {v.n[0] / 2, v.n[1] / 2, v.n[2] / 2};
    static const uint8_t bg[4] = {33, 36, 43, 255};
    ex_image want;
    assert_int_equal(ex_volume_slices_image(&want, v.hu, v.labels, v.n, v.spacing, c, EX_VOLUME_LEVEL,
                                            EX_VOLUME_WIDTH, ex_volume_slices_zoom(v.n, v.spacing, SIZE), bg),
                     0);

    image rest = render("rest", "");
    assert_int_equal(rest.w, SIZE + GAP + want.width);
    assert_int_equal(rest.h, want.height > SIZE ? want.height : SIZE);
    size_t differ = 0, labelled = 0;
    for (int y = 0; y < want.height; y++)
        for (int x = 0; x < want.width; x++) {
            const unsigned char *got = at(&rest, SIZE + GAP + x, y), *exp = want.rgba + 4 * ((size_t)y * want.width + x);
            differ += memcmp(got, exp, 3) != 0;
            labelled += got[0] != got[1] || got[1] != got[2];
        }
    printf("slice panel %dx%d: %zu pixels differ, %zu in label colours\n", want.width, want.height, differ,
           labelled);
    assert_int_equal(differ, 0);
    assert_true(labelled > (size_t)want.width * want.height / 20);

    /* A known place: the first labelled voxel along the axial slice's middle
     * row, drawn in its label's colour where the layout puts it. */
    int px[3], zoom = ex_volume_slices_zoom(v.n, v.spacing, SIZE);
    ex_volume_slice_pixels(v.spacing, zoom, px);
    const int j = c[1];
    int i = 0;
    while (i < v.n[0] && !v.labels[((size_t)c[2] * v.n[1] + j) * v.n[0] + i])
        i++;
    assert_true(i < v.n[0]);
    const size_t vox = ((size_t)c[2] * v.n[1] + j) * v.n[0] + i;
    unsigned char rgb[3];
    ex_volume_voxel_rgb(v.hu + vox, v.labels + vox, EX_VOLUME_LEVEL, EX_VOLUME_WIDTH, rgb);
    const unsigned char *p = at(&rest, SIZE + GAP + i * px[0] + px[0] / 2, (v.n[1] - 1 - j) * px[1] + px[1] / 2);
    assert_memory_equal(p, rgb, 3);
    assert_true(rgb[0] != rgb[1] || rgb[1] != rgb[2]);

    /* Flexing the left hip changes the slices (the femur moves through them). */
    image bent = render("bent", "--pose hip_l=45,0,0");
    assert_int_equal(bent.w, rest.w);
    size_t moved = 0;
    for (int y = 0; y < want.height; y++)
        for (int x = 0; x < want.width; x++)
            moved += memcmp(at(&rest, SIZE + GAP + x, y), at(&bent, SIZE + GAP + x, y), 3) != 0;
    printf("hip_l 45 deg: %zu slice pixels changed\n", moved);
    assert_true(moved > 500);

    free(rest.px), free(bent.px);
    ex_image_free(&want);
    ex_volume_posed_close(&v);
    pose_state_free(st);
    pose_rig_free(rig);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s pose-render RIG\n", argv[0]);
        return 2;
    }
    render_bin = argv[1], rig_path = argv[2];
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_slices_beside_model)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
