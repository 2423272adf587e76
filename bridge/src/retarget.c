/* SPDX-License-Identifier: Apache-2.0
 * Retargeting a clip onto a rig skeleton.
 *
 * For a rig joint j driven by clip joint s, with G the rotation from the
 * clip's axes to the rig's and Qs(t), Qs(ref) the clip joint's world
 * rotations now and in the reference pose:
 *     D_j(t) = G Qs(t) Qs(ref)^-1 G^-1      (how the segment turned, rig axes)
 *     W_j(t) = D_j(t) A_j Rest_j            (the rig joint's world rotation)
 * A_j (rest alignment) is the smallest rotation taking the rig's rest bone
 * direction (j to its first driven descendant) onto the clip's reference
 * bone direction between the corresponding clip joints, so a limb points
 * where the clip's limb points even if the two rest poses differ (arms at
 * 90 degrees versus 45, say). Undriven joints follow their parents. The
 * local target is R_j = Base_j^-1 W_j with Base_j = W_parent * RestLocal_j,
 * which is what pose_set_joint expects. Root motion is the clip root's
 * displacement from the reference, rotated by G and scaled. */
#include <stdlib.h>
#include <string.h>

#include "mapping.h"
#include "pb_math.h"

struct pb_retarget {
    const pb_clip *clip;
    const pb_rig_skel *rig;
    int *src;              /* per rig joint: clip joint or -1 */
    double (*ref_inv)[4];  /* per clip joint: Qs(ref)^-1 */
    double (*ref_p)[3];    /* per clip joint: reference world position */
    double (*target)[4];   /* per rig joint: A_j Rest_j */
    double G[4], Gi[4];
    double up[3], scale;
    pb_root_motion root_motion;
    int mapped;
    pb_one_euro_quat *filters; /* per rig joint, or NULL */
    double (*wq)[4], (*wp)[3]; /* clip world, scratch */
    double (*rw)[4];           /* rig world, scratch */
};

void pb_retarget_free(pb_retarget *r)
{
    if (!r)
        return;
    free(r->src);
    free(r->ref_inv);
    free(r->ref_p);
    free(r->target);
    free(r->filters);
    free(r->wq);
    free(r->wp);
    free(r->rw);
    free(r);
}

int pb_retarget_mapped_count(const pb_retarget *r) { return r ? r->mapped : 0; }

static int is_descendant(const pb_rig_skel *rig, int k, int j)
{
    for (int p = rig->joints[k].parent; p >= 0; p = rig->joints[p].parent)
        if (p == j)
            return 1;
    return 0;
}

static pose_status bind_names(pb_retarget *r, const pb_mapping *map, pb_error *err)
{
    const pb_clip *clip = r->clip;
    const pb_rig_skel *rig = r->rig;
    for (int j = 0; j < rig->joint_count; j++)
        r->src[j] = -1;
    if (map->identity) {
        for (int j = 0; j < rig->joint_count; j++)
            r->src[j] = pb_clip_find_joint(clip, rig->joints[j].name);
    }
    for (int i = 0; i < map->joint_count; i++) {
        const pb_map_joint *M = &map->joints[i];
        int j = pb_rig_skel_find(rig, M->rig);
        if (j < 0)
            return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: joints.%s: the rig has no joint '%s'", map->path, M->rig,
                           M->rig);
        int s = pb_clip_find_joint(clip, M->source);
        if (s < 0)
            return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: joints.%s: the clip %s has no joint '%s'", map->path,
                           M->rig, clip->path, M->source);
        r->src[j] = s;
    }
    r->mapped = 0;
    for (int j = 0; j < rig->joint_count; j++)
        r->mapped += r->src[j] >= 0;
    if (r->mapped == 0)
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no rig joint is driven by a joint of %s", map->path, clip->path);
    return POSE_OK;
}

static int joint_align(const pb_mapping *map, const char *rig_name)
{
    for (int i = 0; i < map->joint_count; i++)
        if (strcmp(map->joints[i].rig, rig_name) == 0 && map->joints[i].align >= 0)
            return map->joints[i].align;
    return map->align;
}

static void compute_alignment(pb_retarget *r, const pb_mapping *map)
{
    const pb_rig_skel *rig = r->rig;
    double (*A)[4] = r->rw; /* scratch: per rig joint alignment */
    for (int j = 0; j < rig->joint_count; j++) {
        const pb_rig_joint *J = &rig->joints[j];
        if (J->parent >= 0)
            pb_quat_copy(A[j], A[J->parent]); /* default: inherit */
        else
            pb_quat_identity(A[j]);
        if (r->src[j] >= 0 && joint_align(map, J->name)) {
            for (int k = j + 1; k < rig->joint_count; k++) {
                if (r->src[k] < 0 || !is_descendant(rig, k, j))
                    continue;
                double dr[3], ds[3];
                for (int a = 0; a < 3; a++) {
                    dr[a] = rig->joints[k].rest_p[a] - J->rest_p[a];
                    ds[a] = r->ref_p[r->src[k]][a] - r->ref_p[r->src[j]][a];
                }
                pb_quat_rotate(r->G, ds, ds);
                double lr = pb_vec_len(dr), ls = pb_vec_len(ds);
                if (lr < 1e-9 || ls < 1e-9)
                    continue;
                pb_quat_from_to(dr, ds, A[j]);
                break;
            }
        }
        pb_quat_mul(A[j], J->rest_q, r->target[j]);
    }
}

pose_status pb_retarget_create(const pb_mapping *map, const pb_clip *clip, const pb_rig_skel *rig,
                               pb_retarget **out, pb_error *err)
{
    if (!map || !clip || !rig || !out)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_retarget_create: NULL argument");
    *out = NULL;
    pb_retarget *r = calloc(1, sizeof *r);
    if (!r)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    r->clip = clip;
    r->rig = rig;
    size_t nc = (size_t)(clip->joint_count > 0 ? clip->joint_count : 1);
    size_t nr = (size_t)(rig->joint_count > 0 ? rig->joint_count : 1);
    r->src = malloc(nr * sizeof *r->src);
    r->ref_inv = malloc(nc * sizeof *r->ref_inv);
    r->ref_p = malloc(nc * sizeof *r->ref_p);
    r->target = malloc(nr * sizeof *r->target);
    r->wq = malloc(nc * sizeof *r->wq);
    r->wp = malloc(nc * sizeof *r->wp);
    r->rw = malloc(nr * sizeof *r->rw);
    double *scratch = malloc(nc * 7 * sizeof *scratch);
    if (!r->src || !r->ref_inv || !r->ref_p || !r->target || !r->wq || !r->wp || !r->rw || !scratch) {
        free(scratch);
        pb_retarget_free(r);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
    pose_status s = bind_names(r, map, err);
    if (!s && map->reference_frame >= 0 && (size_t)map->reference_frame >= clip->frame_count)
        s = pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "%s: reference: frame %ld is beyond the clip's %zu frames",
                    map->path, map->reference_frame, clip->frame_count);
    if (s) {
        free(scratch);
        pb_retarget_free(r);
        return s;
    }
    pb_clip_fk(clip, map->reference_frame >= 0 ? pb_clip_frame(clip, (size_t)map->reference_frame) : NULL, scratch,
               r->wq, r->ref_p);
    free(scratch);
    for (int c = 0; c < clip->joint_count; c++)
        pb_quat_conj(r->wq[c], r->ref_inv[c]);
    pb_quat_copy(r->G, map->axes_q);
    pb_quat_conj(r->G, r->Gi);
    memcpy(r->up, map->up, sizeof r->up);
    r->scale = map->scale;
    r->root_motion = map->root_motion;
    compute_alignment(r, map);
    int any_filter = map->has_filter;
    for (int i = 0; i < map->joint_count; i++)
        any_filter |= map->joints[i].has_filter;
    if (any_filter) {
        r->filters = calloc(nr, sizeof *r->filters);
        if (!r->filters) {
            pb_retarget_free(r);
            return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        }
        for (int j = 0; j < rig->joint_count; j++) {
            pb_one_euro_params p = map->has_filter ? map->filter : (pb_one_euro_params){0, 0, 1};
            for (int i = 0; i < map->joint_count; i++)
                if (map->joints[i].has_filter && strcmp(map->joints[i].rig, rig->joints[j].name) == 0)
                    p = map->joints[i].filter;
            pb_one_euro_quat_init(&r->filters[j], &p);
        }
    }
    *out = r;
    return POSE_OK;
}

void pb_retarget_apply(pb_retarget *r, const double (*lq)[4], const double (*lt)[3], double dt_s, pb_pose *out)
{
    const pb_rig_skel *rig = r->rig;
    pb_clip_world(r->clip, lq, lt, r->wq, r->wp);
    int root_src = -1;
    for (int j = 0; j < rig->joint_count; j++) {
        const pb_rig_joint *J = &rig->joints[j];
        double base[4], R[4], bi[4];
        if (J->parent < 0)
            pb_quat_copy(base, J->rest_q);
        else
            pb_quat_mul(r->rw[J->parent], J->local_q, base);
        int s = r->src[j];
        if (s < 0) {
            pb_quat_copy(r->rw[j], base);
            pb_quat_identity(R);
        } else {
            if (J->parent < 0 && root_src < 0)
                root_src = s;
            double d[4];
            pb_quat_mul(r->wq[s], r->ref_inv[s], d);
            pb_quat_mul(r->G, d, d);
            pb_quat_mul(d, r->Gi, d);
            pb_quat_mul(d, r->target[j], r->rw[j]);
            pb_quat_normalize(r->rw[j]);
            pb_quat_conj(base, bi);
            pb_quat_mul(bi, r->rw[j], R);
            if (R[3] < 0) { /* keep w >= 0: the same rotation, steadier for filters and clients */
                R[0] = -R[0]; R[1] = -R[1]; R[2] = -R[2]; R[3] = -R[3];
            }
            if (r->filters) {
                pb_one_euro_quat_step(&r->filters[j], R, dt_s);
                /* the filtered local rotation defines what children see */
                pb_quat_mul(base, R, r->rw[j]);
            }
        }
        for (int k = 0; k < 4; k++)
            out->q[j][k] = (float)R[k];
        out->active[j] = s >= 0;
    }
    out->has_root = 0;
    out->root_q[0] = out->root_q[1] = out->root_q[2] = 0.0f;
    out->root_q[3] = 1.0f;
    out->root_t[0] = out->root_t[1] = out->root_t[2] = 0.0f;
    if (r->root_motion != PB_ROOT_NONE && root_src >= 0) {
        double d[3];
        for (int a = 0; a < 3; a++)
            d[a] = (r->wp[root_src][a] - r->ref_p[root_src][a]) * r->scale;
        pb_quat_rotate(r->G, d, d);
        if (r->root_motion == PB_ROOT_HORIZONTAL) {
            double h = d[0] * r->up[0] + d[1] * r->up[1] + d[2] * r->up[2];
            for (int a = 0; a < 3; a++)
                d[a] -= h * r->up[a];
        }
        for (int a = 0; a < 3; a++)
            out->root_t[a] = (float)d[a];
        out->has_root = 1;
    }
}
