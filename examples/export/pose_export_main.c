/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-export: write a posed rig to files that Blender, MeshLab and ParaView
 * open: tissues as OBJ (one file) or PLY (one per tissue), tet mesh as VTU.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "ex_args.h"
#include "pose_cli.h"
#include "ex_export.h"
#include "ex_motion.h"
#include "ex_scene.h"

enum { MAX_POSES = 64 };

static void usage(FILE *f)
{
    fputs("usage: pose-export RIG [options] (--obj FILE | --ply DIR | --vtu FILE)...\n"
          "Pose a rig and write the result.\n"
          "  --pose JOINT=RX,RY,RZ   set a joint (degrees, XYZ order; repeatable)\n"
          "  --source FILE --frame N take the pose from frame N of a source, through the bridge\n"
          "  --map FILE              the bridge mapping file for --source\n"
          "  --method lbs|dqs|cor    skinning method (default: cor when the rig has CoR data)\n"
          "  --obj FILE              all tissues into one Wavefront OBJ (one object per tissue)\n"
          "  --ply DIR               one binary PLY per tissue, with normals\n"
          "  --vtu FILE              the posed tet mesh (VTK XML) with labels, displacement, weights\n"
          "  --weights JOINT         add this joint's weight to the VTU point data\n"
          "  --json                  print a JSON summary on stdout\n"
          "  -h, --help              this text\n",
          f);
}

int main(int argc, char **argv)
{
    const char *rig = NULL, *obj = NULL, *ply = NULL, *vtu = NULL, *source = NULL, *map = NULL, *weights = NULL;
    const char *poses[MAX_POSES];
    int npose = 0, json = 0, method = -1;
    long frame = -1;
    char err[1024] = "";
    enum { OPT_POSE = POSE_CLI_LONG_ONLY, OPT_SOURCE, OPT_FRAME, OPT_MAP, OPT_METHOD, OPT_OBJ, OPT_PLY,
           OPT_VTU, OPT_WEIGHTS, OPT_JSON };
    static const struct option options[] = {
        {"pose", required_argument, NULL, OPT_POSE},       {"source", required_argument, NULL, OPT_SOURCE},
        {"frame", required_argument, NULL, OPT_FRAME},     {"map", required_argument, NULL, OPT_MAP},
        {"method", required_argument, NULL, OPT_METHOD},   {"obj", required_argument, NULL, OPT_OBJ},
        {"ply", required_argument, NULL, OPT_PLY},         {"vtu", required_argument, NULL, OPT_VTU},
        {"weights", required_argument, NULL, OPT_WEIGHTS}, {"json", no_argument, NULL, OPT_JSON},
        {"help", no_argument, NULL, 'h'},                  {0}};
    pose_cli cli;
    pose_cli_begin(&cli, "pose-export", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;) {
        switch (c) {
        case 'h':
            usage(stdout);
            return 0;
        case OPT_JSON:
            json = 1;
            break;
        case POSE_CLI_ARGUMENT:
            if (rig) {
                pose_cli_error(&cli, "unexpected argument '%s' (one rig only)", cli.value);
                return 2;
            }
            rig = cli.value;
            break;
        case OPT_OBJ:
            obj = cli.value;
            break;
        case OPT_PLY:
            ply = cli.value;
            break;
        case OPT_VTU:
            vtu = cli.value;
            break;
        case OPT_SOURCE:
            source = cli.value;
            break;
        case OPT_MAP:
            map = cli.value;
            break;
        case OPT_WEIGHTS:
            weights = cli.value;
            break;
        case OPT_POSE:
            if (npose == MAX_POSES) {
                pose_cli_error(&cli, "at most %d --pose options", MAX_POSES);
                return 2;
            }
            poses[npose++] = cli.value;
            break;
        case OPT_FRAME:
            if (pose_cli_long(&cli, 0, 100000000, &frame) < 0)
                return 2;
            break;
        case OPT_METHOD:
            if ((method = ex_parse_method(cli.value)) < 0) {
                pose_cli_error(&cli, "--method: expected lbs, dqs or cor, got '%s'", cli.value);
                return 2;
            }
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    }
    if (!rig || (!obj && !ply && !vtu)) {
        fprintf(stderr, "pose-export: need a rig and at least one of --obj, --ply, --vtu (see --help)\n");
        return 2;
    }
    if ((source != NULL) != (frame >= 0)) {
        fprintf(stderr, "pose-export: --source and --frame go together\n");
        return 2;
    }

    ex_scene sc;
    ex_motion *motion = NULL;
    int rc = 1, wj = -1;
    if (ex_scene_open(&sc, rig, err, sizeof err) < 0) {
        fprintf(stderr, "pose-export: %s\n", err);
        return 1;
    }
    pose_tet_info tet;
    int has_cor = pose_rig_tet_info(sc.rig, &tet) == POSE_OK && tet.cor != NULL;
    pose_method m = method >= 0 ? (pose_method)method : has_cor ? POSE_COR : POSE_LBS;
    if (pose_set_method(sc.state, m) < 0) {
        snprintf(err, sizeof err, "--method %s: %s", ex_method_name(m), pose_last_error());
        goto done;
    }
    if (weights && (wj = pose_rig_find_joint(sc.rig, weights)) < 0) {
        snprintf(err, sizeof err, "--weights: the rig has no joint '%s'", weights);
        goto done;
    }
    for (int i = 0; i < npose; i++)
        if (ex_scene_set_pose_arg(&sc, poses[i], err, sizeof err) < 0)
            goto done;
    if (source && (ex_motion_open(source, map, sc.rig, &motion, err, sizeof err) < 0 ||
                   ex_motion_set_frame(motion, sc.state, frame, err, sizeof err) < 0))
        goto done;
    if (ex_scene_apply(&sc, err, sizeof err) < 0)
        goto done;
    if (obj && ex_export_obj(sc.state, obj, err, sizeof err) < 0)
        goto done;
    if (ply) {
        struct stat sb;
        if (mkdir(ply, 0777) < 0 && !(stat(ply, &sb) == 0 && S_ISDIR(sb.st_mode))) {
            snprintf(err, sizeof err, "%s: cannot create the folder", ply);
            goto done;
        }
        if (ex_export_ply(sc.state, ply, err, sizeof err) < 0)
            goto done;
    }
    if (vtu && ex_export_vtu(sc.state, vtu, wj, err, sizeof err) < 0)
        goto done;
    if (json) {
        printf("{\"rig\": ");
        ex_json_string(stdout, rig);
        printf(", \"method\": \"%s\", \"tissues\": %zu, \"apply_ms\": %.3f", ex_method_name(m), sc.tissue_count,
               sc.last_apply_ms);
        printf(", ");
        ex_clamp_log_json(&sc.clamped, stdout);
        const char *keys[3] = {"obj", "ply", "vtu"}, *vals[3] = {obj, ply, vtu};
        for (int k = 0; k < 3; k++)
            if (vals[k]) {
                printf(", \"%s\": ", keys[k]);
                ex_json_string(stdout, vals[k]);
            }
        printf("}\n");
    } else {
        printf("posed %s with %s (pose_apply %.2f ms)%s%s%s%s%s%s\n", rig, ex_method_name(m), sc.last_apply_ms,
               obj ? "; OBJ " : "", obj ? obj : "", ply ? "; PLY in " : "", ply ? ply : "", vtu ? "; VTU " : "",
               vtu ? vtu : "");
    }
    rc = 0;
done:
    if (rc)
        fprintf(stderr, "pose-export: %s\n", err);
    ex_motion_close(motion);
    ex_scene_close(&sc);
    return rc;
}
