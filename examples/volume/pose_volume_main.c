/* SPDX-License-Identifier: Apache-2.0
 * pose-volume: pose a CT and its labels with a rig baked from them
 * (pose-bake --labels) and write the posed image as NIfTI and slice PNGs.
 *
 *   pose-volume RIG --ct CT.nii.gz --labels SEG.nii.gz --pose hip_l=45,0,0 ...
 *               [--pad N] [--threads N] [--nifti PREFIX] [--png PREFIX] [--json]
 *
 * --pose JOINT=a,b,c: clinical angles in degrees where the joint has them
 * (flexion, abduction, rotation), else Euler XYZ about its rest frame.
 * The output grid is the scan's grown by --pad voxels per side (a flexed
 * thigh leaves a pelvic scan's field of view); PREFIX_ct.nii.gz and
 * PREFIX_labels.nii.gz keep the inputs' datatypes, units and intent;
 * PREFIX_rest.png and PREFIX_posed.png show axial, coronal and sagittal
 * slices through the posed joint, labels in colour. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <pose/pose.h>
#include <pose/volume.h>

#include "pose_cli.h"
#include "vol_nifti.h"
#include "vol_slices.h"
#include "vol_slices_image.h"

#define MAX_POSES 64

static void usage(FILE *f)
{
    fprintf(f, "usage: pose-volume RIG --ct CT.nii[.gz] --labels SEG.nii[.gz] [--pose JOINT=A,B,C]...\n"
               "                  [--pad N] [--threads N] [--nifti PREFIX] [--png PREFIX] [--json]\n"
               "Poses a scan with the rig pose-bake --labels made from it (model space: the scan's\n"
               "RAS in metres, facing +X, left +Y, up +Z) and writes PREFIX_ct.nii.gz,\n"
               "PREFIX_labels.nii.gz and PREFIX_rest.png / PREFIX_posed.png (slices).\n"
               "  --pose JOINT=A,B,C  clinical degrees (flexion, abduction, rotation), or Euler\n"
               "                      XYZ for a joint without clinical data; repeatable\n"
               "  --pad N             grow the output grid by N voxels per side (default 24)\n"
               "  --threads N         sampler threads (default 2)\n");
}

typedef struct pose_req {
    char joint[64];
    float deg[3];
} pose_req;

static int parse_pose(const char *s, pose_req *r)
{
    const char *eq = strchr(s, '=');
    if (!eq || eq == s || (size_t)(eq - s) >= sizeof r->joint)
        return -1;
    memcpy(r->joint, s, (size_t)(eq - s));
    r->joint[eq - s] = '\0';
    char tail;
    return sscanf(eq + 1, "%f,%f,%f%c", &r->deg[0], &r->deg[1], &r->deg[2], &tail) == 3 ? 0 : -1;
}

static int write_pair(const char *prefix, const pv_image *like_ct, const pv_image *like_seg,
                      const pose_volume_grid *g, int pad, const float *hu, const uint16_t *lab)
{
    pv_image ct = *like_ct, seg = *like_seg;
    ct.nx = seg.nx = g->nx, ct.ny = seg.ny = g->ny, ct.nz = seg.nz = g->nz;
    for (int a = 0; a < 3; a++) { /* the grid grown by pad voxels, in the scan's RAS */
        ct.affine[a][3] -= pad * (like_ct->affine[a][0] + like_ct->affine[a][1] + like_ct->affine[a][2]);
        seg.affine[a][3] = ct.affine[a][3];
    }
    size_t n = (size_t)g->nx * g->ny * g->nz;
    float *lf = malloc(n * sizeof *lf);
    if (!lf)
        return -1;
    for (size_t v = 0; v < n; v++)
        lf[v] = lab[v];
    ct.data = (float *)hu;
    seg.data = lf;
    char path[1024], err[512];
    int rc = 0;
    snprintf(path, sizeof path, "%s_ct.nii.gz", prefix);
    if (pv_nifti_write(path, &ct, 0, err, sizeof err) != 0)
        rc = -1, fprintf(stderr, "pose-volume: %s\n", err);
    snprintf(path, sizeof path, "%s_labels.nii.gz", prefix);
    if (rc == 0 && pv_nifti_write(path, &seg, 0, err, sizeof err) != 0)
        rc = -1, fprintf(stderr, "pose-volume: %s\n", err);
    free(lf);
    return rc;
}

int main(int argc, char **argv)
{
    const char *rig_path = NULL, *ct_path = NULL, *seg_path = NULL, *nifti = NULL, *png = NULL;
    pose_req req[MAX_POSES];
    int nreq = 0, pad = 24, threads = 2, json = 0, status = 2;
    enum { OPT_CT = POSE_CLI_LONG_ONLY, OPT_LABELS, OPT_POSE, OPT_PAD, OPT_THREADS, OPT_NIFTI, OPT_PNG,
           OPT_JSON };
    static const struct option options[] = {{"ct", required_argument, NULL, OPT_CT},
                                            {"labels", required_argument, NULL, OPT_LABELS},
                                            {"pose", required_argument, NULL, OPT_POSE},
                                            {"pad", required_argument, NULL, OPT_PAD},
                                            {"threads", required_argument, NULL, OPT_THREADS},
                                            {"nifti", required_argument, NULL, OPT_NIFTI},
                                            {"png", required_argument, NULL, OPT_PNG},
                                            {"json", no_argument, NULL, OPT_JSON},
                                            {"help", no_argument, NULL, 'h'},
                                            {0}};
    pose_cli cli;
    pose_cli_begin(&cli, "pose-volume", argc, argv, options);
    long l;
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;) {
        switch (c) {
        case 'h': usage(stdout); return 0;
        case POSE_CLI_ARGUMENT:
            if (rig_path) {
                pose_cli_error(&cli, "unexpected argument '%s'", cli.value);
                return 2;
            }
            rig_path = cli.value;
            break;
        case OPT_CT: ct_path = cli.value; break;
        case OPT_LABELS: seg_path = cli.value; break;
        case OPT_NIFTI: nifti = cli.value; break;
        case OPT_PNG: png = cli.value; break;
        case OPT_JSON: json = 1; break;
        case OPT_POSE:
            if (nreq == MAX_POSES || parse_pose(cli.value, &req[nreq]) != 0) {
                pose_cli_error(&cli, "--pose is JOINT=A,B,C in degrees (got '%s')", cli.value);
                return 2;
            }
            nreq++;
            break;
        case OPT_PAD:
            if (pose_cli_long(&cli, 0, 256, &l) < 0)
                return 2;
            pad = (int)l;
            break;
        case OPT_THREADS:
            if (pose_cli_long(&cli, 1, 256, &l) < 0)
                return 2;
            threads = (int)l;
            break;
        default: return 2;
        }
    }
    if (!rig_path || !ct_path || !seg_path) {
        fprintf(stderr, "pose-volume: RIG, --ct and --labels are required (see --help)\n");
        return 2;
    }
    char err[512];
    pv_image ct = {0}, seg = {0};
    pose_rig *rig = NULL;
    pose_state *rest = NULL, *st = NULL;
    pose_volume_sampler *s = NULL;
    float *hu = NULL, *hu0 = NULL;
    uint16_t *lab = NULL, *lab_in = NULL, *lab0 = NULL;
    if (pv_nifti_read(ct_path, &ct, err, sizeof err) || pv_nifti_read(seg_path, &seg, err, sizeof err)) {
        fprintf(stderr, "pose-volume: %s\n", err);
        status = 1;
        goto out;
    }
    if (seg.nx != ct.nx || seg.ny != ct.ny || seg.nz != ct.nz) {
        fprintf(stderr, "pose-volume: %s and %s are on different grids\n", ct_path, seg_path);
        status = 1;
        goto out;
    }
    if (pose_rig_load(rig_path, &rig) != POSE_OK || pose_state_create(rig, &rest) != POSE_OK ||
        pose_state_create(rig, &st) != POSE_OK) {
        fprintf(stderr, "pose-volume: %s\n", pose_last_error());
        status = 1;
        goto out;
    }
    for (int i = 0; i < nreq; i++) {
        int j = pose_rig_find_joint(rig, req[i].joint);
        pose_joint_clinical jc;
        pose_status ps = j < 0 ? POSE_ERR_NOT_FOUND
                         : pose_rig_joint_clinical(rig, j, &jc) == POSE_OK
                             ? pose_set_joint_clinical(st, j, req[i].deg)
                             : pose_set_joint_euler(st, j, req[i].deg, POSE_EULER_XYZ);
        if (ps < 0) {
            fprintf(stderr, "pose-volume: --pose %s: %s\n", req[i].joint,
                    j < 0 ? "no such joint in the rig" : pose_last_error());
            status = 1;
            goto out;
        }
    }
    pose_apply(rest);
    pose_apply(st);
    size_t nin = pv_image_voxels(&ct);
    lab_in = malloc(nin * sizeof *lab_in);
    for (size_t v = 0; lab_in && v < nin; v++)
        lab_in[v] = (uint16_t)(seg.data[v] < 0 ? 0 : seg.data[v] > 65535 ? 65535 : seg.data[v]);
    double m[3][4];
    pv_image_model_affine(&ct, m);
    pose_volume_grid g = {(uint32_t)(ct.nx + 2 * pad), (uint32_t)(ct.ny + 2 * pad),
                          (uint32_t)(ct.nz + 2 * pad), {{0}}};
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 4; c++)
            g.affine[a][c] = (float)(c < 3 ? m[a][c] : m[a][3] - pad * (m[a][0] + m[a][1] + m[a][2]));
    pose_volume_desc desc = {{(uint32_t)ct.nx, (uint32_t)ct.ny, (uint32_t)ct.nz, {{0}}}, ct.data, lab_in,
                             -1024.0f, 0};
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 4; c++)
            desc.grid.affine[a][c] = (float)m[a][c];
    size_t n = (size_t)g.nx * g.ny * g.nz;
    hu = malloc(n * sizeof *hu), hu0 = malloc(n * sizeof *hu0);
    lab = malloc(n * sizeof *lab), lab0 = malloc(n * sizeof *lab0);
    if (!lab_in || !hu || !hu0 || !lab || !lab0 ||
        pose_volume_sampler_create(rig, &desc, &g, threads, NULL, &s) != POSE_OK ||
        pose_volume_sample(s, rest, hu0, lab0) != POSE_OK || pose_volume_sample(s, st, hu, lab) != POSE_OK) {
        fprintf(stderr, "pose-volume: %s\n", lab_in && hu && hu0 && lab && lab0 ? pose_last_error() : "out of memory");
        status = 1;
        goto out;
    }
    status = 0;
    if (nifti && write_pair(nifti, &ct, &seg, &g, pad, hu, lab) != 0)
        status = 1;
    if (png && status == 0) {
        /* Slices through the first posed joint's centre (or the middle). */
        int c[3] = {(int)g.nx / 2, (int)g.ny / 2, (int)g.nz / 2};
        int j = nreq ? pose_rig_find_joint(rig, req[0].joint) : -1;
        pose_transform w;
        if (j >= 0 && pose_joint_world(st, j, &w) == POSE_OK) {
            /* model -> index: the grid's affine is orthogonal; solve by transposes. */
            for (int a = 0; a < 3; a++) {
                double col2 = 0, dot = 0;
                for (int r = 0; r < 3; r++) {
                    col2 += (double)g.affine[r][a] * g.affine[r][a];
                    dot += (double)g.affine[r][a] * (w.translation[r] - g.affine[r][3]);
                }
                int idx = (int)lround(dot / col2);
                int lim = a == 0 ? (int)g.nx : a == 1 ? (int)g.ny : (int)g.nz;
                c[a] = idx < 0 ? 0 : idx >= lim ? lim - 1 : idx;
            }
        }
        char path[1024];
        snprintf(path, sizeof path, "%s_rest.png", png);
        const int dims[3] = {(int)g.nx, (int)g.ny, (int)g.nz};
        int bad = ex_volume_slices_png(path, hu0, lab0, dims, ct.spacing, c, EX_VOLUME_LEVEL,
                                       EX_VOLUME_WIDTH, err, sizeof err);
        snprintf(path, sizeof path, "%s_posed.png", png);
        bad = bad || ex_volume_slices_png(path, hu, lab, dims, ct.spacing, c, EX_VOLUME_LEVEL,
                                          EX_VOLUME_WIDTH, err, sizeof err);
        if (bad) {
            fprintf(stderr, "pose-volume: %s\n", err);
            status = 1;
        }
    }
    if (json && status == 0) {
        size_t covered = 0;
        for (size_t v = 0; v < n; v++)
            covered += lab[v] != 0 || hu[v] != -1024.0f;
        printf("{\"grid\": [%u, %u, %u], \"voxels\": %zu, \"body_voxels\": %zu, \"nifti\": %s%s%s, "
               "\"png\": %s%s%s}\n",
               g.nx, g.ny, g.nz, n, covered, nifti ? "\"" : "", nifti ? nifti : "null", nifti ? "\"" : "",
               png ? "\"" : "", png ? png : "null", png ? "\"" : "");
    }
out:
    pose_volume_sampler_free(s);
    pose_state_free(st);
    pose_state_free(rest);
    pose_rig_free(rig);
    pv_image_free(&ct);
    pv_image_free(&seg);
    free(hu), free(hu0), free(lab), free(lab0), free(lab_in);
    return status;
}
