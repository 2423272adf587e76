/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-export: write a posed rig to files that Blender, MeshLab, ParaView and
 * three.js open: tissues as OBJ (one file), PLY (one per tissue), binary glTF
 * or binary VTU surfaces, tet mesh as VTU; a whole session (--frames or
 * --times of a source) as a ParaView series (.pvd) and an animated glTF.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "ex_args.h"
#include "pose_cli.h"
#include "ex_export.h"
#include "ex_export_series.h"
#include "ex_gltf.h"
#include "ex_vtk.h"
#include "ex_motion.h"
#include "ex_scene.h"
#include "ex_volume_nifti.h"

enum { MAX_POSES = 64 };

static void usage(FILE *f)
{
    fputs("usage: pose-export RIG [options] (--obj FILE | --ply DIR | --vtu FILE | --glb FILE | --surfaces FILE |\n"
          "                                      --nifti PREFIX)...\n"
          "       pose-export RIG --source SRC [--map MAP] (--frames A-B:STEP | --times T,...) (--pvd FILE | --gltf-anim FILE)...\n"
          "Pose a rig and write the result; or pose it at many frames of a source and write the session.\n"
          "  --pose JOINT=RX,RY,RZ   set a joint (degrees, XYZ order; repeatable)\n"
          "  --source FILE --frame N take the pose from frame N of a source, through the bridge\n"
          "  --frames A-B:STEP       clip frames of --source to export (or a list: 0,30,60)\n"
          "  --times T0-T1:STEP      seconds of the source's recorded time instead (or a list: 0,2.5)\n"
          "  --map FILE              the bridge mapping file for --source\n"
          "  --method lbs|dqs|cor|fem skinning method (default: cor when the rig has CoR data)\n"
          "  --obj FILE              all tissues into one Wavefront OBJ (one object per tissue)\n"
          "  --ply DIR               one binary PLY per tissue, with normals\n"
          "  --vtu FILE              the posed tet mesh (VTK XML) with labels, displacement, weights\n"
          "  --weights JOINT         add this joint's weight to the VTU point data\n"
          "  --glb FILE              all tissues, posed, into one binary glTF (Blender, three.js)\n"
          "  --surfaces FILE         all tissue surfaces, posed, into one binary VTU (ParaView)\n"
          "  --pvd FILE              with --frames/--times: one surfaces VTU per frame beside FILE\n"
          "                          (FILE minus .pvd, then _00000.vtu ...) and the ParaView series FILE\n"
          "  --gltf-anim FILE        with --frames/--times: skin and bones as skinned meshes with the\n"
          "                          session's joint animation, one binary glTF (Blender, three.js)\n"
          "  --nifti PREFIX          the rig's scan (pose-bake --labels) posed: PREFIX_ct.nii.gz and\n"
          "                          PREFIX_labels.nii.gz on the scan's grid\n"
          "  --json                  print a JSON summary on stdout\n"
          "  -h, --help              this text\n",
          f);
}

int main(int argc, char **argv)
{
    const char *rig = NULL, *obj = NULL, *ply = NULL, *vtu = NULL, *source = NULL, *map = NULL, *weights = NULL;
    const char *glb = NULL, *surfaces = NULL, *pvd = NULL, *anim = NULL, *frames_arg = NULL, *times_arg = NULL;
    const char *nifti = NULL;
    int nifti_files = 0;
    long *frames = NULL;
    double *times = NULL;
    size_t nframes = 0;
    ex_export_series series = {0};
    const char *poses[MAX_POSES];
    int npose = 0, json = 0, method = -1;
    long frame = -1;
    char err[1024] = "";
    enum { OPT_POSE = POSE_CLI_LONG_ONLY, OPT_SOURCE, OPT_FRAME, OPT_MAP, OPT_METHOD, OPT_OBJ, OPT_PLY,
           OPT_VTU, OPT_WEIGHTS, OPT_JSON, OPT_FRAMES, OPT_TIMES, OPT_GLB, OPT_SURFACES, OPT_PVD, OPT_ANIM,
           OPT_NIFTI };
    static const struct option options[] = {
        {"pose", required_argument, NULL, OPT_POSE},       {"source", required_argument, NULL, OPT_SOURCE},
        {"frame", required_argument, NULL, OPT_FRAME},     {"map", required_argument, NULL, OPT_MAP},
        {"method", required_argument, NULL, OPT_METHOD},   {"obj", required_argument, NULL, OPT_OBJ},
        {"ply", required_argument, NULL, OPT_PLY},         {"vtu", required_argument, NULL, OPT_VTU},
        {"weights", required_argument, NULL, OPT_WEIGHTS}, {"json", no_argument, NULL, OPT_JSON},
        {"frames", required_argument, NULL, OPT_FRAMES},   {"times", required_argument, NULL, OPT_TIMES},
        {"glb", required_argument, NULL, OPT_GLB},         {"surfaces", required_argument, NULL, OPT_SURFACES},
        {"pvd", required_argument, NULL, OPT_PVD},         {"gltf-anim", required_argument, NULL, OPT_ANIM},
        {"nifti", required_argument, NULL, OPT_NIFTI},
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
        case OPT_FRAMES:
            frames_arg = cli.value;
            break;
        case OPT_TIMES:
            times_arg = cli.value;
            break;
        case OPT_GLB:
            glb = cli.value;
            break;
        case OPT_SURFACES:
            surfaces = cli.value;
            break;
        case OPT_PVD:
            pvd = cli.value;
            break;
        case OPT_ANIM:
            anim = cli.value;
            break;
        case OPT_NIFTI:
            nifti = cli.value;
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
                pose_cli_error(&cli, "--method: expected lbs, dqs, cor or fem, got '%s'", cli.value);
                return 2;
            }
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    }
    const int many = frames_arg || times_arg, one = obj || ply || vtu || glb || surfaces || nifti;
    if (!rig || (!one && !pvd && !anim)) {
        fprintf(stderr, "pose-export: need a rig and at least one of --obj, --ply, --vtu, --glb, --surfaces, "
                        "--nifti, --pvd, --gltf-anim (see --help)\n");
        return 2;
    }
    if ((frames_arg && times_arg) || (many && frame >= 0)) {
        fprintf(stderr, "pose-export: one of --frame, --frames, --times\n");
        return 2;
    }
    if (many ? !source || one || (!pvd && !anim) : (pvd || anim)) {
        fprintf(stderr, "pose-export: %s\n",
                many ? "--frames/--times need --source and write --pvd and/or --gltf-anim (the other outputs "
                       "hold one pose: use --frame)"
                     : "--pvd and --gltf-anim write a session: give --source with --frames or --times");
        return 2;
    }
    if (!many && (source != NULL) != (frame >= 0)) {
        fprintf(stderr, "pose-export: --source and --frame go together\n");
        return 2;
    }
    if ((glb || anim) && !ex_gltf_available()) {
        fprintf(stderr, "pose-export: this build writes no glTF (it was built without cJSON: apt-get install "
                        "libcjson-dev)\n");
        return 2;
    }
    if ((frames_arg && ex_parse_frames("--frames", frames_arg, &frames, &nframes, err, sizeof err) < 0) ||
        (times_arg && ex_parse_times("--times", times_arg, &times, &nframes, err, sizeof err) < 0)) {
        fprintf(stderr, "pose-export: %s\n", err);
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
    if (source && ex_motion_open(source, map, sc.rig, &motion, err, sizeof err) < 0)
        goto done;
    if (many) {
        series = (ex_export_series){.frames = frames, .times = times, .count = nframes, .pvd = pvd, .anim = anim};
        if (ex_export_series_run(&sc, motion, &series, err, sizeof err) < 0)
            goto done;
    }
    if (source && !many && ex_motion_set_frame(motion, sc.state, frame, err, sizeof err) < 0)
        goto done;
    if (!many && ex_scene_apply(&sc, err, sizeof err) < 0)
        goto done;
    if (glb && ex_gltf_write_posed(sc.state, glb, err, sizeof err) < 0)
        goto done;
    if (surfaces && ex_vtk_write_surfaces(sc.state, surfaces, err, sizeof err) < 0)
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
    if (nifti && ex_volume_write_nifti(sc.state, nifti, 0, &nifti_files, err, sizeof err) < 0)
        goto done;
    if (json) {
        printf("{\"rig\": ");
        ex_json_string(stdout, rig);
        printf(", \"method\": \"%s\", \"tissues\": %zu, \"apply_ms\": %.3f", ex_method_name(m), sc.tissue_count,
               sc.last_apply_ms);
        size_t nv = 0, nt = 0;
        for (int t = 0; t < (int)sc.tissue_count; t++) {
            pose_tissue_info ti;
            if (pose_rig_tissue_info(sc.rig, t, &ti) == POSE_OK) {
                nv += ti.vertex_count;
                nt += ti.triangle_count;
            }
        }
        printf(", \"tissue_vertices\": %zu, \"tissue_triangles\": %zu, ", nv, nt);
        ex_clamp_log_json(&sc.clamped, stdout);
        if (many)
            printf(", \"frames\": %zu, \"first_s\": %.6f, \"last_s\": %.6f, \"apply_ms_total\": %.3f, "
                   "\"skinned_meshes\": %zu",
                   nframes, series.first_s, series.last_s, series.apply_ms, anim ? series.meshes : (size_t)0);
        const char *keys[8] = {"obj", "ply", "vtu", "glb", "surfaces", "pvd", "gltf_anim", "nifti"},
                   *vals[8] = {obj, ply, vtu, glb, surfaces, pvd, anim, nifti};
        if (nifti)
            printf(", \"nifti_files\": %d", nifti_files);
        for (int k = 0; k < 8; k++)
            if (vals[k]) {
                printf(", \"%s\": ", keys[k]);
                ex_json_string(stdout, vals[k]);
            }
        printf("}\n");
    } else if (many) {
        printf("posed %s with %s at %zu times (%.3f-%.3f s; pose_apply %.1f ms in all)%s%s%s%s\n", rig,
               ex_method_name(m), nframes, series.first_s, series.last_s, series.apply_ms, pvd ? "; series " : "",
               pvd ? pvd : "", anim ? "; animated glTF " : "", anim ? anim : "");
    } else {
        printf("posed %s with %s (pose_apply %.2f ms)%s%s%s%s%s%s\n", rig, ex_method_name(m), sc.last_apply_ms,
               obj ? "; OBJ " : "", obj ? obj : "", ply ? "; PLY in " : "", ply ? ply : "", vtu ? "; VTU " : "",
               vtu ? vtu : "");
        if (glb || surfaces)
            printf("%s%s%s%s\n", glb ? "glTF " : "", glb ? glb : "", surfaces ? (glb ? "; surfaces " : "surfaces ") : "",
                   surfaces ? surfaces : "");
        if (nifti)
            printf("NIfTI: %d files %s_*.nii.gz\n", nifti_files, nifti);
    }
    rc = 0;
done:
    if (rc)
        fprintf(stderr, "pose-export: %s\n", err);
    ex_motion_close(motion);
    ex_scene_close(&sc);
    free(frames);
    free(times);
    return rc;
}
