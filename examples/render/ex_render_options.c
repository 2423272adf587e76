/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_render_options.h"

#include <stdlib.h>
#include <string.h>

#include "ex_args.h"
#include "ex_font.h"
#include "ex_motion.h"

void ex_render_usage(FILE *f)
{
    fputs("usage: pose-render RIG [options]\n"
          "Render a posed rig off-screen (OSMesa) to PNG.\n\n"
          "What to render (default: one image of the pose given by --pose):\n"
          "  --source FILE --frames LIST  one image per frame of a mocap clip (BVH, ASF/AMC) driven\n"
          "                               through the bridge;\n"
          "                               LIST as 0,30,60 or 0-120:10\n"
          "  --source FILE --times LIST   one image per recorded time (seconds): the recording is\n"
          "                               replayed as fast as possible through the bridge's decoder\n"
          "                               and mapping, and the pose held at each time is shown;\n"
          "                               LIST as 0,2.5,5 or 0-10:0.5 (HID and CAN recordings, clips)\n"
          "  --map FILE                   the bridge mapping file for --source\n"
          "  --turntable N                N images around the model\n"
          "  --compare                    one image: LBS | DQS | CoR side by side, same pose (of\n"
          "                               --pose, or of one --frames frame or --times time of --source)\n"
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
int ex_render_caption_scale(int image_width)
{
    return image_width >= 480 ? 2 : 1;
}

int ex_render_label_scale(int width)
{
    return width >= 480 ? 3 : 2;
}

/* Bands kept free of the model, so text never covers it. */
int ex_render_caption_band(const ex_render_options *o)
{
    return o->caption || o->source ? EX_FONT_H * ex_render_caption_scale(o->width * (o->compare ? 3 : 1)) + 12 : 0;
}

int ex_render_label_band(const ex_render_options *o)
{
    return o->compare ? EX_FONT_H * ex_render_label_scale(o->width) + 10 : 0;
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

int ex_render_parse(int argc, char **argv, ex_render_options *o, char *err, size_t err_size)
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
            ex_render_usage(stdout);
            return 1;
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
            if (o->pose_count == EX_RENDER_MAX_POSES) {
                snprintf(err, err_size, "--pose: at most %d joints", EX_RENDER_MAX_POSES);
                return -1;
            }
            o->poses[o->pose_count++] = v;
        } else if (!strcmp(a, "--frames")) {
            free(o->frames);
            if (ex_parse_frames(a, v, &o->frames, &o->frame_count, err, err_size) < 0)
                return -1;
        } else if (!strcmp(a, "--times")) {
            free(o->times);
            if (ex_parse_times(a, v, &o->times, &o->time_count, err, err_size) < 0)
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
    if (modes > 1 && !(modes == 2 && o->compare && o->source && o->frame_count + o->time_count == 1)) {
        snprintf(err, err_size, "choose one of --source, --turntable, --compare (--compare takes --source with "
                                "one frame or time)");
        return -1;
    }
    if (o->frames && o->times) {
        snprintf(err, err_size, "choose one of --frames, --times");
        return -1;
    }
    if ((o->frames || o->times) && !o->source) {
        snprintf(err, err_size, "%s needs --source", o->frames ? "--frames" : "--times");
        return -1;
    }
    if (o->source && !o->frames && !o->times) {
        snprintf(err, err_size, "--source needs --frames (e.g. --frames 0,30,60) or, for recordings, --times "
                                "(seconds, e.g. --times 0,2.5,5)");
        return -1;
    }
    if (o->height - ex_render_caption_band(o) - ex_render_label_band(o) < 16) {
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
