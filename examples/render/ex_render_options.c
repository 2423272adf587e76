/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_render_options.h"

#include <stdlib.h>
#include <string.h>

#include "ex_args.h"
#include "ex_font.h"
#include "ex_motion.h"
#include "pose_cli.h"

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
          "  --compare                    one image: LBS | DQS | CoR (| FEM where the rig has its data)\n"
          "                               side by side, same pose (of --pose, or of one --frames frame\n"
          "                               or --times time of --source)\n"
          "Pose and look:\n"
          "  --pose JOINT=RX,RY,RZ        set a joint (degrees, XYZ order; repeatable)\n"
          "  --method lbs|dqs|cor|fem     skinning method (default: cor when the rig has CoR data;\n"
          "                               fem: CoR refined by quasi-static FEM, rigs with fem data)\n"
          "  --skin auto|translucent|opaque|hidden   (default auto: translucent over other tissues)\n"
          "  --hide KINDS                 hide tissue kinds: skin,bone,muscle,organ,other\n"
          "  --weights JOINT              colour the tet mesh by this joint's skinning weight\n"
          "  --caption TEXT               caption drawn at the top of each image\n"
          "  --slices                     beside the model: axial, coronal and sagittal slices of the\n"
          "                               rig's scan (pose-bake --labels) posed alike, label colours\n"
          "                               over the CT, through the middle of the grid\n"
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
    enum { OPT_JSON = POSE_CLI_LONG_ONLY, OPT_LIST_JOINTS, OPT_COMPARE, OPT_SOURCE, OPT_MAP, OPT_CAPTION,
           OPT_WEIGHTS, OPT_FOCUS, OPT_POSE, OPT_FRAMES, OPT_TIMES, OPT_TURNTABLE, OPT_METHOD, OPT_SKIN, OPT_FIT,
           OPT_HIDE, OPT_SIZE, OPT_SUPERSAMPLE, OPT_THREADS, OPT_AZIMUTH, OPT_ELEVATION, OPT_ZOOM, OPT_SLICES };
    static const struct option options[] = {
        {"output", required_argument, NULL, 'o'},           {"json", no_argument, NULL, OPT_JSON},
        {"list-joints", no_argument, NULL, OPT_LIST_JOINTS}, {"compare", no_argument, NULL, OPT_COMPARE},
        {"source", required_argument, NULL, OPT_SOURCE},     {"map", required_argument, NULL, OPT_MAP},
        {"caption", required_argument, NULL, OPT_CAPTION},   {"weights", required_argument, NULL, OPT_WEIGHTS},
        {"focus", required_argument, NULL, OPT_FOCUS},       {"pose", required_argument, NULL, OPT_POSE},
        {"frames", required_argument, NULL, OPT_FRAMES},     {"times", required_argument, NULL, OPT_TIMES},
        {"turntable", required_argument, NULL, OPT_TURNTABLE}, {"method", required_argument, NULL, OPT_METHOD},
        {"skin", required_argument, NULL, OPT_SKIN},         {"fit", required_argument, NULL, OPT_FIT},
        {"hide", required_argument, NULL, OPT_HIDE},         {"size", required_argument, NULL, OPT_SIZE},
        {"supersample", required_argument, NULL, OPT_SUPERSAMPLE},
        {"threads", required_argument, NULL, OPT_THREADS},   {"azimuth", required_argument, NULL, OPT_AZIMUTH},
        {"elevation", required_argument, NULL, OPT_ELEVATION}, {"zoom", required_argument, NULL, OPT_ZOOM},
        {"slices", no_argument, NULL, OPT_SLICES},
        {"help", no_argument, NULL, 'h'},                    {0}};
    pose_cli cli;
    pose_cli_begin(&cli, "pose-render", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;) {
        const char *a = cli.name, *v = cli.value;
        long l;
        switch (c) {
        case 'h':
            ex_render_usage(stdout);
            return 1;
        case OPT_JSON:
            o->json = 1;
            break;
        case OPT_LIST_JOINTS:
            o->list_joints = 1;
            break;
        case OPT_COMPARE:
            o->compare = 1;
            break;
        case OPT_SLICES:
            o->slices = 1;
            break;
        case POSE_CLI_ARGUMENT:
            if (o->rig) {
                snprintf(err, err_size, "unexpected argument '%s' (one rig only)", v);
                return -1;
            }
            o->rig = v;
            break;
        case 'o':
            o->output = v;
            break;
        case OPT_SOURCE:
            o->source = v;
            break;
        case OPT_MAP:
            o->map = v;
            break;
        case OPT_CAPTION:
            o->caption = v;
            break;
        case OPT_WEIGHTS:
            o->weights = v;
            break;
        case OPT_FOCUS:
            o->focus = v;
            break;
        case OPT_POSE:
            if (o->pose_count == EX_RENDER_MAX_POSES) {
                snprintf(err, err_size, "--pose: at most %d joints", EX_RENDER_MAX_POSES);
                return -1;
            }
            o->poses[o->pose_count++] = v;
            break;
        case OPT_FRAMES:
            free(o->frames);
            if (ex_parse_frames(a, v, &o->frames, &o->frame_count, err, err_size) < 0)
                return -1;
            break;
        case OPT_TIMES:
            free(o->times);
            if (ex_parse_times(a, v, &o->times, &o->time_count, err, err_size) < 0)
                return -1;
            break;
        case OPT_TURNTABLE:
            if (ex_parse_long(a, v, 1, 3600, &l, err, err_size) < 0)
                return -1;
            o->turntable = (int)l;
            break;
        case OPT_METHOD:
            if ((o->method = ex_parse_method(v)) < 0) {
                snprintf(err, err_size, "--method: expected lbs, dqs, cor or fem, got '%s'", v);
                return -1;
            }
            break;
        case OPT_SKIN: {
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
            break;
        }
        case OPT_FIT:
            if (strcmp(v, "pose") && strcmp(v, "rest") && strcmp(v, "follow")) {
                snprintf(err, err_size, "--fit: expected pose, rest or follow, got '%s'", v);
                return -1;
            }
            o->fit_rest = !strcmp(v, "rest");
            o->follow = !strcmp(v, "follow");
            break;
        case OPT_HIDE:
            if (parse_kinds(v, &o->hide, err, err_size) < 0)
                return -1;
            break;
        case OPT_SIZE:
            if (ex_parse_size(a, v, &o->width, &o->height, err, err_size) < 0)
                return -1;
            break;
        case OPT_SUPERSAMPLE:
            if (ex_parse_long(a, v, 1, 4, &l, err, err_size) < 0)
                return -1;
            o->supersample = (int)l;
            break;
        case OPT_THREADS:
            if (ex_parse_long(a, v, 0, 256, &l, err, err_size) < 0)
                return -1;
            o->threads = (int)l;
            break;
        case OPT_AZIMUTH:
            if (ex_parse_double(a, v, -3600, 3600, &o->azimuth, err, err_size) < 0)
                return -1;
            o->have_azimuth = 1;
            break;
        case OPT_ELEVATION:
            if (ex_parse_double(a, v, -89, 89, &o->elevation, err, err_size) < 0)
                return -1;
            o->have_elevation = 1;
            break;
        case OPT_ZOOM:
            if (ex_parse_double(a, v, 0.05, 50, &o->zoom, err, err_size) < 0)
                return -1;
            break;
        default: /* POSE_CLI_ERROR: reported on stderr, err stays empty */
            return -1;
        }
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
    if (o->slices && o->compare) {
        snprintf(err, err_size, "--slices shows one pose: it does not combine with --compare");
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
    if ((long)o->width * o->height * o->supersample * o->supersample * (o->compare ? 4 : 1) > 64L << 20) {
        snprintf(err, err_size, "image too large: reduce --size or --supersample");
        return -1;
    }
    return 0;
}
