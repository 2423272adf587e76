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
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        }
        if (!strcmp(a, "--json")) {
            json = 1;
            continue;
        }
        if (a[0] != '-') {
            if (rig) {
                fprintf(stderr, "pose-export: unexpected argument '%s' (one rig only)\n", a);
                return 2;
            }
            rig = a;
            continue;
        }
        if (!v) {
            fprintf(stderr, "pose-export: %s needs a value (see --help)\n", a);
            return 2;
        }
        i++;
        if (!strcmp(a, "--obj"))
            obj = v;
        else if (!strcmp(a, "--ply"))
            ply = v;
        else if (!strcmp(a, "--vtu"))
            vtu = v;
        else if (!strcmp(a, "--source"))
            source = v;
        else if (!strcmp(a, "--map"))
            map = v;
        else if (!strcmp(a, "--weights"))
            weights = v;
        else if (!strcmp(a, "--pose") && npose < MAX_POSES)
            poses[npose++] = v;
        else if (!strcmp(a, "--frame")) {
            if (ex_parse_long(a, v, 0, 100000000, &frame, err, sizeof err) < 0) {
                fprintf(stderr, "pose-export: %s\n", err);
                return 2;
            }
        } else if (!strcmp(a, "--method")) {
            if ((method = ex_parse_method(v)) < 0) {
                fprintf(stderr, "pose-export: --method: expected lbs, dqs or cor, got '%s'\n", v);
                return 2;
            }
        } else {
            fprintf(stderr, "pose-export: unknown option '%s' (see --help)\n", a);
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
