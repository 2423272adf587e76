/* SPDX-License-Identifier: Apache-2.0
 * Retargeting a clip onto a rig skeleton.
 *
 * For a rig joint j driven by clip joint s, with G the rotation from the
 * clip's axes to the rig's and Qs(t), Qs(ref) the clip joint's world
 * rotations now and in the reference pose:
 *     D_j(t) = G Qs(t) Qs(ref)^-1 G^-1      (how the segment turned, rig axes)
 *     W_j(t) = D_j(t) A_j Rest_j            (the rig joint's world rotation)
 * A_j (rest alignment, see compute_alignment) turns the rig's rest bone
 * (j to its first driven descendant) onto the clip's reference bone between
 * the corresponding clip joints, so a limb points where the clip's limb
 * points even if the two rest poses differ (arms at 90 degrees versus 45,
 * say), and turns it about that bone so that hinge axes agree. Undriven
 * joints follow their parents. The
 * local target is R_j = Base_j^-1 W_j with Base_j = W_parent * RestLocal_j,
 * which is what pose_set_joint expects. Root motion is the clip root's
 * displacement from the reference, rotated by G and scaled. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mapping.h"
#include "pb_math.h"
#include "retarget_hinge.h"

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
    int *hinge_axis;       /* per rig joint: local hinge axis (0..2) where a rig hinge is driven by a clip hinge, else -1 */
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
    free(r->hinge_axis);
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

/* Index of the local axis of frame q nearest to direction d (either sign). */
static int nearest_axis(const double q[4], const double d[3])
{
    int best = 0;
    double best_c = -1.0;
    for (int a = 0; a < 3; a++) {
        double e[3] = {a == 0, a == 1, a == 2}, w[3];
        pb_quat_rotate(q, e, w);
        double c = fabs(w[0] * d[0] + w[1] * d[1] + w[2] * d[2]);
        if (c > best_c) {
            best_c = c;
            best = a;
        }
    }
    return best;
}

/* The turn about unit u that takes v, seen across u, onto the line of h
 * (either sign: a hinge axis has no preferred sign), in (-pi/2, pi/2];
 * NAN when v or h lies within 30 degrees of u (the twist is then not
 * defined by them). */
static double twist_angle(const double u[3], const double v[3], const double h[3])
{
    double dv = v[0] * u[0] + v[1] * u[1] + v[2] * u[2], dh = h[0] * u[0] + h[1] * u[1] + h[2] * u[2];
    double vp[3], hp[3];
    for (int a = 0; a < 3; a++) {
        vp[a] = v[a] - dv * u[a];
        hp[a] = h[a] - dh * u[a];
    }
    if (pb_vec_len(vp) < 0.5 * pb_vec_len(v) || pb_vec_len(hp) < 0.5 * pb_vec_len(h))
        return NAN;
    double x[3] = {vp[1] * hp[2] - vp[2] * hp[1], vp[2] * hp[0] - vp[0] * hp[2], vp[0] * hp[1] - vp[1] * hp[0]};
    double phi = atan2(x[0] * u[0] + x[1] * u[1] + x[2] * u[2], vp[0] * hp[0] + vp[1] * hp[1] + vp[2] * hp[2]);
    const double pi = 3.14159265358979323846;
    if (phi > 0.5 * pi)
        phi -= pi;
    else if (phi <= -0.5 * pi)
        phi += pi;
    return phi;
}

/* The part of rotation q (unit) about unit axis e: its twist in a swing-twist
 * split. */
static void twist_part(const double q[4], const double e[3], double out[4])
{
    double d = q[0] * e[0] + q[1] * e[1] + q[2] * e[2];
    out[0] = d * e[0];
    out[1] = d * e[1];
    out[2] = d * e[2];
    out[3] = q[3];
    if (out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3] < 1e-18)
        pb_quat_identity(out); /* a half turn across the axis: no part about it */
    else
        pb_quat_normalize(out);
}

/* The rig's hinge axis at joint j: its local index (-1 when j is no hinge),
 * and in model space at rest; the local axis nearest to the bone `dir` is
 * taken as the twist axis. */
static int rig_hinge(const pb_rig_skel *rig, int j, const double dir[3], double axis[3])
{
    int ax = pb_rig_skel_hinge_axis(rig, j, nearest_axis(rig->joints[j].rest_q, dir));
    if (ax < 0)
        return -1;
    double e[3] = {ax == 0, ax == 1, ax == 2};
    pb_quat_rotate(rig->joints[j].rest_q, e, axis);
    return ax;
}

/*
 * A_j, the rest alignment, poses the rig into the clip's reference posture
 * the way FK would: each aligned joint starts from its parent's alignment
 * and bends so that its rest bone lies along the clip's reference bone.
 * What a joint may bend by is what the rig says the joint can do:
 *  - a ball joint bends by the smallest rotation between the two bones,
 *    then turns about its bone so that, where the joint at the bone's far
 *    end is a hinge in the rig (read from its limits) driven by a hinge of
 *    the clip (measured from the motion, pb_clip_hinge_axes), the two hinge
 *    axes coincide: bone directions alone leave that twist open, and a
 *    twisted hinge turns every flexion into flexion, abduction and twist
 *    that limits a few degrees wide then clamp;
 *  - a hinge bends about its hinge axis only, and no further than its
 *    limits: a difference across the axis (the carrying angle of an elbow,
 *    say) or past a limit (a knee straighter than straight) is the shape of
 *    the rig's bones, not a pose the clip could have meant, and forcing it
 *    would hold the joint outside its limits in every frame.
 * Unaligned joints keep their parent's alignment. A rig hinge driven by a
 * hinge of the clip is marked in hinge_axis: pb_retarget_apply gives it the
 * clip's flexion about its own axis (see there).
 */
static void compute_alignment(pb_retarget *r, const pb_mapping *map, const double (*hinge)[3], const int *hinge_ok)
{
    const pb_rig_skel *rig = r->rig;
    double (*A)[4] = r->rw; /* scratch: per rig joint alignment */
    for (int j = 0; j < rig->joint_count; j++) {
        const pb_rig_joint *J = &rig->joints[j];
        r->hinge_axis[j] = -1;
        if (J->parent >= 0)
            pb_quat_copy(A[j], A[J->parent]);
        else
            pb_quat_identity(A[j]);
        if (r->src[j] < 0 || !joint_align(map, J->name)) {
            pb_quat_mul(A[j], J->rest_q, r->target[j]);
            continue;
        }
        int k;
        double dr[3] = {0, 0, 0}, ds[3] = {0, 0, 0};
        for (k = j + 1; k < rig->joint_count; k++) {
            if (r->src[k] < 0 || !is_descendant(rig, k, j))
                continue;
            for (int a = 0; a < 3; a++) {
                dr[a] = rig->joints[k].rest_p[a] - J->rest_p[a];
                ds[a] = r->ref_p[r->src[k]][a] - r->ref_p[r->src[j]][a];
            }
            pb_quat_rotate(r->G, ds, ds);
            if (pb_vec_len(dr) >= 1e-9 && pb_vec_len(ds) >= 1e-9)
                break;
        }
        if (k < rig->joint_count) {
            double da[3], q[4], u[3], axis[3], l = pb_vec_len(ds);
            pb_quat_rotate(A[j], dr, da);
            pb_quat_from_to(da, ds, q);
            int ax = rig_hinge(rig, j, dr, axis);
            if (ax >= 0) {
                pb_quat_rotate(A[j], axis, axis);
                twist_part(q, axis, q);
                double flex = 2.0 * atan2(q[0] * axis[0] + q[1] * axis[1] + q[2] * axis[2], q[3]) * PB_RAD2DEG;
                if (flex < J->limit_min_deg[ax] || flex > J->limit_max_deg[ax]) {
                    flex = flex < J->limit_min_deg[ax] ? J->limit_min_deg[ax] : J->limit_max_deg[ax];
                    double sn = sin(0.5 * flex * PB_DEG2RAD);
                    q[0] = axis[0] * sn;
                    q[1] = axis[1] * sn;
                    q[2] = axis[2] * sn;
                    q[3] = cos(0.5 * flex * PB_DEG2RAD);
                }
                pb_quat_mul(q, A[j], A[j]);
                if (hinge_ok[r->src[j]])
                    r->hinge_axis[j] = ax;
            } else {
                pb_quat_mul(q, A[j], A[j]);
                for (int a = 0; a < 3; a++)
                    u[a] = ds[a] / l;
                double hc[3], t[4];
                int c = r->src[k];
                if (hinge_ok[c] && rig_hinge(rig, k, dr, axis) >= 0) {
                    pb_quat_rotate(A[j], axis, axis);
                    pb_quat_rotate(r->G, hinge[c], hc);
                    double phi = twist_angle(u, axis, hc);
                    if (!isnan(phi)) {
                        double sn = sin(0.5 * phi);
                        t[0] = u[0] * sn;
                        t[1] = u[1] * sn;
                        t[2] = u[2] * sn;
                        t[3] = cos(0.5 * phi);
                        pb_quat_mul(t, A[j], A[j]);
                    }
                }
            }
            pb_quat_normalize(A[j]);
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
    r->hinge_axis = malloc(nr * sizeof *r->hinge_axis);
    double *scratch = malloc(nc * 7 * sizeof *scratch);
    if (!r->src || !r->ref_inv || !r->ref_p || !r->target || !r->wq || !r->wp || !r->rw || !r->hinge_axis || !scratch) {
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
    const double *ref_values = map->reference_frame >= 0 ? pb_clip_frame(clip, (size_t)map->reference_frame) : NULL;
    pb_clip_fk(clip, ref_values, scratch, r->wq, r->ref_p);
    for (int c = 0; c < clip->joint_count; c++)
        pb_quat_conj(r->wq[c], r->ref_inv[c]);
    pb_quat_copy(r->G, map->axes_q);
    pb_quat_conj(r->G, r->Gi);
    memcpy(r->up, map->up, sizeof r->up);
    r->scale = map->scale;
    r->root_motion = map->root_motion;
    /* scratch (7 doubles per clip joint) now holds the clip's hinge axes and flags */
    double (*hinge)[3] = (double (*)[3])scratch;
    int *hinge_ok = malloc(nc * sizeof *hinge_ok);
    if (!hinge_ok || pb_clip_hinge_axes(clip, ref_values, (const double (*)[4])r->wq, hinge, hinge_ok) != 0) {
        free(hinge_ok);
        free(scratch);
        pb_retarget_free(r);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
    compute_alignment(r, map, (const double (*)[3])hinge, hinge_ok);
    free(hinge_ok);
    free(scratch);
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
            if (r->hinge_axis[j] >= 0) {
                /* hinge to hinge: the clip's flexion about the rig's own
                 * axis. The clip joint turns about one axis only; what else
                 * the world-space transfer puts in R is the two skeletons'
                 * differing hinge geometry (axes tilted a few degrees apart),
                 * which grows with flexion and which the rig's hinge, a few
                 * degrees wide across its axis, would only clamp. Children
                 * see the hinge as posed, so their directions still follow. */
                int a = r->hinge_axis[j];
                double e[3] = {a == 0, a == 1, a == 2};
                twist_part(R, e, R);
                pb_quat_mul(base, R, r->rw[j]);
            }
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
