/* SPDX-License-Identifier: Apache-2.0
 *
 * The example tools as a user runs them: pose-render under OSMesa makes
 * images that are not blank, whose silhouette follows the pose, and whose
 * LBS and CoR pictures of a strong twist differ where the paper says (LBS
 * collapses the bar at the joint); bad input gives a clear message and a
 * non-zero exit; pose-view without a display refuses plainly; the
 * quickstart runs; pose-export writes files other tools can read.
 *
 * argv: pose-render pose-synth pose-view|- pose-export pose-quickstart MAP
 * (MAP: a bridge mapping from the CMU skeleton onto the bar)
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

static const char *render_bin, *synth_bin, *view_bin, *export_bin, *quickstart_bin, *bar_map;
static char tmp[2048], bar[2300];

/* Run a shell command; its stdout+stderr go to `log`. Returns the exit status. */
static int run(const char *log, const char *fmt, ...)
{
    char cmd[8192];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    assert_true(n > 0 && (size_t)n < sizeof cmd - 64);
    snprintf(cmd + n, sizeof cmd - (size_t)n, " >'%s' 2>&1", log);
    int st = system(cmd);
    assert_true(st != -1 && WIFEXITED(st));
    return WEXITSTATUS(st);
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    static char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    return buf;
}

typedef struct image {
    png_uint_32 w, h;
    uint8_t *px; /* RGBA */
} image;

static image load_png(const char *path)
{
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    assert_true(png_image_begin_read_from_file(&pi, path));
    pi.format = PNG_FORMAT_RGBA;
    image im = {pi.width, pi.height, malloc(PNG_IMAGE_SIZE(pi))};
    assert_non_null(im.px);
    assert_true(png_image_finish_read(&pi, NULL, im.px, 0, NULL));
    return im;
}

/* Foreground mask: pixels that differ from the corner (background) colour. */
static int is_fg(const image *im, size_t x, size_t y)
{
    const uint8_t *bg = im->px, *p = im->px + 4 * (y * im->w + x);
    return abs(p[0] - bg[0]) + abs(p[1] - bg[1]) + abs(p[2] - bg[2]) > 24;
}

static double coverage(const image *im)
{
    size_t hit = 0;
    for (size_t y = 0; y < im->h; y++)
        for (size_t x = 0; x < im->w; x++)
            hit += (size_t)is_fg(im, x, y);
    return (double)hit / (double)(im->w * im->h);
}

static int setup(void **state)
{
    (void)state;
    const char *t = getenv("POSE_TEST_TMP");
    snprintf(tmp, sizeof tmp, "%s", t ? t : "/tmp");
    snprintf(bar, sizeof bar, "%s/bar.rig", tmp);
    char log[2400];
    snprintf(log, sizeof log, "%s/synth.log", tmp);
    return run(log, "'%s' bar -o '%s'", synth_bin, bar) == 0 ? 0 : -1;
}

/* ---------------------------------------------------------- bad input first */

static void test_missing_rig(void **state)
{
    (void)state;
    char log[2400];
    snprintf(log, sizeof log, "%s/missing.log", tmp);
    assert_int_not_equal(run(log, "'%s' '%s/no_such.rig' -o '%s/x.png'", render_bin, tmp, tmp), 0);
    const char *msg = slurp(log);
    assert_non_null(strstr(msg, "pose-render: cannot load rig"));
    assert_non_null(strstr(msg, "no_such.rig"));
    assert_int_not_equal(run(log, "'%s' '%s/no_such.rig' --obj '%s/x.obj'", export_bin, tmp, tmp), 0);
    assert_non_null(strstr(slurp(log), "no_such.rig"));
}

static void test_not_a_rig(void **state)
{
    (void)state;
    char log[2400], path[2400];
    snprintf(path, sizeof path, "%s/garbage.rig", tmp);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs("this is not a rig file, it is text of some length to pass any size check ...", f);
    fclose(f);
    snprintf(log, sizeof log, "%s/garbage.log", tmp);
    assert_int_equal(run(log, "'%s' '%s' -o '%s/x.png'", render_bin, path, tmp), 1);
    assert_non_null(strstr(slurp(log), "garbage.rig"));
}

static void test_bad_options(void **state)
{
    (void)state;
    char log[2400];
    snprintf(log, sizeof log, "%s/opts.log", tmp);
    assert_int_equal(run(log, "'%s'", render_bin), 2);
    assert_non_null(strstr(slurp(log), "no rig given"));
    assert_int_equal(run(log, "'%s' '%s' --size 10x10", render_bin, bar), 2);
    assert_non_null(strstr(slurp(log), "--size"));
    assert_int_equal(run(log, "'%s' '%s' --method foo", render_bin, bar), 2);
    assert_int_equal(run(log, "'%s' '%s' --frames 0,1", render_bin, bar), 2);
    assert_non_null(strstr(slurp(log), "--frames needs --source"));
    assert_int_equal(run(log, "'%s' '%s' --pose nosuchjoint=0,0,0 -o '%s/x.png'", render_bin, bar, tmp), 1);
    assert_non_null(strstr(slurp(log), "no joint 'nosuchjoint'"));
    assert_int_equal(run(log, "'%s' '%s' --pose joint1=1,2 -o '%s/x.png'", render_bin, bar, tmp), 1);
    assert_non_null(strstr(slurp(log), "three angles"));
    assert_int_equal(run(log, "'%s' '%s' -o '%s/no/such/dir/x.png'", render_bin, bar, tmp), 1);
    assert_non_null(strstr(slurp(log), "cannot create"));
}

static void test_broken_source(void **state)
{
    (void)state;
    char log[2400], path[2400];
    snprintf(path, sizeof path, "%s/broken.bvh", tmp);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition", f); /* truncated */
    fclose(f);
    snprintf(log, sizeof log, "%s/broken.log", tmp);
    assert_int_equal(run(log, "'%s' '%s' --source '%s' --frames 0 -o '%s/frames'", render_bin, bar, path, tmp), 1);
    assert_non_null(strstr(slurp(log), "broken.bvh"));
    assert_int_equal(
        run(log, "'%s' '%s' --source '%s/none.bvh' --frames 0 -o '%s/frames'", render_bin, bar, tmp, tmp), 1);
    assert_non_null(strstr(slurp(log), "none.bvh"));
}

static void test_view_without_display(void **state)
{
    (void)state;
    if (!strcmp(view_bin, "-"))
        skip(); /* pose-view not built (no GLFW) */
    char log[2400];
    snprintf(log, sizeof log, "%s/view.log", tmp);
    assert_int_equal(run(log, "env -u DISPLAY -u WAYLAND_DISPLAY '%s' '%s'", view_bin, bar), 1);
    assert_non_null(strstr(slurp(log), "no display"));
    assert_int_not_equal(run(log, "env -u DISPLAY -u WAYLAND_DISPLAY '%s' '%s/none.rig'", view_bin, tmp), 0);
    assert_non_null(strstr(slurp(log), "none.rig"));
}

/* With a virtual X server (xvfb-run), the viewer opens, draws and closes cleanly. */
static void test_view_under_xvfb(void **state)
{
    (void)state;
    char log[2400];
    snprintf(log, sizeof log, "%s/xvfb.log", tmp);
    if (!strcmp(view_bin, "-") || run(log, "command -v xvfb-run") != 0)
        skip(); /* no viewer, or no Xvfb (Debian package xvfb) */
    /* Under ASan, leaks are not checked here: the GL driver is unloaded at exit, so LeakSanitizer
     * cannot name (or suppress) the driver's own allocations. pose-render covers the shared code. */
    assert_int_equal(run(log, "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" "
                              "xvfb-run -a -s '-screen 0 640x480x24' '%s' '%s' --size 320x240 --quit-after 5 "
                              "--pose joint2=0,45,0",
                         view_bin, bar),
                     0);
    const char *out = slurp(log);
    printf("%s", out);
    assert_non_null(strstr(out, "pose-view: 5 frames in"));
    assert_non_null(strstr(out, "method CoR"));
    /* --json: the session as one JSON object, with what the joint limits clamped. */
    assert_int_equal(run(log, "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" "
                              "xvfb-run -a -s '-screen 0 640x480x24' '%s' '%s' --size 320x240 --quit-after 3 "
                              "--json --pose joint2=0,170,0",
                         view_bin, bar),
                     0);
    out = slurp(log);
    printf("%s", out);
    assert_non_null(strstr(out, "{\"rig\": "));
    assert_non_null(strstr(out, "\"frames\": 3, "));
    assert_non_null(strstr(out, "\"method\": \"CoR\""));
    assert_non_null(strstr(out, "\"clamped\": [\"--pose joint2=0,170,0: joint 2 'joint2': y 170.00 clamped to 150.00"));
}

/* The viewer driven live by recorded devices through the bridge's thread: poses arrive. */
static void test_view_live_sources(void **state)
{
    (void)state;
    char log[2400];
    snprintf(log, sizeof log, "%s/xvfb_live.log", tmp);
    if (!strcmp(view_bin, "-") || run(log, "command -v xvfb-run") != 0)
        skip();
    assert_int_equal(run(log, "'%s' --help", render_bin), 0);
    if (strstr(slurp(log), "built without the bridge"))
        skip();
    const char *data = getenv("POSE_DATA_DIR");
    assert_non_null(data);
    static const char *sources[3][2] = {
        {"hid/mannequin_arm_raise.hid", "hid_mannequin_bar.json"},
        {"can-rig/sit_stand_arm_raise.log", "can_rig_bar.json"},
        {"mocap/cmu-bvh/131_01.bvh", "cmu131_arm_to_bar.json"},
    };
    for (int i = 0; i < 3; i++) {
        /* bar_map lives in bridge/maps/; its siblings are the other mappings. */
        char maps[2048];
        snprintf(maps, sizeof maps, "%s", bar_map);
        char *slash = strrchr(maps, '/');
        assert_non_null(slash);
        *slash = '\0';
        assert_int_equal(run(log,
                             "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" "
                             "xvfb-run -a -s '-screen 0 640x480x24' '%s' '%s' --size 200x150 --quit-after 40 "
                             "--source '%s/%s' --map '%s/%s'",
                             view_bin, bar, data, sources[i][0], maps, sources[i][1]),
                         0);
        const char *out = slurp(log);
        printf("%s", out);
        const char *src = strstr(out, ", source ");
        assert_non_null(src);
        /* Clips report the frame reached, devices the poses received: either way not zero. */
        const char *frame = strstr(src, "frame "), *poses = strstr(src, " poses");
        if (i == 2) {
            assert_non_null(frame);
            assert_true(atol(frame + 6) > 0);
        } else {
            assert_non_null(poses);
            const char *p = poses;
            while (p > src && p[-1] >= '0' && p[-1] <= '9')
                p--;
            assert_true(atol(p) > 0);
        }
    }
}

/* ---------------------------------------------------------------- images */

static void test_rest_image_not_blank(void **state)
{
    (void)state;
    char log[2400], png[2400];
    snprintf(png, sizeof png, "%s/rest.png", tmp);
    snprintf(log, sizeof log, "%s/rest.log", tmp);
    assert_int_equal(run(log, "'%s' '%s' --size 320x240 -o '%s' --json", render_bin, bar, png), 0);
    assert_non_null(strstr(slurp(log), "\"ok\": true"));
    image im = load_png(png);
    assert_int_equal(im.w, 320);
    assert_int_equal(im.h, 240);
    double c = coverage(&im);
    printf("rest image coverage %.3f\n", c);
    assert_true(c > 0.05 && c < 0.9); /* the model is there and framed, not clipped */
    /* Shaded, not flat: many distinct foreground intensities. */
    int seen[256] = {0}, distinct = 0;
    for (size_t i = 0; i < (size_t)im.w * im.h; i++)
        if (is_fg(&im, i % im.w, i / im.w))
            seen[im.px[4 * i + 1]] = 1;
    for (int i = 0; i < 256; i++)
        distinct += seen[i];
    assert_true(distinct > 20);
    free(im.px);
}

/* A scripted pose sequence: the silhouette must move, and by more for a larger bend. */
static void test_silhouette_follows_pose(void **state)
{
    (void)state;
    char log[2400];
    snprintf(log, sizeof log, "%s/seq.log", tmp);
    image im[3];
    const int angles[3] = {0, 30, 80};
    for (int i = 0; i < 3; i++) {
        char png[2400];
        snprintf(png, sizeof png, "%s/seq_%d.png", tmp, i);
        /* Fixed camera (side view of the bar), so images are comparable. */
        assert_int_equal(run(log,
                             "'%s' '%s' --size 320x240 --azimuth 90 --elevation 0 --fit rest "
                             "--pose joint2=0,%d,0 -o '%s'",
                             render_bin, bar, angles[i], png),
                         0);
        im[i] = load_png(png);
    }
    size_t diff[2] = {0, 0};
    for (int k = 0; k < 2; k++)
        for (size_t y = 0; y < im[0].h; y++)
            for (size_t x = 0; x < im[0].w; x++)
                diff[k] += (size_t)(is_fg(&im[0], x, y) != is_fg(&im[k + 1], x, y));
    /* The silhouette's centroid moves away from rest, further for the larger bend. */
    double c[3][2];
    for (int i = 0; i < 3; i++) {
        double sx = 0.0, sy = 0.0, n = 0.0;
        for (size_t y = 0; y < im[i].h; y++)
            for (size_t x = 0; x < im[i].w; x++)
                if (is_fg(&im[i], x, y)) {
                    sx += (double)x;
                    sy += (double)y;
                    n += 1.0;
                }
        assert_true(n > 0.0);
        c[i][0] = sx / n;
        c[i][1] = sy / n;
    }
    double shift30 = hypot(c[1][0] - c[0][0], c[1][1] - c[0][1]), shift80 = hypot(c[2][0] - c[0][0], c[2][1] - c[0][1]);
    printf("silhouette pixels changed: %zu (30 deg), %zu (80 deg); centroid moved %.1f px, %.1f px\n", diff[0],
           diff[1], shift30, shift80);
    assert_true(diff[0] > 200 && diff[1] > 200);
    assert_true(shift30 > 2.0);
    assert_true(shift80 > shift30 + 2.0);
    for (int i = 0; i < 3; i++)
        free(im[i].px);
}

/* A real clip replayed through the bridge: the bar follows the CMU walk's right arm. */
static void test_silhouette_follows_replay(void **state)
{
    (void)state;
    char log[2400], dir[2400];
    snprintf(log, sizeof log, "%s/replay.log", tmp);
    assert_int_equal(run(log, "'%s' --help", render_bin), 0);
    if (strstr(slurp(log), "built without the bridge"))
        skip();
    const char *data = getenv("POSE_DATA_DIR");
    assert_non_null(data);
    snprintf(dir, sizeof dir, "%s/replay", tmp);
    /* Frames past the clip's end are refused before anything is drawn. */
    assert_int_equal(run(log, "'%s' '%s' --source '%s/mocap/cmu-bvh/131_01.bvh' --map '%s' --frames 999999 -o '%s'",
                         render_bin, bar, data, bar_map, dir),
                     1);
    assert_non_null(strstr(slurp(log), "past the end"));
    static const long frames[3] = {101, 161, 221};
    assert_int_equal(run(log,
                         "'%s' '%s' --source '%s/mocap/cmu-bvh/131_01.bvh' --map '%s' --frames 101-221:60 "
                         "--size 240x240 -o '%s'",
                         render_bin, bar, data, bar_map, dir),
                     0);
    image im[3];
    for (int i = 0; i < 3; i++) {
        char png[2500];
        snprintf(png, sizeof png, "%s/frame_%05ld.png", dir, frames[i]);
        im[i] = load_png(png);
        assert_true(coverage(&im[i]) > 0.01);
    }
    for (int k = 0; k < 2; k++) {
        size_t diff = 0;
        for (size_t y = 0; y < im[0].h; y++)
            for (size_t x = 0; x < im[0].w; x++)
                diff += (size_t)(is_fg(&im[k], x, y) != is_fg(&im[k + 1], x, y));
        printf("replay: silhouette pixels changed from frame %ld to %ld: %zu\n", frames[k], frames[k + 1], diff);
        assert_true(diff > 300); /* a quarter of a gait cycle apart */
    }
    for (int i = 0; i < 3; i++)
        free(im[i].px);
}

/* Device recordings picked by recorded time (--times): the HID mannequin's and
 * the CAN rig's right leg drive the bar from seated (hip and knee bent) to
 * standing; the bridge replays each recording as fast as possible up to the
 * time asked for. */
static void test_silhouette_follows_recordings(void **state)
{
    (void)state;
    char log[2400], maps[2048];
    snprintf(log, sizeof log, "%s/recordings.log", tmp);
    assert_int_equal(run(log, "'%s' --help", render_bin), 0);
    if (strstr(slurp(log), "built without the bridge"))
        skip();
    const char *data = getenv("POSE_DATA_DIR");
    assert_non_null(data);
    snprintf(maps, sizeof maps, "%s", bar_map); /* bar_map's siblings in bridge/maps/ */
    char *slash = strrchr(maps, '/');
    assert_non_null(slash);
    *slash = '\0';
    static const struct {
        const char *source, *map, *times;
        double t[2];
    } rec[2] = {
        {"hid/mannequin_sit_to_stand.hid", "hid_mannequin_bar.json", "0.5,6", {0.5, 6.0}}, /* 8 s long */
        {"can-rig/sit_stand_arm_raise.log", "can_rig_bar.json", "0.5,4", {0.5, 4.0}},      /* 10 s long */
    };
    /* Invalid first: a time past the recording's end, and --frames on a recording. */
    assert_int_equal(run(log, "'%s' '%s' --source '%s/%s' --map '%s/%s' --times 0,60 -o '%s/rec_bad'", render_bin,
                         bar, data, rec[0].source, maps, rec[0].map, tmp),
                     1);
    assert_non_null(strstr(slurp(log), "past the end of the recording"));
    assert_int_equal(run(log, "'%s' '%s' --source '%s/%s' --map '%s/%s' --frames 0 -o '%s/rec_bad'", render_bin, bar,
                         data, rec[1].source, maps, rec[1].map, tmp),
                     1);
    assert_non_null(strstr(slurp(log), "--times"));
    for (int r = 0; r < 2; r++) {
        char dir[2400];
        snprintf(dir, sizeof dir, "%s/rec_%d", tmp, r);
        assert_int_equal(run(log, "'%s' '%s' --source '%s/%s' --map '%s/%s' --times %s --size 240x240 -o '%s' --json",
                             render_bin, bar, data, rec[r].source, maps, rec[r].map, rec[r].times, dir),
                         0);
        char stamp[64];
        snprintf(stamp, sizeof stamp, "\"time_s\": %g,", rec[r].t[1]);
        assert_non_null(strstr(slurp(log), stamp));
        image im[2];
        for (int i = 0; i < 2; i++) {
            char png[2500];
            snprintf(png, sizeof png, "%s/time_%08.3f.png", dir, rec[r].t[i]);
            im[i] = load_png(png);
            assert_true(coverage(&im[i]) > 0.01);
        }
        size_t diff = 0;
        for (size_t y = 0; y < im[0].h; y++)
            for (size_t x = 0; x < im[0].w; x++)
                diff += (size_t)(is_fg(&im[0], x, y) != is_fg(&im[1], x, y));
        printf("%s: silhouette pixels changed from %.1f s to %.1f s: %zu\n", rec[r].source, rec[r].t[0], rec[r].t[1],
               diff);
        assert_true(diff > 300); /* seated (hip and knee bent 90 degrees) against standing */
        for (int i = 0; i < 2; i++)
            free(im[i].px);
    }
}

/*
 * Candy wrapper: a 135 degree twist of the bar about its axis makes LBS
 * collapse the cross-section at the joint; CoR keeps it. Seen from the side,
 * the silhouette's height at the joint's column shrinks under LBS only.
 */
static double waist_ratio(const image *im)
{
    /* Column heights of the foreground; the waist is the thinnest column in
     * the middle half relative to the median column height. */
    size_t *hgt = calloc(im->w, sizeof *hgt), first = im->w, last = 0;
    for (size_t x = 0; x < im->w; x++) {
        for (size_t y = 0; y < im->h; y++)
            hgt[x] += (size_t)is_fg(im, x, y);
        if (hgt[x] > 2) {
            if (first == im->w)
                first = x;
            last = x;
        }
    }
    assert_true(last > first + 20);
    size_t span = last - first, lo = first + span / 4, hi = last - span / 4, minh = im->h;
    for (size_t x = lo; x <= hi; x++)
        minh = hgt[x] < minh ? hgt[x] : minh;
    size_t q1 = hgt[first + span / 8], q3 = hgt[last - span / 8]; /* away from the joint */
    free(hgt);
    return (double)minh / (0.5 * (double)(q1 + q3));
}

static void test_lbs_vs_cor_twist(void **state)
{
    (void)state;
    char log[2400];
    snprintf(log, sizeof log, "%s/twist.log", tmp);
    static const char *methods[2] = {"lbs", "cor"};
    double ratio[2];
    for (int m = 0; m < 2; m++) {
        char png[2400];
        snprintf(png, sizeof png, "%s/twist_%s.png", tmp, methods[m]);
        assert_int_equal(run(log,
                             "'%s' '%s' --size 480x240 --azimuth 90 --elevation 0 --fit rest --skin opaque "
                             "--pose joint2=135,0,0 --method %s -o '%s'",
                             render_bin, bar, methods[m], png),
                         0);
        image im = load_png(png);
        ratio[m] = waist_ratio(&im);
        free(im.px);
    }
    printf("twist 135 deg, silhouette waist / normal height: LBS %.2f, CoR %.2f\n", ratio[0], ratio[1]);
    assert_true(ratio[1] > 0.75); /* CoR keeps the cross-section (a small notch at the joint) */
    assert_true(ratio[0] < 0.6);  /* LBS collapses it */
    assert_true(ratio[0] < ratio[1] - 0.25);
}

static void test_compare_panel(void **state)
{
    (void)state;
    char log[2400], png[2400];
    snprintf(png, sizeof png, "%s/panel.png", tmp);
    snprintf(log, sizeof log, "%s/panel.log", tmp);
    assert_int_equal(run(log, "'%s' '%s' --size 200x200 --compare --pose joint2=0,90,0 --caption test -o '%s'",
                         render_bin, bar, png),
                     0);
    image im = load_png(png);
    assert_int_equal(im.w, 600);
    assert_int_equal(im.h, 200);
    /* Every third holds a picture. */
    for (size_t p = 0; p < 3; p++) {
        size_t hit = 0;
        for (size_t y = 0; y < im.h; y++)
            for (size_t x = p * 200; x < (p + 1) * 200; x++)
                hit += (size_t)is_fg(&im, x, y);
        assert_true(hit > 2000);
    }
    free(im.px);
}

static void test_turntable(void **state)
{
    (void)state;
    char log[2400], dir[2400], png[2500];
    snprintf(dir, sizeof dir, "%s/turn", tmp);
    snprintf(log, sizeof log, "%s/turn.log", tmp);
    assert_int_equal(run(log, "'%s' '%s' --size 64x64 --turntable 4 -o '%s'", render_bin, bar, dir), 0);
    for (int i = 0; i < 4; i++) {
        snprintf(png, sizeof png, "%s/turn_%03d.png", dir, i);
        image im = load_png(png);
        assert_true(coverage(&im) > 0.02);
        free(im.px);
    }
}

/* ------------------------------------------------------- quickstart, export */

static void test_quickstart(void **state)
{
    (void)state;
    char log[2400];
    snprintf(log, sizeof log, "%s/quick.log", tmp);
    assert_int_equal(run(log, "'%s' '%s' joint2", quickstart_bin, bar), 0);
    const char *out = slurp(log);
    const char *moved = strstr(out, "moved up to ");
    assert_non_null(moved);
    double d = atof(moved + strlen("moved up to "));
    printf("%s", out);
    assert_true(d > 0.1); /* a 60 degree bend at the third of four unit bones moves the tip far */
    assert_int_equal(run(log, "'%s' '%s/none.rig'", quickstart_bin, tmp), 1);
    assert_non_null(strstr(slurp(log), "none.rig"));
}

static void test_export(void **state)
{
    (void)state;
    char log[2400], obj[2400], vtu[2400], ply[2400];
    snprintf(log, sizeof log, "%s/export.log", tmp);
    snprintf(obj, sizeof obj, "%s/bent.obj", tmp);
    snprintf(vtu, sizeof vtu, "%s/bent.vtu", tmp);
    snprintf(ply, sizeof ply, "%s/ply", tmp);
    assert_int_equal(run(log, "'%s' '%s' --pose joint2=0,90,0 --obj '%s' --ply '%s' --vtu '%s' --weights joint2",
                         export_bin, bar, obj, ply, vtu),
                     0);
    /* --json lists what the joint limits clamped (the bar's limits are 150 degrees), and only that. */
    assert_int_equal(run(log, "'%s' '%s' --pose joint1=0,20,0 --pose joint2=0,170,0 --obj '%s/clamped.obj' --json",
                         export_bin, bar, tmp),
                     0);
    const char *json = slurp(log);
    printf("%s", json);
    assert_non_null(strstr(json, "\"clamped\": [\"--pose joint2=0,170,0: joint 2 'joint2': y 170.00 clamped to "
                                 "150.00 [-150.00, 150.00] degrees (limits in XYZ order)\"]"));
    /* OBJ: as many v lines as the rig has tissue vertices, faces index within range. */
    FILE *f = fopen(obj, "r");
    assert_non_null(f);
    char line[512];
    size_t v = 0, faces = 0, objects = 0, bad = 0;
    while (fgets(line, sizeof line, f)) {
        if (!strncmp(line, "v ", 2))
            v++;
        else if (!strncmp(line, "o ", 2))
            objects++;
        else if (!strncmp(line, "f ", 2)) {
            faces++;
            unsigned long a, b, c, na, nb, nc;
            if (sscanf(line, "f %lu//%lu %lu//%lu %lu//%lu", &a, &na, &b, &nb, &c, &nc) != 6 || a < 1 || a > v ||
                b < 1 || b > v || c < 1 || c > v)
                bad++;
        }
    }
    fclose(f);
    printf("OBJ: %zu objects, %zu vertices, %zu faces\n", objects, v, faces);
    assert_true(objects >= 2 && v > 100 && faces > 100);
    assert_int_equal(bad, 0);
    /* VTU: well-formed header, counts that match the body. */
    f = fopen(vtu, "r");
    assert_non_null(f);
    size_t np = 0, nc = 0;
    int found = 0;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "<Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\"", &np, &nc) == 2)
            found = 1;
    fclose(f);
    assert_true(found && np > 100 && nc > 100);
    assert_memory_equal(slurp(vtu), "<?xml", 5);
    /* One binary PLY per tissue. */
    assert_int_equal(run(log, "ls '%s'/*.ply | wc -l | grep -qv '^0$'", ply), 0);
}

int main(int argc, char **argv)
{
    if (argc < 7) {
        fprintf(stderr, "usage: %s pose-render pose-synth pose-view|- pose-export pose-quickstart MAP\n", argv[0]);
        return 2;
    }
    render_bin = argv[1];
    synth_bin = argv[2];
    view_bin = argv[3];
    export_bin = argv[4];
    quickstart_bin = argv[5];
    bar_map = argv[6];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_missing_rig),
        cmocka_unit_test(test_not_a_rig),
        cmocka_unit_test(test_bad_options),
        cmocka_unit_test(test_broken_source),
        cmocka_unit_test(test_view_without_display),
        cmocka_unit_test(test_view_under_xvfb),
        cmocka_unit_test(test_view_live_sources),
        cmocka_unit_test(test_rest_image_not_blank),
        cmocka_unit_test(test_silhouette_follows_pose),
        cmocka_unit_test(test_silhouette_follows_replay),
        cmocka_unit_test(test_silhouette_follows_recordings),
        cmocka_unit_test(test_lbs_vs_cor_twist),
        cmocka_unit_test(test_compare_panel),
        cmocka_unit_test(test_turntable),
        cmocka_unit_test(test_quickstart),
        cmocka_unit_test(test_export),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
