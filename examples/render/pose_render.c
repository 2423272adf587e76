/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-render: draw a posed rig off-screen with OSMesa and write PNG images.
 * One image of a hand-set pose, one image per requested frame of a replayed
 * source, a turntable, or an LBS | DQS | CoR panel of the same pose.
 */
#include <GL/osmesa.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ex_args.h"
#include "ex_camera.h"
#include "ex_draw.h"
#include "ex_font.h"
#include "ex_image.h"
#include "ex_motion.h"
#include "ex_scene.h"

enum { MAX_POSES = 64, PANELS_MAX = 3 };

typedef struct options {
    const char *rig, *output, *source, *map, *caption, *weights, *focus;
    const char *poses[MAX_POSES];
    int pose_count;
    int width, height, supersample, turntable, compare, json, threads, list_joints;
    int fit_rest; /* frame the camera on the rest pose only (comparable images across calls) */
    int follow;   /* --frames: the camera follows the model (moving target, fixed distance) */
    int method; /* -1: CoR when the rig has it, else LBS */
    long *frames;
    size_t frame_count;
    double azimuth, elevation, zoom;
    int have_azimuth, have_elevation;
    unsigned hide; /* bit per pose_tissue_kind */
    ex_skin_mode skin;
} options;

typedef struct renderer {
    OSMesaContext ctx;
    uint8_t *fb; /* (w*ss) x (h*ss) RGBA, bottom-up */
    int w, h, ss;
} renderer;

static const float bg[3] = {0.13f, 0.14f, 0.17f};
static const uint8_t bg8[4] = {33, 36, 43, 255};
static const uint8_t text_col[4] = {235, 235, 235, 255};

static void usage(FILE *f)
{
    fputs("usage: pose-render RIG [options]\n"
          "Render a posed rig off-screen (OSMesa) to PNG.\n\n"
          "What to render (default: one image of the pose given by --pose):\n"
          "  --source FILE --frames LIST  one image per frame of a replayed source (BVH, ASF/AMC,\n"
          "                               HID or CAN recording) driven through the bridge;\n"
          "                               LIST as 0,30,60 or 0-120:10\n"
          "  --map FILE                   the bridge mapping file for --source\n"
          "  --turntable N                N images around the model\n"
          "  --compare                    one image: LBS | DQS | CoR side by side, same pose (of\n"
          "                               --pose, or of one --frames frame of --source)\n"
          "Pose and look:\n"
          "  --pose JOINT=RX,RY,RZ        set a joint (degrees, XYZ order; repeatable)\n"
          "  --method lbs|dqs|cor         skinning method (default: cor when the rig has CoR data)\n"
          "  --skin auto|translucent|opaque|hidden   (default auto: translucent over other tissues)\n"
          "  --hide KINDS                 hide tissue kinds: skin,bone,muscle,organ,other\n"
          "  --weights JOINT              colour the tet mesh by this joint's skinning weight\n"
          "  --caption TEXT               caption drawn at the top of each image\n"
          "  --azimuth DEG --elevation DEG --zoom F   camera (default: frames the whole model)\n"
          "  --focus JOINT                close-up: frame the region around this joint\n"
          "  --fit pose|rest|follow       frame every pose shown (default); or the rest pose only, so\n"
          "                               separate runs share one camera; or, with --frames, follow\n"
          "                               the model from frame to frame at a fixed distance\n"
          "  --size WxH                   image size (default 640x640; a panel is 3 of these)\n"
          "  --supersample N              anti-aliasing factor 1..4 (default 2)\n"
          "  --threads N                  pose_apply worker threads (default: cores)\n"
          "Output:\n"
          "  -o, --output PATH            PNG file for one image (default pose.png), or a folder\n"
          "                               for --frames / --turntable (default render/)\n"
          "  --json                       print a JSON summary on stdout\n"
          "  --list-joints                print the rig's joints (name, parent, limits) and exit\n"
          "  -h, --help                   this text\n",
          f);
    fputs(ex_motion_available() ? "Sources: through the input bridge (BVH, ASF/AMC, HID and CAN recordings).\n"
                                : "Sources: none, built without the bridge (--source is refused).\n",
          f);
}

/* Text scales: captions on top, method labels under the panels of --compare. */
static int caption_scale(int image_width)
{
    return image_width >= 480 ? 2 : 1;
}

static int label_scale(int width)
{
    return width >= 480 ? 3 : 2;
}

/* Bands kept free of the model, so text never covers it. */
static int caption_band(const options *o)
{
    return o->caption || o->source ? EX_FONT_H * caption_scale(o->width * (o->compare ? 3 : 1)) + 12 : 0;
}

static int label_band(const options *o)
{
    return o->compare ? EX_FONT_H * label_scale(o->width) + 10 : 0;
}

static int parse_kinds(const char *s, unsigned *mask, char *err, size_t err_size)
{
    static const char *names[] = {"skin", "bone", "muscle", "organ", "other"};
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    *mask = 0;
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int k = -1;
        for (int i = 0; i < 5; i++)
            if (!strcmp(tok, names[i]))
                k = i;
        if (k < 0) {
            snprintf(err, err_size, "--hide: unknown tissue kind '%s' (skin, bone, muscle, organ, other)", tok);
            return -1;
        }
        *mask |= 1u << k;
    }
    return 0;
}

static int parse_args(int argc, char **argv, options *o, char *err, size_t err_size)
{
    memset(o, 0, sizeof *o);
    o->width = o->height = 640;
    o->supersample = 2;
    o->method = -1;
    o->zoom = 1.0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        long l;
        int takes = 1;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            exit(0);
        } else if (!strcmp(a, "--json")) {
            o->json = 1;
            takes = 0;
        } else if (!strcmp(a, "--list-joints")) {
            o->list_joints = 1;
            takes = 0;
        } else if (!strcmp(a, "--compare")) {
            o->compare = 1;
            takes = 0;
        } else if (a[0] != '-') {
            if (o->rig) {
                snprintf(err, err_size, "unexpected argument '%s' (one rig only)", a);
                return -1;
            }
            o->rig = a;
            takes = 0;
        } else if (!v) {
            snprintf(err, err_size, "%s needs a value (see --help)", a);
            return -1;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            o->output = v;
        } else if (!strcmp(a, "--source")) {
            o->source = v;
        } else if (!strcmp(a, "--map")) {
            o->map = v;
        } else if (!strcmp(a, "--caption")) {
            o->caption = v;
        } else if (!strcmp(a, "--weights")) {
            o->weights = v;
        } else if (!strcmp(a, "--focus")) {
            o->focus = v;
        } else if (!strcmp(a, "--pose")) {
            if (o->pose_count == MAX_POSES) {
                snprintf(err, err_size, "--pose: at most %d joints", MAX_POSES);
                return -1;
            }
            o->poses[o->pose_count++] = v;
        } else if (!strcmp(a, "--frames")) {
            free(o->frames);
            if (ex_parse_frames(a, v, &o->frames, &o->frame_count, err, err_size) < 0)
                return -1;
        } else if (!strcmp(a, "--turntable")) {
            if (ex_parse_long(a, v, 1, 3600, &l, err, err_size) < 0)
                return -1;
            o->turntable = (int)l;
        } else if (!strcmp(a, "--method")) {
            if ((o->method = ex_parse_method(v)) < 0) {
                snprintf(err, err_size, "--method: expected lbs, dqs or cor, got '%s'", v);
                return -1;
            }
        } else if (!strcmp(a, "--skin")) {
            static const char *modes[] = {"auto", "translucent", "opaque", "hidden"};
            int m = -1;
            for (int k = 0; k < 4; k++)
                if (!strcmp(v, modes[k]))
                    m = k;
            if (m < 0) {
                snprintf(err, err_size, "--skin: expected auto, translucent, opaque or hidden, got '%s'", v);
                return -1;
            }
            o->skin = (ex_skin_mode)m;
        } else if (!strcmp(a, "--fit")) {
            if (strcmp(v, "pose") && strcmp(v, "rest") && strcmp(v, "follow")) {
                snprintf(err, err_size, "--fit: expected pose, rest or follow, got '%s'", v);
                return -1;
            }
            o->fit_rest = !strcmp(v, "rest");
            o->follow = !strcmp(v, "follow");
        } else if (!strcmp(a, "--hide")) {
            if (parse_kinds(v, &o->hide, err, err_size) < 0)
                return -1;
        } else if (!strcmp(a, "--size")) {
            if (ex_parse_size(a, v, &o->width, &o->height, err, err_size) < 0)
                return -1;
        } else if (!strcmp(a, "--supersample")) {
            if (ex_parse_long(a, v, 1, 4, &l, err, err_size) < 0)
                return -1;
            o->supersample = (int)l;
        } else if (!strcmp(a, "--threads")) {
            if (ex_parse_long(a, v, 0, 256, &l, err, err_size) < 0)
                return -1;
            o->threads = (int)l;
        } else if (!strcmp(a, "--azimuth")) {
            if (ex_parse_double(a, v, -3600, 3600, &o->azimuth, err, err_size) < 0)
                return -1;
            o->have_azimuth = 1;
        } else if (!strcmp(a, "--elevation")) {
            if (ex_parse_double(a, v, -89, 89, &o->elevation, err, err_size) < 0)
                return -1;
            o->have_elevation = 1;
        } else if (!strcmp(a, "--zoom")) {
            if (ex_parse_double(a, v, 0.05, 50, &o->zoom, err, err_size) < 0)
                return -1;
        } else {
            snprintf(err, err_size, "unknown option '%s' (see --help)", a);
            return -1;
        }
        i += takes;
    }
    if (!o->rig) {
        snprintf(err, err_size, "no rig given (usage: pose-render RIG [options]; see --help)");
        return -1;
    }
    int modes = (o->source != NULL) + (o->turntable > 0) + o->compare;
    if (modes > 1 && !(modes == 2 && o->compare && o->source && o->frame_count == 1)) {
        snprintf(err, err_size, "choose one of --source, --turntable, --compare (--compare takes --source with "
                                "one frame)");
        return -1;
    }
    if (o->frames && !o->source) {
        snprintf(err, err_size, "--frames needs --source");
        return -1;
    }
    if (o->source && !o->frames) {
        snprintf(err, err_size, "--source needs --frames (e.g. --frames 0,30,60)");
        return -1;
    }
    if (o->height - caption_band(o) - label_band(o) < 16) {
        snprintf(err, err_size, "--size: %dx%d leaves no room for the picture under the caption and labels",
                 o->width, o->height);
        return -1;
    }
    if ((long)o->width * o->height * o->supersample * o->supersample * (o->compare ? 3 : 1) > 64L << 20) {
        snprintf(err, err_size, "image too large: reduce --size or --supersample");
        return -1;
    }
    return 0;
}

static int renderer_init(renderer *r, int w, int h, int ss, char *err, size_t err_size)
{
    r->w = w;
    r->h = h;
    r->ss = ss;
    r->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
    r->fb = malloc((size_t)w * (size_t)ss * (size_t)h * (size_t)ss * 4);
    if (!r->ctx || !r->fb) {
        snprintf(err, err_size, "cannot create an OSMesa context of %dx%d", w * ss, h * ss);
        return -1;
    }
    if (!OSMesaMakeCurrent(r->ctx, r->fb, GL_UNSIGNED_BYTE, w * ss, h * ss)) {
        snprintf(err, err_size, "OSMesaMakeCurrent failed for %dx%d", w * ss, h * ss);
        return -1;
    }
    return 0;
}

static void renderer_free(renderer *r)
{
    if (r->ctx)
        OSMesaDestroyContext(r->ctx);
    free(r->fb);
}

/* Draw the scene between the bands and read it back into img (w x h, top row first, opaque). */
static void render_to(renderer *r, const options *o, ex_scene *sc, const ex_camera *cam, ex_image *img)
{
    int top = caption_band(o), bottom = label_band(o);
    ex_draw_scene(sc, cam, 0, bottom * r->ss, r->w * r->ss, (r->h - top - bottom) * r->ss, bg);
    glFinish();
    ex_image_downsample_flip(img, r->fb, r->ss);
    for (size_t i = 0; i < (size_t)img->width * (size_t)img->height; i++)
        img->rgba[4 * i + 3] = 255;
}

/* Fraction of pixels that differ from the background: 0 means nothing was drawn. */
static double coverage(const ex_image *img)
{
    size_t n = (size_t)img->width * (size_t)img->height, hit = 0;
    for (size_t i = 0; i < n; i++) {
        const uint8_t *p = img->rgba + 4 * i;
        if (abs(p[0] - bg8[0]) + abs(p[1] - bg8[1]) + abs(p[2] - bg8[2]) > 12)
            hit++;
    }
    return n ? (double)hit / (double)n : 0.0;
}

static void caption(ex_image *img, const char *text)
{
    if (!text || !*text)
        return;
    int scale = caption_scale(img->width);
    int x = (img->width - ex_font_text_width(text) * scale) / 2;
    ex_image_text(img, x > 4 ? x : 4, 6, scale, text_col, text);
}

typedef struct summary {
    FILE *json;
    int first;
    double apply_ms, render_ms;
    int images;
    int total;    /* images this run will write, for the progress line */
    double start; /* ex_now() at the first image */
} summary;

static int emit(summary *s, const ex_image *img, const char *path, long frame, const char *method,
                double render_ms, double apply_ms, char *err, size_t err_size)
{
    if (ex_image_write_png(img, path, err, err_size) < 0)
        return -1;
    s->images++;
    s->apply_ms += apply_ms;
    s->render_ms += render_ms;
    double cov = coverage(img);
    if (s->json) {
        fprintf(s->json, "%s\n    {\"path\": ", s->first ? "" : ",");
        ex_json_string(s->json, path);
        fprintf(s->json, ", \"frame\": %ld, \"method\": \"%s\", \"coverage\": %.4f, \"apply_ms\": %.3f}", frame,
                method, cov, apply_ms);
        s->first = 0;
    }
    /* Progress: in the text output's own lines, or on stderr beside JSON when it is a terminal. */
    double el = ex_now() - s->start, eta = el / s->images * (s->total - s->images);
    char progress[64] = "";
    if (s->total > 1)
        snprintf(progress, sizeof progress, " [%d/%d, %.0f%%, ETA %.0f s]", s->images, s->total,
                 100.0 * s->images / s->total, eta);
    if (!s->json)
        printf("wrote %s (%dx%d, %s, %.1f%% covered)%s\n", path, img->width, img->height, method, 100.0 * cov,
               progress);
    else if (isatty(STDERR_FILENO) && s->total > 1)
        fprintf(stderr, "\r\033[Kpose-render:%s", progress);
    return 0;
}

static int make_dir(const char *dir, char *err, size_t err_size)
{
    struct stat sb;
    if (mkdir(dir, 0777) == 0 || (stat(dir, &sb) == 0 && S_ISDIR(sb.st_mode)))
        return 0;
    snprintf(err, err_size, "%s: cannot create the output folder", dir);
    return -1;
}

/*
 * Camera looking at bounds bmin/bmax in an image of aspect w/h, from the
 * user's direction or the default one, then fitted to the focus box when
 * there is one (the direction still chosen from the whole model).
 */
static void setup_camera(ex_camera *cam, const options *o, const float bmin[3], const float bmax[3],
                         const float *fmin, const float *fmax, float aspect)
{
    ex_camera_frame(cam, bmin, bmax, aspect);
    if (o->have_azimuth)
        cam->azimuth_deg = (float)o->azimuth;
    if (o->have_elevation)
        cam->elevation_deg = (float)o->elevation;
    if (fmin)
        for (int i = 0; i < 3; i++)
            cam->target[i] = 0.5f * (fmin[i] + fmax[i]);
    ex_camera_fit(cam, fmin ? fmin : bmin, fmin ? fmax : bmax, aspect);
    cam->distance /= (float)o->zoom;
}

static void grow_bounds(const ex_scene *sc, float bmin[3], float bmax[3])
{
    float a[3], b[3];
    ex_scene_bounds(sc, 1, a, b);
    for (int i = 0; i < 3; i++) {
        bmin[i] = a[i] < bmin[i] ? a[i] : bmin[i];
        bmax[i] = b[i] > bmax[i] ? b[i] : bmax[i];
    }
}

static int run(const options *o, summary *s, char *err, size_t err_size)
{
    ex_scene sc;
    ex_motion *motion = NULL;
    renderer r = {0};
    ex_image img = {0}, panel = {0};
    int rc = -1;
    char path[4096];

    if (ex_scene_open(&sc, o->rig, err, err_size) < 0)
        return -1;
    if (o->list_joints) {
        for (size_t j = 0; j < pose_rig_joint_count(sc.rig); j++) {
            pose_joint_info ji;
            if (pose_rig_joint_info(sc.rig, (int)j, &ji) < 0)
                continue;
            printf("%s parent=%d", ji.name, ji.parent);
            for (int a = 0; a < 3; a++)
                if (ji.limit_flags & (1u << a))
                    printf(" %c=[%g,%g]", "xyz"[a], ji.limit_min_deg[a], ji.limit_max_deg[a]);
            printf("\n");
        }
        ex_scene_close(&sc);
        return 0;
    }
    if (o->threads)
        pose_set_threads(sc.state, o->threads);
    sc.skin_mode = o->skin;
    if (o->hide & 1u)
        sc.skin_mode = EX_SKIN_HIDDEN;
    for (size_t t = 0; t < sc.tissue_count; t++) {
        pose_tissue_info ti;
        if (pose_rig_tissue_info(sc.rig, (int)t, &ti) == POSE_OK && (o->hide & (1u << ti.kind)))
            sc.tissue_visible[t] = 0;
    }
    pose_tet_info tet;
    int has_cor = pose_rig_tet_info(sc.rig, &tet) == POSE_OK && tet.cor != NULL;
    pose_method method = o->method >= 0 ? (pose_method)o->method : has_cor ? POSE_COR : POSE_LBS;
    if (!o->compare && pose_set_method(sc.state, method) < 0) {
        snprintf(err, err_size, "--method %s: %s", ex_method_name(method), pose_last_error());
        goto done;
    }
    if (o->weights) {
        int j = pose_rig_find_joint(sc.rig, o->weights);
        if (j < 0) {
            snprintf(err, err_size, "--weights: the rig has no joint '%s'", o->weights);
            goto done;
        }
        if (ex_scene_set_weight_joint(&sc, j, err, err_size) < 0)
            goto done;
    }
    for (int i = 0; i < o->pose_count; i++)
        if (ex_scene_set_pose_arg(&sc, o->poses[i], err, err_size) < 0)
            goto done;
    if (o->source && ex_motion_open(o->source, o->map, sc.rig, &motion, err, err_size) < 0)
        goto done;
    if (motion) {
        long n = ex_motion_frame_count(motion);
        for (size_t i = 0; i < o->frame_count; i++)
            if (n >= 0 && o->frames[i] >= n) {
                snprintf(err, err_size, "--frames: frame %ld is past the end of %s (%ld frames)", o->frames[i],
                         o->source, n);
                goto done;
            }
    }

    /* Frame the camera on everything that will be shown, so a sequence shares one camera. */
    float bmin[3], bmax[3];
    if (ex_scene_apply(&sc, err, err_size) < 0)
        goto done;
    float half[3] = {0.0f, 0.0f, 0.0f}; /* largest half-extents of one frame, for --fit follow */
    ex_scene_bounds(&sc, !o->fit_rest, bmin, bmax);
    if (motion && !o->fit_rest)
        for (size_t i = 0; i < o->frame_count; i++) {
            if (ex_motion_set_frame(motion, sc.state, o->frames[i], err, err_size) < 0 ||
                ex_scene_apply(&sc, err, err_size) < 0)
                goto done;
            if (i == 0) /* the frames alone, not the pose before them */
                ex_scene_bounds(&sc, 1, bmin, bmax);
            else
                grow_bounds(&sc, bmin, bmax);
            float a[3], b[3];
            ex_scene_bounds(&sc, 1, a, b);
            for (int k = 0; k < 3; k++)
                half[k] = fmaxf(half[k], 0.5f * (b[k] - a[k]));
        }
    if (o->compare && !o->fit_rest)
        for (int m = 0; m < 3; m++)
            if (pose_set_method(sc.state, (pose_method)m) == POSE_OK && ex_scene_apply(&sc, err, err_size) == 0)
                grow_bounds(&sc, bmin, bmax);
    float fmin[3], fmax[3];
    if (o->focus) {
        /* A box around the joint, a fifth of the model's size on each side. */
        int j = pose_rig_find_joint(sc.rig, o->focus);
        pose_transform x;
        if (j < 0 || pose_joint_world(sc.state, j, &x) < 0) {
            snprintf(err, err_size, "--focus: the rig has no joint '%s'", o->focus);
            goto done;
        }
        float d = 0.0f;
        for (int i = 0; i < 3; i++)
            d = fmaxf(d, bmax[i] - bmin[i]);
        for (int i = 0; i < 3; i++) {
            fmin[i] = x.translation[i] - 0.2f * d;
            fmax[i] = x.translation[i] + 0.2f * d;
        }
    }
    ex_camera cam;
    setup_camera(&cam, o, bmin, bmax, o->focus ? fmin : NULL, o->focus ? fmax : NULL,
                 (float)o->width / (float)(o->height - caption_band(o) - label_band(o)));

    if (renderer_init(&r, o->width, o->height, o->supersample, err, err_size) < 0 ||
        ex_image_init(&img, o->width, o->height, bg8) < 0) {
        if (!*err)
            snprintf(err, err_size, "out of memory");
        goto done;
    }
    int many = (motion && !o->compare) || o->turntable;
    s->total = motion && !o->compare ? (int)o->frame_count : o->turntable ? o->turntable : 1;
    s->start = ex_now();
    const char *out = o->output ? o->output : many ? "render" : "pose.png";
    if (many && make_dir(out, err, err_size) < 0)
        goto done;

    if (o->compare) {
        static const pose_method methods[3] = {POSE_LBS, POSE_DQS, POSE_COR};
        if (motion && ex_motion_set_frame(motion, sc.state, o->frames[0], err, err_size) < 0)
            goto done;
        if (ex_image_init(&panel, 3 * o->width, o->height, bg8) < 0) {
            snprintf(err, err_size, "out of memory");
            goto done;
        }
        double apply = 0.0, t0 = ex_now();
        for (int m = 0; m < 3; m++) {
            char label[64];
            if (pose_set_method(sc.state, methods[m]) < 0) {
                /* A rig without CoR data: say so in the panel rather than fail. */
                ex_image_fill(&img, bg8);
                snprintf(label, sizeof label, "%s: not in this rig", ex_method_name(methods[m]));
            } else {
                if (ex_scene_apply(&sc, err, err_size) < 0)
                    goto done;
                apply += sc.last_apply_ms;
                render_to(&r, o, &sc, &cam, &img);
                snprintf(label, sizeof label, "%s", ex_method_name(methods[m]));
            }
            int scale = label_scale(o->width);
            ex_image_text(&img, (img.width - ex_font_text_width(label) * scale) / 2,
                          img.height - EX_FONT_H * scale - 5, scale, text_col, label);
            ex_image_blit(&panel, &img, m * o->width, 0);
        }
        caption(&panel, o->caption);
        if (emit(s, &panel, out, -1, "LBS|DQS|CoR", 1e3 * (ex_now() - t0), apply, err, err_size) < 0)
            goto done;
    } else if (motion) {
        for (size_t i = 0; i < o->frame_count; i++) {
            char text[512];
            double t0 = ex_now();
            if (ex_motion_set_frame(motion, sc.state, o->frames[i], err, err_size) < 0 ||
                ex_scene_apply(&sc, err, err_size) < 0)
                goto done;
            if (o->follow) { /* same size of box every frame: the distance stays, the target moves */
                float a[3], b[3];
                ex_scene_bounds(&sc, 1, a, b);
                for (int k = 0; k < 3; k++) {
                    float c = 0.5f * (a[k] + b[k]);
                    a[k] = c - half[k];
                    b[k] = c + half[k];
                }
                setup_camera(&cam, o, bmin, bmax, a, b,
                             (float)o->width / (float)(o->height - caption_band(o) - label_band(o)));
            }
            render_to(&r, o, &sc, &cam, &img);
            snprintf(text, sizeof text, "%s%sframe %ld  %s", o->caption ? o->caption : "",
                     o->caption ? "  " : "", o->frames[i], ex_method_name(method));
            caption(&img, text);
            snprintf(path, sizeof path, "%s/frame_%05ld.png", out, o->frames[i]);
            if (emit(s, &img, path, o->frames[i], ex_method_name(method), 1e3 * (ex_now() - t0), sc.last_apply_ms,
                     err, err_size) < 0)
                goto done;
        }
    } else if (o->turntable) {
        if (ex_scene_apply(&sc, err, err_size) < 0)
            goto done;
        float az0 = cam.azimuth_deg;
        for (int i = 0; i < o->turntable; i++) {
            double t0 = ex_now();
            cam.azimuth_deg = az0 + 360.0f * (float)i / (float)o->turntable;
            render_to(&r, o, &sc, &cam, &img);
            caption(&img, o->caption);
            snprintf(path, sizeof path, "%s/turn_%03d.png", out, i);
            if (emit(s, &img, path, -1, ex_method_name(method), 1e3 * (ex_now() - t0), sc.last_apply_ms, err,
                     err_size) < 0)
                goto done;
        }
    } else {
        double t0 = ex_now();
        if (ex_scene_apply(&sc, err, err_size) < 0)
            goto done;
        render_to(&r, o, &sc, &cam, &img);
        caption(&img, o->caption);
        if (emit(s, &img, out, -1, ex_method_name(method), 1e3 * (ex_now() - t0), sc.last_apply_ms, err,
                 err_size) < 0)
            goto done;
    }
    rc = 0;
done:
    ex_image_free(&panel);
    ex_image_free(&img);
    renderer_free(&r);
    ex_motion_close(motion);
    ex_scene_close(&sc);
    return rc;
}

int main(int argc, char **argv)
{
    options o;
    char err[1024] = "";
    if (parse_args(argc, argv, &o, err, sizeof err) < 0) {
        fprintf(stderr, "pose-render: %s\n", err);
        free(o.frames);
        return 2;
    }
    summary s = {.json = o.json ? stdout : NULL, .first = 1};
    if (s.json) {
        fprintf(s.json, "{\n  \"rig\": ");
        ex_json_string(s.json, o.rig);
        fprintf(s.json, ",\n  \"width\": %d, \"height\": %d,\n  \"images\": [", o.width, o.height);
    }
    int rc = run(&o, &s, err, sizeof err);
    if (s.json && isatty(STDERR_FILENO) && s.total > 1 && s.images)
        fputc('\n', stderr);
    if (s.json) {
        fprintf(s.json, "\n  ],\n  \"ok\": %s", rc == 0 ? "true" : "false");
        if (s.images)
            fprintf(s.json, ",\n  \"mean_apply_ms\": %.3f, \"mean_image_ms\": %.1f", s.apply_ms / s.images,
                    s.render_ms / s.images);
        if (rc != 0) {
            fprintf(s.json, ",\n  \"error\": ");
            ex_json_string(s.json, err);
        }
        fprintf(s.json, "\n}\n");
    }
    free(o.frames);
    if (rc != 0) {
        fprintf(stderr, "pose-render: %s\n", err);
        return 1;
    }
    return 0;
}
