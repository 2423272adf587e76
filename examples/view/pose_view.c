/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-view: an interactive viewer for a rig (GLFW, legacy OpenGL). Orbit,
 * pan and zoom; show or hide tissues; colour the tet mesh by a joint's
 * weight; switch LBS/DQS/CoR; pick a joint and rotate it (the rig's limits
 * apply); drive the pose from a bridge source with play/pause/step/seek;
 * show a slice plane of the rig's scan (pose-bake --labels), posed alike.
 */
#include <GLFW/glfw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ex_args.h"
#include "ex_camera.h"
#include "ex_draw.h"
#include "ex_motion.h"
#include "ex_scene.h"
#include "ex_slice_plane.h"
#include "ex_volume_posed.h"
#include "pose_cli.h"

typedef struct viewer {
    ex_scene sc;
    ex_camera cam;
    ex_motion *motion;
    int joint;           /* selected joint */
    float (*euler)[3];   /* per joint, the hand-set angles in degrees */
    int show_joints, show_help;
    double fps, last_mouse[2];
    int dragging;        /* 0, 1 orbit, 2 pan */
    ex_volume_posed vol; /* the rig's scan, posed: opened with the first slice plane */
    ex_slice_plane plane;
    char status[1024];
} viewer;

/* Show slice plane `axis` (-1 hides it; -2 the next one), opening the scan the first time. */
static void show_plane(viewer *v, int axis)
{
    if (!v->vol.sampler && ex_volume_posed_open(&v->vol, v->sc.rig, 0, v->status, sizeof v->status) < 0)
        return;
    if ((axis == -2 ? ex_slice_plane_cycle(&v->plane, &v->vol) : ex_slice_plane_show(&v->plane, &v->vol, axis)) < 0)
        snprintf(v->status, sizeof v->status, "out of memory for the slice plane");
    else if (v->plane.axis >= 0)
        snprintf(v->status, sizeof v->status, "slice plane: %s %d", ex_slice_plane_name(v->plane.axis),
                 v->plane.index);
    else
        v->status[0] = 0;
}

static void usage(FILE *f)
{
    fputs("usage: pose-view RIG [options]\n"
          "Interactive viewer (needs a display).\n"
          "  --source SPEC           drive the pose through the bridge, in real time: a clip\n"
          "                          (.bvh, .amc), a hid-recorder file (.hid), /dev/hidrawN or\n"
          "                          hid:VID:PID, a candump log (.log) or a CAN interface (can0)\n"
          "  --map FILE              the bridge mapping file for --source (bridge/maps/)\n"
          "  --method lbs|dqs|cor|fem initial skinning method (default: cor when the rig has CoR data)\n"
          "  --pose JOINT=RX,RY,RZ   initial joint angles (degrees; repeatable)\n"
          "  --size WxH              window size (default 1280x800)\n"
          "  --slice PLANE           start with a slice plane of the rig's scan (pose-bake --labels),\n"
          "                          posed alike: axial, coronal or sagittal (key V cycles them)\n"
          "  --quit-after N          close after N frames and print the frame rate (smoke tests)\n"
          "  --json                  at exit, a JSON summary on stdout (frames, fps, method, source,\n"
          "                          clamped --pose requests) instead of the line --quit-after prints\n"
          "  -h, --help              this text\n"
          "Mouse: drag orbit, right drag pan, wheel zoom, ctrl+click pick a joint, shift+drag rotate it\n"
          "Keys: 1 LBS 2 DQS 3 CoR | S skin\n"
          "  (translucent/opaque/hidden) B bones M muscles O organs T other | W weights of the\n"
          "  selected joint | [ ] select joint | X/Y/Z rotate +5 deg (Shift: -5) | R reset |\n"
          "  J joints | Space play/pause . step , back Home start Left/Right seek 1 s | F frame all |\n"
          "  H help | Esc quit\n",
          f);
}

static void toggle_kind(viewer *v, pose_tissue_kind kind)
{
    int any_visible = 0;
    for (size_t t = 0; t < v->sc.tissue_count; t++) {
        pose_tissue_info ti;
        if (pose_rig_tissue_info(v->sc.rig, (int)t, &ti) == POSE_OK && ti.kind == kind && v->sc.tissue_visible[t])
            any_visible = 1;
    }
    for (size_t t = 0; t < v->sc.tissue_count; t++) {
        pose_tissue_info ti;
        if (pose_rig_tissue_info(v->sc.rig, (int)t, &ti) == POSE_OK && ti.kind == kind)
            v->sc.tissue_visible[t] = (unsigned char)!any_visible;
    }
}

static void joint_name(const viewer *v, char *out, size_t n)
{
    pose_joint_info ji;
    snprintf(out, n, "%s", pose_rig_joint_info(v->sc.rig, v->joint, &ji) == POSE_OK ? ji.name : "?");
}

static void rotate_selected(viewer *v, int axis, float step)
{
    char name[64];
    v->euler[v->joint][axis] += step;
    pose_status st = pose_set_joint_euler(v->sc.state, v->joint, v->euler[v->joint], POSE_EULER_XYZ);
    joint_name(v, name, sizeof name);
    if (st == POSE_CLAMPED) {
        /* Keep the angles the rig accepted, so further presses start from the limit. */
        v->euler[v->joint][axis] -= step;
        pose_set_joint_euler(v->sc.state, v->joint, v->euler[v->joint], POSE_EULER_XYZ);
        snprintf(v->status, sizeof v->status, "%s: at its limit (%s)", name, pose_last_error());
    } else if (st < 0) {
        snprintf(v->status, sizeof v->status, "%s: %s", name, pose_last_error());
    } else {
        snprintf(v->status, sizeof v->status, "%s = %.0f, %.0f, %.0f deg", name, v->euler[v->joint][0],
                 v->euler[v->joint][1], v->euler[v->joint][2]);
    }
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    viewer *v = glfwGetWindowUserPointer(w);
    if (action == GLFW_RELEASE)
        return;
    char err[512];
    float step = (mods & GLFW_MOD_SHIFT) ? -5.0f : 5.0f;
    size_t nj = pose_rig_joint_count(v->sc.rig);
    double dt = v->motion ? ex_motion_frame_time(v->motion) : 0.0, now = v->motion ? ex_motion_time(v->motion) : 0.0;
    switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q: glfwSetWindowShouldClose(w, 1); break;
    case GLFW_KEY_1:
    case GLFW_KEY_2:
    case GLFW_KEY_3:
        if (pose_set_method(v->sc.state, (pose_method)(key - GLFW_KEY_1)) < 0)
            snprintf(v->status, sizeof v->status, "%s", pose_last_error());
        else
            snprintf(v->status, sizeof v->status, "method %s", ex_method_name(pose_get_method(v->sc.state)));
        break;
    case GLFW_KEY_S: v->sc.skin_mode = v->sc.skin_mode == EX_SKIN_HIDDEN ? EX_SKIN_TRANSLUCENT
                                       : v->sc.skin_mode == EX_SKIN_OPAQUE ? EX_SKIN_HIDDEN
                                       : v->sc.skin_mode == EX_SKIN_TRANSLUCENT ? EX_SKIN_OPAQUE
                                       : ex_scene_skin_translucent(&v->sc) ? EX_SKIN_OPAQUE : EX_SKIN_HIDDEN;
        break;
    case GLFW_KEY_B: toggle_kind(v, POSE_TISSUE_BONE); break;
    case GLFW_KEY_M: toggle_kind(v, POSE_TISSUE_MUSCLE); break;
    case GLFW_KEY_O: toggle_kind(v, POSE_TISSUE_ORGAN); break;
    case GLFW_KEY_T: toggle_kind(v, POSE_TISSUE_OTHER); break;
    case GLFW_KEY_W:
        if (ex_scene_set_weight_joint(&v->sc, v->sc.weight_joint >= 0 ? -1 : v->joint, err, sizeof err) < 0)
            snprintf(v->status, sizeof v->status, "%s", err);
        break;
    case GLFW_KEY_LEFT_BRACKET:
    case GLFW_KEY_RIGHT_BRACKET:
        v->joint = (int)(((size_t)v->joint + (key == GLFW_KEY_LEFT_BRACKET ? nj - 1 : 1)) % nj);
        if (v->sc.weight_joint >= 0)
            ex_scene_set_weight_joint(&v->sc, v->joint, err, sizeof err);
        joint_name(v, err, sizeof err);
        snprintf(v->status, sizeof v->status, "selected %s", err);
        break;
    case GLFW_KEY_X: rotate_selected(v, 0, step); break;
    case GLFW_KEY_Y: rotate_selected(v, 1, step); break;
    case GLFW_KEY_Z: rotate_selected(v, 2, step); break;
    case GLFW_KEY_R:
        pose_reset(v->sc.state);
        memset(v->euler, 0, nj * sizeof *v->euler);
        snprintf(v->status, sizeof v->status, "rest pose");
        break;
    case GLFW_KEY_J: v->show_joints = !v->show_joints; break;
    case GLFW_KEY_V: show_plane(v, -2); break;
    case GLFW_KEY_PAGE_UP:
    case GLFW_KEY_PAGE_DOWN:
        if (v->plane.axis >= 0) {
            ex_slice_plane_move(&v->plane, &v->vol, (key == GLFW_KEY_PAGE_UP ? 1 : -1) * ((mods & GLFW_MOD_SHIFT) ? 10 : 1));
            snprintf(v->status, sizeof v->status, "slice plane: %s %d", ex_slice_plane_name(v->plane.axis),
                     v->plane.index);
        }
        break;
    case GLFW_KEY_H: v->show_help = !v->show_help; break;
    case GLFW_KEY_F: {
        float bmin[3], bmax[3];
        int fw, fh;
        glfwGetFramebufferSize(w, &fw, &fh);
        ex_scene_bounds(&v->sc, 1, bmin, bmax);
        ex_camera_frame(&v->cam, bmin, bmax, fh > 0 ? (float)fw / (float)fh : 1.0f);
        break;
    }
    /* Playback runs on the bridge's thread; these only send it commands. */
    case GLFW_KEY_SPACE:
        if (v->motion)
            ex_motion_pause(v->motion, !ex_motion_paused(v->motion));
        break;
    case GLFW_KEY_PERIOD:
        if (v->motion)
            ex_motion_step(v->motion, 1);
        break;
    case GLFW_KEY_COMMA:
        if (v->motion) {
            ex_motion_pause(v->motion, 1);
            ex_motion_seek(v->motion, now - dt);
        }
        break;
    case GLFW_KEY_HOME:
        if (v->motion)
            ex_motion_seek(v->motion, 0.0);
        break;
    case GLFW_KEY_RIGHT:
    case GLFW_KEY_LEFT:
        if (v->motion)
            ex_motion_seek(v->motion, now + (key == GLFW_KEY_RIGHT ? 1.0 : -1.0));
        break;
    default: break;
    }
}

/* The joint whose centre is drawn nearest to window point (x, y), within 25 pixels, or -1. */
static int pick_joint(viewer *v, GLFWwindow *w, double x, double y)
{
    int ww, wh, fw, fh, best = -1;
    float view[16], proj[16], best_d2 = 25.0f * 25.0f;
    glfwGetWindowSize(w, &ww, &wh);
    glfwGetFramebufferSize(w, &fw, &fh);
    if (ww <= 0 || wh <= 0 || fh <= 0)
        return -1;
    ex_camera_view(&v->cam, view);
    ex_camera_projection(&v->cam, (float)fw / (float)fh, proj);
    for (size_t j = 0; j < pose_rig_joint_count(v->sc.rig); j++) {
        pose_transform xf;
        if (pose_joint_world(v->sc.state, (int)j, &xf) < 0)
            continue;
        float e[4], c[4];
        for (int r = 0; r < 4; r++) /* eye space, then clip space (column-major matrices) */
            e[r] = view[r] * xf.translation[0] + view[4 + r] * xf.translation[1] + view[8 + r] * xf.translation[2] +
                   view[12 + r];
        for (int r = 0; r < 4; r++)
            c[r] = proj[r] * e[0] + proj[4 + r] * e[1] + proj[8 + r] * e[2] + proj[12 + r] * e[3];
        if (c[3] <= 0.0f)
            continue;
        float sx = (c[0] / c[3] * 0.5f + 0.5f) * (float)ww, sy = (0.5f - c[1] / c[3] * 0.5f) * (float)wh;
        float d2 = (sx - (float)x) * (sx - (float)x) + (sy - (float)y) * (sy - (float)y);
        if (d2 < best_d2) {
            best_d2 = d2;
            best = (int)j;
        }
    }
    return best;
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    viewer *v = glfwGetWindowUserPointer(w);
    if (action != GLFW_PRESS) {
        v->dragging = 0;
        return;
    }
    glfwGetCursorPos(w, &v->last_mouse[0], &v->last_mouse[1]);
    if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_CONTROL)) {
        int j = pick_joint(v, w, v->last_mouse[0], v->last_mouse[1]);
        char name[64];
        if (j >= 0) {
            v->joint = j;
            v->show_joints = 1;
            joint_name(v, name, sizeof name);
            snprintf(v->status, sizeof v->status, "selected %s (shift+drag rotates it)", name);
        }
        return;
    }
    v->dragging = button != GLFW_MOUSE_BUTTON_LEFT ? 2 : (mods & GLFW_MOD_SHIFT) ? 3 : 1;
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    viewer *v = glfwGetWindowUserPointer(w);
    double dx = x - v->last_mouse[0], dy = y - v->last_mouse[1];
    v->last_mouse[0] = x;
    v->last_mouse[1] = y;
    if (v->dragging == 1) {
        v->cam.azimuth_deg -= (float)dx * 0.4f;
        v->cam.elevation_deg += (float)dy * 0.4f;
        if (v->cam.elevation_deg > 89.0f)
            v->cam.elevation_deg = 89.0f;
        if (v->cam.elevation_deg < -89.0f)
            v->cam.elevation_deg = -89.0f;
    } else if (v->dragging == 2) {
        ex_camera_pan(&v->cam, -(float)dx * 0.0015f, (float)dy * 0.0015f);
    } else if (v->dragging == 3) {
        /* Vertical drag: the joint's local y (flexion of the template's hinges), horizontal: local z. */
        if (dy != 0.0)
            rotate_selected(v, 1, (float)dy * 0.5f);
        if (dx != 0.0)
            rotate_selected(v, 2, (float)dx * 0.5f);
    }
}

static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    (void)dx;
    viewer *v = glfwGetWindowUserPointer(w);
    v->cam.distance *= powf(0.9f, (float)dy);
}

static void hud(viewer *v, int fw, int fh)
{
    static const float white[4] = {0.92f, 0.92f, 0.92f, 1.0f}, dim[4] = {0.7f, 0.75f, 0.8f, 1.0f};
    char line[512], name[64];
    joint_name(v, name, sizeof name);
    snprintf(line, sizeof line, "%.0f fps  pose_apply %.2f ms  %s  joint %s%s", v->fps, v->sc.last_apply_ms,
             ex_method_name(pose_get_method(v->sc.state)), name,
             v->sc.weight_joint >= 0 ? "  (weights)" : "");
    ex_draw_text(10, 10, 2, white, line, fw, fh);
    if (v->motion)
        ex_draw_text(10, 30, 2, dim, ex_motion_status(v->motion), fw, fh);
    if (v->status[0])
        ex_draw_text(10, fh - 24, 2, dim, v->status, fw, fh);
    if (v->show_help) {
        static const char *help[] = {
            "drag: orbit   right drag: pan   wheel: zoom   F: frame all",
            "ctrl+click: pick a joint   shift+drag: rotate it (limits apply)",
            "1/2/3: LBS/DQS/CoR   S: skin   B/M/O/T: bones/muscles/organs/other",
            "[ ]: select joint   X/Y/Z: rotate +5 (shift -5)   R: reset   J: joints",
            "W: weights of joint   space: play   . , : step   left/right: seek 1 s",
            "V: slice plane of the scan (axial/coronal/sagittal/off)   PgUp/PgDn: move it (shift: 10)",
            "H: hide this help   Esc: quit"};
        for (size_t i = 0; i < sizeof help / sizeof help[0]; i++)
            ex_draw_text(10, 56 + 18 * (int)i, 2, dim, help[i], fw, fh);
    }
}

/* What the session did, for scripts: the --json summary printed when the window closes. */
static void print_summary_json(viewer *v, const char *rig, long frames, double seconds, double apply_sum_ms)
{
    printf("{\"rig\": ");
    ex_json_string(stdout, rig);
    printf(", \"frames\": %ld, \"seconds\": %.3f, \"fps\": %.2f, \"apply_ms_mean\": %.4f, \"method\": \"%s\", ",
           frames, seconds, seconds > 0 ? (double)frames / seconds : 0.0,
           frames > 0 ? apply_sum_ms / (double)frames : 0.0, ex_method_name(pose_get_method(v->sc.state)));
    ex_clamp_log_json(&v->sc.clamped, stdout);
    if (v->motion) {
        printf(", \"source\": ");
        ex_json_string(stdout, ex_motion_status(v->motion));
    }
    if (v->plane.axis >= 0)
        printf(", \"slice\": {\"axis\": \"%s\", \"index\": %d, \"labelled_texels\": %ld, \"gl_error\": %u}",
               ex_slice_plane_name(v->plane.axis), v->plane.index, v->plane.labelled_texels, v->plane.gl_error);
    printf("}\n");
}

int main(int argc, char **argv)
{
    const char *rig = NULL, *source = NULL, *map = NULL, *poses[64], *slice = NULL;
    int npose = 0, method = -1, width = 1280, height = 800, json = 0;
    long quit_after = 0;
    char err[1024] = "";
    enum { OPT_SOURCE = POSE_CLI_LONG_ONLY, OPT_MAP, OPT_POSE, OPT_METHOD, OPT_SIZE, OPT_QUIT_AFTER, OPT_JSON,
           OPT_SLICE };
    static const struct option options[] = {
        {"source", required_argument, NULL, OPT_SOURCE}, {"map", required_argument, NULL, OPT_MAP},
        {"pose", required_argument, NULL, OPT_POSE},     {"method", required_argument, NULL, OPT_METHOD},
        {"size", required_argument, NULL, OPT_SIZE},     {"quit-after", required_argument, NULL, OPT_QUIT_AFTER},
        {"json", no_argument, NULL, OPT_JSON},           {"help", no_argument, NULL, 'h'},
        {"slice", required_argument, NULL, OPT_SLICE},
        {0}};
    pose_cli cli;
    pose_cli_begin(&cli, "pose-view", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;) {
        switch (c) {
        case 'h':
            usage(stdout);
            return 0;
        case POSE_CLI_ARGUMENT:
            if (rig) {
                pose_cli_error(&cli, "unexpected argument '%s' (one rig only)", cli.value);
                return 2;
            }
            rig = cli.value;
            break;
        case OPT_SOURCE:
            source = cli.value;
            break;
        case OPT_MAP:
            map = cli.value;
            break;
        case OPT_POSE:
            if (npose == 64) {
                pose_cli_error(&cli, "at most 64 --pose options");
                return 2;
            }
            poses[npose++] = cli.value;
            break;
        case OPT_METHOD:
            if ((method = ex_parse_method(cli.value)) < 0) {
                pose_cli_error(&cli, "--method: expected lbs, dqs, cor or fem, got '%s'", cli.value);
                return 2;
            }
            break;
        case OPT_SIZE:
            if (ex_parse_size(cli.name, cli.value, &width, &height, err, sizeof err) < 0) {
                pose_cli_error(&cli, "%s", err);
                return 2;
            }
            break;
        case OPT_QUIT_AFTER:
            if (pose_cli_long(&cli, 1, 1000000, &quit_after) < 0)
                return 2;
            break;
        case OPT_JSON:
            json = 1;
            break;
        case OPT_SLICE:
            if (ex_slice_plane_parse(cli.value) < -1) {
                pose_cli_error(&cli, "--slice: expected axial, coronal, sagittal or off, got '%s'", cli.value);
                return 2;
            }
            slice = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    }
    if (!rig) {
        fprintf(stderr, "pose-view: no rig given (usage: pose-view RIG [options]; see --help)\n");
        return 2;
    }

    viewer v;
    memset(&v, 0, sizeof v);
    v.show_help = 1;
    v.plane.axis = -1;
    if (ex_scene_open(&v.sc, rig, err, sizeof err) < 0) {
        fprintf(stderr, "pose-view: %s\n", err);
        return 1;
    }
    int rc = 1;
    GLFWwindow *win = NULL;
    v.euler = calloc(pose_rig_joint_count(v.sc.rig) + 1, sizeof *v.euler);
    if (!v.euler) {
        snprintf(err, sizeof err, "out of memory");
        goto done;
    }
    if (method < 0) { /* like pose-render: CoR when the rig has the data */
        pose_tet_info tet;
        method = pose_rig_tet_info(v.sc.rig, &tet) == POSE_OK && tet.cor ? POSE_COR : POSE_LBS;
    }
    if (pose_set_method(v.sc.state, (pose_method)method) < 0) {
        snprintf(err, sizeof err, "--method: %s", pose_last_error());
        goto done;
    }
    for (int i = 0; i < npose; i++)
        if (ex_scene_set_pose_arg(&v.sc, poses[i], err, sizeof err) < 0)
            goto done;
    if (source) {
        if (ex_motion_open(source, map, v.sc.rig, &v.motion, err, sizeof err) < 0)
            goto done;
    }
    if (slice && ex_slice_plane_parse(slice) >= 0) {
        show_plane(&v, ex_slice_plane_parse(slice));
        if (!v.vol.sampler) {
            snprintf(err, sizeof err, "--slice: %.900s", v.status);
            goto done;
        }
    }
    /* Check for a display before GLFW does, to say what is missing in plain words. */
    const char *display = getenv("DISPLAY"), *wayland = getenv("WAYLAND_DISPLAY");
    if ((!display || !*display) && (!wayland || !*wayland)) {
        snprintf(err, sizeof err, "no display (DISPLAY and WAYLAND_DISPLAY are unset); for images without a "
                                  "display use pose-render");
        goto done;
    }
    if (!glfwInit()) {
        const char *desc = NULL;
        glfwGetError(&desc);
        snprintf(err, sizeof err, "cannot open the display: %s (for images without a display use pose-render)",
                 desc ? desc : "glfwInit failed");
        goto done;
    }
    glfwWindowHint(GLFW_SAMPLES, 4);
    char title[512];
    snprintf(title, sizeof title, "pose-view - %s", rig);
    win = glfwCreateWindow(width, height, title, NULL, NULL);
    if (!win) {
        const char *desc = NULL;
        glfwGetError(&desc);
        snprintf(err, sizeof err, "cannot create an OpenGL window: %s", desc ? desc : "unknown error");
        goto done;
    }
    glfwMakeContextCurrent(win);
    glfwSwapInterval(1);
    glfwSetWindowUserPointer(win, &v);
    glfwSetKeyCallback(win, on_key);
    glfwSetMouseButtonCallback(win, on_button);
    glfwSetCursorPosCallback(win, on_cursor);
    glfwSetScrollCallback(win, on_scroll);
    {
        float bmin[3], bmax[3];
        ex_scene_bounds(&v.sc, 1, bmin, bmax);
        ex_camera_frame(&v.cam, bmin, bmax, (float)width / (float)height);
    }
    v.joint = pose_rig_joint_count(v.sc.rig) > 1 ? 1 : 0;
    if (v.motion && ex_motion_start(v.motion, err, sizeof err) < 0)
        goto done;
    double fps_t = glfwGetTime(), start = fps_t, apply_sum = 0.0;
    int frames = 0;
    long total = 0;
    while (!glfwWindowShouldClose(win) && (!quit_after || total < quit_after)) {
        double now = glfwGetTime();
        /* The newest pose the bridge thread published, if any; never waits for it. */
        if (v.motion && ex_motion_poll(v.motion, v.sc.state, err, sizeof err) < 0)
            snprintf(v.status, sizeof v.status, "%s", err);
        if (ex_scene_apply(&v.sc, err, sizeof err) < 0)
            goto done;
        int fw, fh;
        glfwGetFramebufferSize(win, &fw, &fh);
        static const float bg[3] = {0.13f, 0.14f, 0.17f};
        ex_draw_scene(&v.sc, &v.cam, 0, 0, fw, fh, bg);
        if (v.plane.axis >= 0) {
            if (ex_volume_posed_update(&v.vol, v.sc.state, err, sizeof err) < 0)
                goto done;
            ex_slice_plane_draw(&v.plane, &v.vol);
        }
        if (v.show_joints)
            ex_draw_joints(&v.sc, v.joint);
        hud(&v, fw, fh);
        glfwSwapBuffers(win);
        glfwPollEvents();
        frames++;
        total++;
        apply_sum += v.sc.last_apply_ms;
        if (now - fps_t >= 0.5) {
            v.fps = frames / (now - fps_t);
            frames = 0;
            fps_t = now;
        }
    }
    if (json)
        print_summary_json(&v, rig, total, glfwGetTime() - start, apply_sum);
    else if (quit_after && total > 0)
        printf("pose-view: %ld frames in %.2f s (%.1f fps), mean pose_apply %.3f ms, method %s%s%s\n", total,
               glfwGetTime() - start, (double)total / (glfwGetTime() - start), apply_sum / (double)total,
               ex_method_name(pose_get_method(v.sc.state)), v.motion ? ", source " : "",
               v.motion ? ex_motion_status(v.motion) : "");
    rc = 0;
done:
    if (rc)
        fprintf(stderr, "pose-view: %s\n", err);
    ex_slice_plane_free(&v.plane); /* its texture (if any) while the context lives */
    ex_volume_posed_close(&v.vol);
    if (win)
        glfwDestroyWindow(win);
    glfwTerminate();
    ex_motion_close(v.motion);
    free(v.euler);
    ex_scene_close(&v.sc);
    return rc;
}
