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
#include "ex_render_options.h"
#include "ex_scene.h"
#include "ex_volume_posed.h"
#include "vol_slices.h"
#include "vol_slices_image.h"

/* --slices: pixels between the model and the slices. */
#define SLICES_GAP 8

typedef struct renderer {
    OSMesaContext ctx;
    uint8_t *fb; /* (w*ss) x (h*ss) RGBA, bottom-up */
    int w, h, ss;
} renderer;

static const float bg[3] = {0.13f, 0.14f, 0.17f};
static const uint8_t bg8[4] = {33, 36, 43, 255};
static const uint8_t text_col[4] = {235, 235, 235, 255};

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
static void render_to(renderer *r, const ex_render_options *o, ex_scene *sc, const ex_camera *cam, ex_image *img)
{
    int top = ex_render_caption_band(o), bottom = ex_render_label_band(o);
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
    int scale = ex_render_caption_scale(img->width);
    int x = (img->width - ex_font_text_width(text) * scale) / 2;
    ex_image_text(img, x > 4 ? x : 4, 6, scale, text_col, text);
}

typedef struct summary {
    FILE *json;
    ex_clamp_log clamped; /* the scene's, kept for the summary after the scene is closed */
    int first;
    double apply_ms, render_ms;
    int images;
    int total;    /* images this run will write, for the progress line */
    double start; /* ex_now() at the first image */
} summary;

static int emit(summary *s, const ex_image *img, const char *path, long frame, double time_s, const char *method,
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
        fprintf(s->json, ", \"frame\": %ld, ", frame);
        if (time_s >= 0.0)
            fprintf(s->json, "\"time_s\": %.6g, ", time_s);
        fprintf(s->json, "\"method\": \"%s\", \"coverage\": %.4f, \"apply_ms\": %.3f}", method, cov, apply_ms);
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
static void setup_camera(ex_camera *cam, const ex_render_options *o, const float bmin[3], const float bmax[3],
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

/* Everything one run of pose-render works with. */
typedef struct job {
    const ex_render_options *o;
    summary *s;
    ex_scene sc;
    ex_motion *motion;
    renderer r;
    ex_image img;
    ex_camera cam;
    ex_volume_posed vol; /* --slices */
    pose_method method;
    float bmin[3], bmax[3]; /* what the camera frames */
    float half[3];          /* largest half-extents of one frame, for --fit follow */
    const char *out;        /* the PNG file, or the folder of a sequence */
    char *err;
    size_t err_size;
} job;

static float aspect(const ex_render_options *o)
{
    return (float)o->width / (float)(o->height - ex_render_caption_band(o) - ex_render_label_band(o));
}

static void list_joints(const pose_rig *rig)
{
    for (size_t j = 0; j < pose_rig_joint_count(rig); j++) {
        pose_joint_info ji;
        if (pose_rig_joint_info(rig, (int)j, &ji) < 0)
            continue;
        printf("%s parent=%d", ji.name, ji.parent);
        for (int a = 0; a < 3; a++)
            if (ji.limit_flags & (1u << a))
                printf(" %c=[%g,%g]", "xyz"[a], ji.limit_min_deg[a], ji.limit_max_deg[a]);
        printf("\n");
    }
}

/* Visibility, method, weights, hand-set joints and the source, as the options say. */
static int prepare(job *jb)
{
    const ex_render_options *o = jb->o;
    ex_scene *sc = &jb->sc;
    if (o->threads)
        pose_set_threads(sc->state, o->threads);
    sc->skin_mode = (o->hide & 1u) ? EX_SKIN_HIDDEN : o->skin;
    for (size_t t = 0; t < sc->tissue_count; t++) {
        pose_tissue_info ti;
        if (pose_rig_tissue_info(sc->rig, (int)t, &ti) == POSE_OK && (o->hide & (1u << ti.kind)))
            sc->tissue_visible[t] = 0;
    }
    pose_tet_info tet;
    int has_cor = pose_rig_tet_info(sc->rig, &tet) == POSE_OK && tet.cor != NULL;
    jb->method = o->method >= 0 ? (pose_method)o->method : has_cor ? POSE_COR : POSE_LBS;
    if (!o->compare && pose_set_method(sc->state, jb->method) < 0) {
        snprintf(jb->err, jb->err_size, "--method %s: %s", ex_method_name(jb->method), pose_last_error());
        return -1;
    }
    if (o->weights) {
        int j = pose_rig_find_joint(sc->rig, o->weights);
        if (j < 0) {
            snprintf(jb->err, jb->err_size, "--weights: the rig has no joint '%s'", o->weights);
            return -1;
        }
        if (ex_scene_set_weight_joint(sc, j, jb->err, jb->err_size) < 0)
            return -1;
    }
    for (int i = 0; i < o->pose_count; i++)
        if (ex_scene_set_pose_arg(sc, o->poses[i], jb->err, jb->err_size) < 0)
            return -1;
    if (o->source && ex_motion_open(o->source, o->map, sc->rig, &jb->motion, jb->err, jb->err_size) < 0)
        return -1;
    if (jb->motion) {
        long n = ex_motion_frame_count(jb->motion);
        for (size_t i = 0; i < o->frame_count; i++)
            if (n >= 0 && o->frames[i] >= n) {
                snprintf(jb->err, jb->err_size, "--frames: frame %ld is past the end of %s (%ld frames)",
                         o->frames[i], o->source, n);
                return -1;
            }
    }
    return ex_scene_apply(sc, jb->err, jb->err_size);
}

/* How many frames (--frames) or recorded times (--times) were asked for. */
static size_t pick_count(const ex_render_options *o)
{
    return o->times ? o->time_count : o->frame_count;
}

/* Set the i-th requested frame or time of the source (no pose_apply). */
static int set_pick(job *jb, size_t i)
{
    const ex_render_options *o = jb->o;
    return o->times ? ex_motion_set_time(jb->motion, jb->sc.state, o->times[i], jb->err, jb->err_size)
                    : ex_motion_set_frame(jb->motion, jb->sc.state, o->frames[i], jb->err, jb->err_size);
}

/* Set the i-th requested frame or time of the source and pose it. */
static int pose_pick(job *jb, size_t i)
{
    if (set_pick(jb, i) < 0)
        return -1;
    return ex_scene_apply(&jb->sc, jb->err, jb->err_size);
}

/* One camera for everything that will be shown (or for the rest pose, or a joint's region). */
static int frame_camera(job *jb)
{
    const ex_render_options *o = jb->o;
    ex_scene *sc = &jb->sc;
    ex_scene_bounds(sc, !o->fit_rest, jb->bmin, jb->bmax);
    if (jb->motion && !o->fit_rest)
        for (size_t i = 0; i < pick_count(o); i++) {
            float a[3], b[3];
            if (pose_pick(jb, i) < 0)
                return -1;
            ex_scene_bounds(sc, 1, a, b);
            for (int k = 0; k < 3; k++) {
                /* the frames alone, not the pose before them */
                jb->bmin[k] = i == 0 ? a[k] : fminf(jb->bmin[k], a[k]);
                jb->bmax[k] = i == 0 ? b[k] : fmaxf(jb->bmax[k], b[k]);
                jb->half[k] = fmaxf(jb->half[k], 0.5f * (b[k] - a[k]));
            }
        }
    if (o->compare && !o->fit_rest)
        for (int m = 0; m < 3; m++)
            if (pose_set_method(sc->state, (pose_method)m) == POSE_OK && ex_scene_apply(sc, jb->err, jb->err_size) == 0)
                grow_bounds(sc, jb->bmin, jb->bmax);
    if (!o->focus) {
        setup_camera(&jb->cam, o, jb->bmin, jb->bmax, NULL, NULL, aspect(o));
        return 0;
    }
    /* A box around the joint, a fifth of the model's size on each side. */
    int j = pose_rig_find_joint(sc->rig, o->focus);
    pose_transform x;
    float fmin[3], fmax[3], d = 0.0f;
    if (j < 0 || pose_joint_world(sc->state, j, &x) < 0) {
        snprintf(jb->err, jb->err_size, "--focus: the rig has no joint '%s'", o->focus);
        return -1;
    }
    for (int i = 0; i < 3; i++)
        d = fmaxf(d, jb->bmax[i] - jb->bmin[i]);
    for (int i = 0; i < 3; i++) {
        fmin[i] = x.translation[i] - 0.2f * d;
        fmax[i] = x.translation[i] + 0.2f * d;
    }
    setup_camera(&jb->cam, o, jb->bmin, jb->bmax, fmin, fmax, aspect(o));
    return 0;
}

/* LBS | DQS | CoR side by side, one pose (a rig without CoR data says so in its panel),
 * and FEM beside them when the rig has its data. */
static int render_compare(job *jb)
{
    static const pose_method methods[4] = {POSE_LBS, POSE_DQS, POSE_COR, POSE_FEM};
    const int count = pose_rig_has_fem(jb->sc.rig) ? 4 : 3;
    const ex_render_options *o = jb->o;
    ex_image panel = {0};
    double apply = 0.0, t0 = ex_now();
    int rc = -1;
    if (jb->motion && set_pick(jb, 0) < 0)
        return -1;
    if (ex_image_init(&panel, count * o->width, o->height, bg8) < 0) {
        snprintf(jb->err, jb->err_size, "out of memory");
        return -1;
    }
    for (int m = 0; m < count; m++) {
        char label[64];
        if (pose_set_method(jb->sc.state, methods[m]) < 0) {
            ex_image_fill(&jb->img, bg8);
            snprintf(label, sizeof label, "%s: not in this rig", ex_method_name(methods[m]));
        } else {
            if (ex_scene_apply(&jb->sc, jb->err, jb->err_size) < 0)
                goto done;
            apply += jb->sc.last_apply_ms;
            render_to(&jb->r, o, &jb->sc, &jb->cam, &jb->img);
            snprintf(label, sizeof label, "%s", ex_method_name(methods[m]));
        }
        int scale = ex_render_label_scale(o->width);
        ex_image_text(&jb->img, (jb->img.width - ex_font_text_width(label) * scale) / 2,
                      jb->img.height - EX_FONT_H * scale - 5, scale, text_col, label);
        ex_image_blit(&panel, &jb->img, m * o->width, 0);
    }
    caption(&panel, o->caption);
    rc = emit(jb->s, &panel, jb->out, -1, -1.0, count == 4 ? "LBS|DQS|CoR|FEM" : "LBS|DQS|CoR", 1e3 * (ex_now() - t0), apply, jb->err, jb->err_size);
done:
    ex_image_free(&panel);
    return rc;
}

/* The image to write: img itself, or with --slices img and the posed scan's
 * slices through the middle of its grid beside it (top aligned, SLICES_GAP
 * apart, as tall as img allows) in *both (free it). */
static const ex_image *with_slices(job *jb, const ex_image *img, ex_image *both)
{
    if (!jb->o->slices)
        return img;
    ex_volume_posed *v = &jb->vol;
    if (ex_volume_posed_update(v, jb->sc.state, jb->err, jb->err_size) < 0)
        return NULL;
    const int c[3] = {v->n[0] / 2, v->n[1] / 2, v->n[2] / 2};
    ex_image sl = {0};
    if (ex_volume_slices_image(&sl, v->hu, v->labels, v->n, v->spacing, c, EX_VOLUME_LEVEL,
                               EX_VOLUME_WIDTH, ex_volume_slices_zoom(v->n, v->spacing, img->height),
                               bg8) < 0 ||
        ex_image_init(both, img->width + SLICES_GAP + sl.width, img->height > sl.height ? img->height : sl.height,
                      bg8) < 0) {
        ex_image_free(&sl);
        snprintf(jb->err, jb->err_size, "out of memory for the slices");
        return NULL;
    }
    ex_image_blit(both, img, 0, 0);
    ex_image_blit(both, &sl, img->width + SLICES_GAP, 0);
    ex_image_free(&sl);
    return both;
}

/* One image per requested frame or recorded time of the source. */
static int render_frames(job *jb)
{
    const ex_render_options *o = jb->o;
    for (size_t i = 0; i < pick_count(o); i++) {
        char text[512], what[64], path[4096];
        double t0 = ex_now();
        if (pose_pick(jb, i) < 0)
            return -1;
        if (o->follow) { /* the same size of box every frame: the distance stays, the target moves */
            float a[3], b[3];
            ex_scene_bounds(&jb->sc, 1, a, b);
            for (int k = 0; k < 3; k++) {
                float c = 0.5f * (a[k] + b[k]);
                a[k] = c - jb->half[k];
                b[k] = c + jb->half[k];
            }
            setup_camera(&jb->cam, o, jb->bmin, jb->bmax, a, b, aspect(o));
        }
        render_to(&jb->r, o, &jb->sc, &jb->cam, &jb->img);
        if (o->times) {
            snprintf(what, sizeof what, "t %.2f s", o->times[i]);
            snprintf(path, sizeof path, "%s/time_%08.3f.png", jb->out, o->times[i]);
        } else {
            snprintf(what, sizeof what, "frame %ld", o->frames[i]);
            snprintf(path, sizeof path, "%s/frame_%05ld.png", jb->out, o->frames[i]);
        }
        snprintf(text, sizeof text, "%s%s%s  %s", o->caption ? o->caption : "", o->caption ? "  " : "", what,
                 ex_method_name(jb->method));
        caption(&jb->img, text);
        ex_image both = {0};
        const ex_image *out = with_slices(jb, &jb->img, &both);
        int bad = !out || emit(jb->s, out, path, o->times ? -1 : o->frames[i], o->times ? o->times[i] : -1.0,
                               ex_method_name(jb->method), 1e3 * (ex_now() - t0), jb->sc.last_apply_ms,
                               jb->err, jb->err_size) < 0;
        ex_image_free(&both);
        if (bad)
            return -1;
    }
    return 0;
}

/* N images around the model; also the single image (N = 1, no folder). */
static int render_turntable(job *jb, int n, int folder)
{
    float az0 = jb->cam.azimuth_deg;
    for (int i = 0; i < n; i++) {
        char path[4096];
        double t0 = ex_now();
        jb->cam.azimuth_deg = az0 + 360.0f * (float)i / (float)n;
        render_to(&jb->r, jb->o, &jb->sc, &jb->cam, &jb->img);
        caption(&jb->img, jb->o->caption);
        if (folder)
            snprintf(path, sizeof path, "%s/turn_%03d.png", jb->out, i);
        else
            snprintf(path, sizeof path, "%s", jb->out);
        ex_image both = {0};
        const ex_image *out = with_slices(jb, &jb->img, &both);
        int bad = !out || emit(jb->s, out, path, -1, -1.0, ex_method_name(jb->method), 1e3 * (ex_now() - t0),
                               jb->sc.last_apply_ms, jb->err, jb->err_size) < 0;
        ex_image_free(&both);
        if (bad)
            return -1;
    }
    return 0;
}

static int run(const ex_render_options *o, summary *s, char *err, size_t err_size)
{
    job jb = {.o = o, .s = s, .err = err, .err_size = err_size};
    int rc = -1;
    if (ex_scene_open(&jb.sc, o->rig, err, err_size) < 0)
        return -1;
    if (o->list_joints) {
        list_joints(jb.sc.rig);
        ex_scene_close(&jb.sc);
        return 0;
    }
    if (prepare(&jb) < 0 || frame_camera(&jb) < 0 ||
        (o->slices && ex_volume_posed_open(&jb.vol, jb.sc.rig, o->threads, err, err_size) < 0))
        goto done;
    /* The pose to show, after framing tried the others. */
    if (!o->compare && !jb.motion &&
        (pose_set_method(jb.sc.state, jb.method) < 0 || ex_scene_apply(&jb.sc, err, err_size) < 0))
        goto done;
    if (renderer_init(&jb.r, o->width, o->height, o->supersample, err, err_size) < 0 ||
        ex_image_init(&jb.img, o->width, o->height, bg8) < 0) {
        if (!*err)
            snprintf(err, err_size, "out of memory");
        goto done;
    }
    int frames = jb.motion && !o->compare, folder = frames || o->turntable;
    s->total = frames ? (int)pick_count(o) : o->turntable ? o->turntable : 1;
    s->start = ex_now();
    jb.out = o->output ? o->output : folder ? "render" : "pose.png";
    if (folder && make_dir(jb.out, err, err_size) < 0)
        goto done;
    if (o->compare)
        rc = render_compare(&jb);
    else if (frames)
        rc = render_frames(&jb);
    else
        rc = render_turntable(&jb, o->turntable ? o->turntable : 1, folder);
done:
    s->clamped = jb.sc.clamped;
    ex_image_free(&jb.img);
    ex_volume_posed_close(&jb.vol);
    renderer_free(&jb.r);
    ex_motion_close(jb.motion);
    ex_scene_close(&jb.sc);
    return rc;
}

int main(int argc, char **argv)
{
    ex_render_options o;
    char err[1024] = "";
    int parsed = ex_render_parse(argc, argv, &o, err, sizeof err);
    if (parsed != 0) {
        if (parsed < 0 && err[0]) /* else the option parser has said what was wrong */
            fprintf(stderr, "pose-render: %s\n", err);
        free(o.frames);
        free(o.times);
        return parsed < 0 ? 2 : 0;
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
        fprintf(s.json, "\n  ],\n  \"ok\": %s,\n  ", rc == 0 ? "true" : "false");
        ex_clamp_log_json(&s.clamped, s.json);
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
    free(o.times);
    if (rc != 0) {
        fprintf(stderr, "pose-render: %s\n", err);
        return 1;
    }
    return 0;
}
