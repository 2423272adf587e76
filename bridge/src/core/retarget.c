/* SPDX-License-Identifier: Apache-2.0
 * Retargeting a clip onto a rig skeleton.
 *
 * For a rig joint j driven by clip joint s, with G the rotation from the
 * clip's axes to the rig's and Qs(t), Qs(ref) the clip joint's world
 * rotations now and in the reference pose:
 *     D_j(t) = G Qs(t) Qs(ref)^-1 G^-1      (how the segment turned, rig axes)
 *     W_j(t) = D_j(t) A_j Neutral_j         (the rig joint's world rotation)
 * Neutral_j is the joint's world frame in the rig's neutral posture (the
 * rest pose where the rig has no clinical data): the clip's reference pose
 * is taken to be the clip's neutral. A_j (rest alignment, see
 * compute_alignment) turns the rig's neutral bone (j to its first driven
 * descendant) onto the clip's reference bone between the corresponding clip
 * joints, so a limb points where the clip's limb points even if the two
 * postures differ (arms at 90 degrees versus hanging, say), and turns it
 * about that bone so that hinge axes agree. Undriven joints follow their
 * parents. The local target is R_j = Base_j^-1 W_j with
 * Base_j = W_parent * RestLocal_j, which is what pose_set_joint expects; a
 * rig hinge driven by a clip hinge takes only part of it (hinge_pose). Root
 * motion is the clip root's displacement from the reference (or from the
 * clip's first frame: "root_origin"), rotated by G and scaled. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mapping.h"
#include "pb_math.h"
#include "retarget_hinge.h"

/*
 * A rig joint's three anatomical axes (flexion, abduction, long axis: the
 * clinical axes where the rig has them, else the joint's rest axes ordered
 * by its Euler limits) and ranges, relative to its neutral posture:
 *     local = R(b[0], flex) R(b[1], abd) R(b[2], sign * rot) Neutral
 * b is right-handed; `sign` is -1 where the rig's own axis set is not (the
 * left side's clinical axes), so rot keeps the rig's sense.
 */
typedef struct pb_hinge {
    int driven;            /* a rig hinge driven by a clip hinge: posed by hinge_pose */
    int overflow;          /* a joint that keeps within its clinical range and leaves the rest to its children */
    int child;             /* rig joint whose twist about the long axis this hinge takes, or -1 */
    int bone;              /* rig joint at the far end of the hinge's bone (its first driven descendant) */
    double dir[3];         /* that bone, unit, in the joint's own frame */
    double sign;
    double N[4];           /* neutral posture, local (relative to rest) */
    double b[3][3];        /* in the joint's rest frame */
    double lo[3], hi[3];   /* ranges in radians (lo > hi: unlimited) */
} pb_hinge;

struct pb_retarget {
    const pb_clip *clip;
    const pb_rig_skel *rig;
    int *src;              /* per rig joint: clip joint or -1 */
    double (*ref_inv)[4];  /* per clip joint: Qs(ref)^-1 */
    double (*ref_p)[3];    /* per clip joint: reference world position */
    double (*origin_p)[3]; /* per clip joint: where root motion is measured from (ref_p or frame 0) */
    double (*target)[4];   /* per rig joint: A_j Neutral_j */
    double G[4], Gi[4];
    double up[3], scale;
    pb_root_motion root_motion;
    int mapped;
    pb_hinge *hinge;       /* per rig joint */
    pb_one_euro_quat *filters; /* per rig joint, or NULL */
    double (*wq)[4], (*wp)[3]; /* clip world, scratch */
    double (*rw)[4];           /* rig world, scratch */
    double (*nw)[4], (*np)[3]; /* rig world frames and positions in the neutral posture */
};

void pb_retarget_free(pb_retarget *r)
{
    if (!r)
        return;
    free(r->src);
    free(r->ref_inv);
    free(r->ref_p);
    free(r->origin_p);
    free(r->target);
    free(r->hinge);
    free(r->nw);
    free(r->np);
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

static void axis_quat(const double u[3], double rad, double q[4])
{
    double sn = sin(0.5 * rad);
    q[0] = u[0] * sn;
    q[1] = u[1] * sn;
    q[2] = u[2] * sn;
    q[3] = cos(0.5 * rad);
}

static void cross(const double a[3], const double b[3], double out[3])
{
    double x[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    memcpy(out, x, sizeof x);
}

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* The rig's neutral posture (local rotations Neutral_j on the rest pose,
 * identity where the rig has no clinical data), by FK: world frames nw and
 * positions np. */
static void neutral_posture(pb_retarget *r)
{
    const pb_rig_skel *rig = r->rig;
    for (int j = 0; j < rig->joint_count; j++) {
        const pb_rig_joint *J = &rig->joints[j];
        double n[4] = {0, 0, 0, 1};
        if (J->clinical.flags & POSE_CLINICAL_DEFINED) {
            for (int k = 0; k < 4; k++)
                n[k] = J->clinical.neutral[k];
            pb_quat_normalize(n);
        }
        pb_quat_copy(r->hinge[j].N, n);
        if (J->parent < 0) {
            pb_quat_mul(J->rest_q, n, r->nw[j]);
            memcpy(r->np[j], J->rest_p, sizeof r->np[j]);
            continue;
        }
        double b[4], d[3];
        pb_quat_mul(r->nw[J->parent], J->local_q, b);
        pb_quat_mul(b, n, r->nw[j]);
        pb_quat_normalize(r->nw[j]);
        pb_quat_rotate(r->nw[J->parent], J->local_p, d);
        for (int k = 0; k < 3; k++)
            r->np[j][k] = r->np[J->parent][k] + d[k];
    }
}

/* A right-handed basis b from three orthonormal axes a (either hand). */
static void set_basis(pb_hinge *h, const double a[3][3])
{
    memcpy(h->b[0], a[0], sizeof a[0]);
    memcpy(h->b[1], a[1], sizeof a[1]);
    cross(a[0], a[1], h->b[2]);
    h->sign = dot(h->b[2], a[2]) < 0 ? -1.0 : 1.0;
}

/* The joint's clinical axes and ranges into h; 0 when it has none. */
static int clinical_frame(const pb_rig_joint *J, pb_hinge *h)
{
    const pose_joint_clinical *c = &J->clinical;
    if (!(c->flags & POSE_CLINICAL_DEFINED))
        return 0;
    double a[3][3];
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < 3; k++)
            a[i][k] = c->axes[i][k];
        h->lo[i] = (c->limit_flags >> i & 1u) ? c->limit_min_deg[i] * PB_DEG2RAD : 1.0;
        h->hi[i] = (c->limit_flags >> i & 1u) ? c->limit_max_deg[i] * PB_DEG2RAD : -1.0;
    }
    set_basis(h, a);
    return 1;
}

/*
 * Whether rig joint j is a hinge, and its axes (pb_hinge). With clinical
 * data: a flexion range of 60 degrees or more and an abduction range of 30
 * or less (elbow, knee), the flexion axis being the one pose-bake fitted to
 * the bones. Without: pb_rig_skel_hinge_axis on the Euler limits, the local
 * axis nearest the bone (`dir`, in the joint's own frame) carrying the twist.
 */
static int hinge_setup(const pb_rig_skel *rig, int j, const double dir[3], pb_hinge *h)
{
    const pb_rig_joint *J = &rig->joints[j];
    if (clinical_frame(J, h)) {
        const pose_joint_clinical *c = &J->clinical;
        return (c->limit_flags & 3u) == 3u && c->limit_max_deg[0] - c->limit_min_deg[0] >= 60.0f &&
               c->limit_max_deg[1] - c->limit_min_deg[1] <= 30.0f;
    }
    double a[3][3];
    int l = 0;
    for (int k = 1; k < 3; k++)
        if (fabs(dir[k]) > fabs(dir[l]))
            l = k;
    int ax = pb_rig_skel_hinge_axis(rig, j, l);
    if (ax < 0)
        return 0;
    int idx[3] = {ax, 3 - ax - l, l};
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < 3; k++)
            a[i][k] = idx[i] == k;
        h->lo[i] = J->limit_min_deg[idx[i]] * PB_DEG2RAD;
        h->hi[i] = J->limit_max_deg[idx[i]] * PB_DEG2RAD;
    }
    set_basis(h, a);
    return 1;
}

static double clamp_range(double v, double lo, double hi) { return lo > hi ? v : v < lo ? lo : v > hi ? hi : v; }

/* The rig joint k's base frame (parent frame times rest local) in the
 * neutral posture. */
static void neutral_base(const pb_retarget *r, int k, double out[4])
{
    const pb_rig_joint *K = &r->rig->joints[k];
    if (K->parent < 0)
        pb_quat_copy(out, K->rest_q);
    else
        pb_quat_mul(r->nw[K->parent], K->local_q, out);
}

/*
 * A driven joint without a driven descendant (a hand, a foot) has no bone to
 * align. Where it is aligned, the rig knows its neutral posture (clinical
 * data) and the map names no reference frame, the clip's neutral for it is
 * its mean posture relative to its parent over the clip rather than its
 * zero pose: a clip's zero pose says little about a hand's or foot's
 * neutral (131_01's hands sit 30 to 60 degrees from theirs all clip long,
 * pressing the rig's wrists against their ranges in most frames), while a
 * hand or foot spends a clip around its relaxed posture. The reference of
 * those clip joints becomes their parent's reference with the mean local
 * rotation, which the rig's neutral posture then receives.
 *
 * Only the mean's swing, where the rig's parent is a hinge that takes this
 * joint's twist about its bone with a wider range than the joint's own (an
 * elbow's +-80 of pronation against a wrist's +-20): the mean twist about
 * the forearm is the clip's average pronation, and kept in the reference it
 * would turn the hand's flexion axis by that much against the rig's, so
 * that the rig's wrist received flexion as deviation (131_01: a 22 degree
 * mean pronation on the right, 10 on the left, on top of CMU's 30 degrees
 * between elbow hinge and hand axes). Without it the twist reaches the elbow
 * as pronation and both hands keep the one offset of the hinges. A foot
 * keeps its whole mean: a knee's +-15 could not hold a mean toe-out.
 */
static pose_status mean_reference(pb_retarget *r, const pb_mapping *map)
{
    const pb_rig_skel *rig = r->rig;
    const pb_clip *clip = r->clip;
    size_t nc = (size_t)(clip->joint_count > 0 ? clip->joint_count : 1);
    int *want = calloc(nc, sizeof *want), any = 0;
    double (*mean)[4] = malloc(nc * sizeof *mean);
    if (!want || !mean) {
        free(want);
        free(mean);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    for (int j = 0; j < rig->joint_count && map->reference_frame < 0; j++) {
        const pb_rig_joint *J = &rig->joints[j];
        int s = r->src[j], leaf = 1;
        if (s < 0 || clip->joints[s].parent < 0 || !(J->clinical.flags & POSE_CLINICAL_DEFINED) ||
            !joint_align(map, J->name))
            continue;
        for (int k = j + 1; k < rig->joint_count && leaf; k++)
            leaf = !(r->src[k] >= 0 && is_descendant(rig, k, j));
        want[s] |= leaf;
        any |= leaf;
        /* its twist about the parent's bone is the parent's to take (see above) */
        const pb_hinge *P = J->parent >= 0 ? &r->hinge[J->parent] : NULL;
        pb_hinge own;
        if (leaf && P && P->driven && P->child == j && clinical_frame(J, &own) && P->lo[2] <= P->hi[2] &&
            own.lo[2] <= own.hi[2] && P->hi[2] - P->lo[2] > own.hi[2] - own.lo[2])
            want[s] |= 2;
    }
    if (any && pb_clip_mean_local(clip, want, mean) != 0) {
        free(want);
        free(mean);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    for (int c = 0; c < clip->joint_count && any; c++) {
        if (!want[c])
            continue;
        int p = clip->joints[c].parent;
        double q[4], e[3], t[4], ti[4];
        for (int a = 0; a < 3; a++)
            e[a] = r->ref_p[c][a] - r->ref_p[p][a];
        pb_quat_conj(r->wq[p], q);
        pb_quat_rotate(q, e, e);
        double l = pb_vec_len(e);
        if ((want[c] & 2) && l > 1e-9) {
            for (int a = 0; a < 3; a++)
                e[a] /= l;
            twist_part(mean[c], e, t);
            pb_quat_conj(t, ti);
            pb_quat_mul(ti, mean[c], mean[c]);
            pb_quat_normalize(mean[c]);
        }
        pb_quat_mul(r->wq[p], mean[c], q);
        pb_quat_conj(q, r->ref_inv[c]);
    }
    free(want);
    free(mean);
    return POSE_OK;
}

/*
 * A_j, the rest alignment, poses the rig from its neutral posture into the
 * clip's reference posture the way FK would: each aligned joint starts from
 * its parent's alignment and bends so that its neutral bone lies along the
 * clip's reference bone. What a joint may bend by is what the rig says the
 * joint can do:
 *  - a ball joint bends by the smallest rotation between the two bones,
 *    then turns about its bone so that, where the joint at the bone's far
 *    end is a hinge in the rig driven by a hinge of the clip (measured from
 *    the motion, pb_clip_hinge_axes), the two hinge axes coincide as seen
 *    along the bone: bone directions alone leave that twist open, and a
 *    twisted hinge turns every flexion into flexion, abduction and twist
 *    that limits a few degrees wide then clamp;
 *  - a hinge bends about its flexion axis only, and no further than its
 *    range: a difference across the axis or past a limit (a knee straighter
 *    than straight) is the shape of the rig's bones, not a pose the clip
 *    could have meant (hinge_pose deals with what remains across the axis).
 * Unaligned joints keep their parent's alignment. A rig hinge driven by a
 * hinge of the clip is marked driven; pb_retarget_apply poses it through
 * hinge_pose.
 */
static void compute_alignment(pb_retarget *r, const pb_mapping *map, const double (*hinge)[3], const int *hinge_ok)
{
    const pb_rig_skel *rig = r->rig;
    double (*A)[4] = r->rw; /* scratch: per rig joint alignment */
    for (int j = 0; j < rig->joint_count; j++) {
        const pb_rig_joint *J = &rig->joints[j];
        pb_hinge *H = &r->hinge[j];
        H->driven = 0;
        H->child = -1;
        if (J->parent >= 0)
            pb_quat_copy(A[j], A[J->parent]);
        else
            pb_quat_identity(A[j]);
        if (r->src[j] < 0 || !joint_align(map, J->name)) {
            pb_quat_mul(A[j], r->nw[j], r->target[j]);
            continue;
        }
        int k;
        double dr[3] = {0, 0, 0}, ds[3] = {0, 0, 0};
        for (k = j + 1; k < rig->joint_count; k++) {
            if (r->src[k] < 0 || !is_descendant(rig, k, j))
                continue;
            for (int a = 0; a < 3; a++) {
                dr[a] = r->np[k][a] - r->np[j][a];
                ds[a] = r->ref_p[r->src[k]][a] - r->ref_p[r->src[j]][a];
            }
            pb_quat_rotate(r->G, ds, ds);
            if (pb_vec_len(dr) >= 1e-9 && pb_vec_len(ds) >= 1e-9)
                break;
        }
        if (k < rig->joint_count) {
            double da[3], q[4], u[3], axis[3], base[4], ri[4], l = pb_vec_len(ds), lr = pb_vec_len(dr);
            pb_quat_rotate(A[j], dr, da);
            pb_quat_from_to(da, ds, q);
            pb_quat_conj(r->nw[j], ri);
            pb_quat_rotate(ri, dr, H->dir);
            for (int a = 0; a < 3; a++)
                H->dir[a] /= lr;
            if (hinge_setup(rig, j, H->dir, H)) {
                /* flexion turns about b0 on the parent's side of the neutral offset */
                neutral_base(r, j, base);
                pb_quat_rotate(base, H->b[0], axis);
                pb_quat_rotate(A[j], axis, axis);
                twist_part(q, axis, q);
                double flex = clamp_range(2.0 * atan2(dot(q, axis), q[3]), H->lo[0], H->hi[0]);
                axis_quat(axis, flex, q);
                pb_quat_mul(q, A[j], A[j]);
                H->bone = k;
                H->driven = hinge_ok[r->src[j]];
            } else {
                pb_quat_mul(q, A[j], A[j]);
                for (int a = 0; a < 3; a++)
                    u[a] = ds[a] / l;
                double hc[3], t[4], dk[3];
                int c = r->src[k];
                pb_hinge hk;
                /* the bone j->k stands in for k's own, as at rest an elbow's
                 * or knee's two bones lie near one line */
                pb_quat_conj(r->nw[k], ri);
                pb_quat_rotate(ri, dr, dk);
                if (hinge_ok[c] && hinge_setup(rig, k, dk, &hk)) {
                    neutral_base(r, k, base);
                    pb_quat_rotate(base, hk.b[0], axis);
                    pb_quat_rotate(A[j], axis, axis);
                    pb_quat_rotate(r->G, hinge[c], hc);
                    double phi = twist_angle(u, axis, hc);
                    if (!isnan(phi)) {
                        axis_quat(u, phi, t);
                        pb_quat_mul(t, A[j], A[j]);
                    }
                }
            }
            pb_quat_normalize(A[j]);
        }
        pb_quat_mul(A[j], r->nw[j], r->target[j]);
    }
    /* A driven hinge also takes its bone's far joint's twist about the long
     * axis where that joint's own long axis lies along it (an elbow and its
     * wrist: see hinge_pose). */
    for (int j = 0; j < rig->joint_count; j++) {
        pb_hinge *H = &r->hinge[j];
        if (!H->driven)
            continue;
        int k = H->bone;
        const pb_rig_joint *K = &rig->joints[k];
        if (rig->joints[k].parent != j || !(K->clinical.flags & POSE_CLINICAL_DEFINED))
            continue;
        double lj[3], lk[3], kb[4], jb[4], c[3];
        neutral_base(r, j, jb);
        neutral_base(r, k, kb);
        pb_quat_rotate(jb, H->b[2], lj);
        for (int a = 0; a < 3; a++)
            c[a] = K->clinical.axes[2][a];
        pb_quat_rotate(kb, c, lk);
        if (fabs(dot(lj, lk)) >= cos(30.0 * PB_DEG2RAD))
            H->child = k;
    }
    /* Joints that hand what lies beyond their range on to their children
     * (see range_overflow): driven ball joints with clinical ranges within
     * +-90 degrees (the spine, the clavicles; not a shoulder, whose
     * abduction passes 90) and a driven child. */
    for (int j = 0; j < rig->joint_count; j++) {
        pb_hinge *H = &r->hinge[j], c;
        H->overflow = 0;
        if (r->src[j] < 0 || H->driven || !clinical_frame(&rig->joints[j], &c))
            continue;
        int within = 1, child = 0;
        for (int i = 0; i < 3; i++)
            within &= c.lo[i] <= c.hi[i] && c.lo[i] > -0.5 * PB_PI && c.hi[i] < 0.5 * PB_PI;
        for (int k = j + 1; k < rig->joint_count; k++)
            child |= rig->joints[k].parent == j && r->src[k] >= 0;
        if (!within || !child)
            continue;
        memcpy(H->b, c.b, sizeof c.b);
        H->sign = c.sign;
        memcpy(H->lo, c.lo, sizeof c.lo);
        memcpy(H->hi, c.hi, sizeof c.hi);
        H->overflow = 1;
    }
}

/* Angles (radians) of a local rotation Q = R(b0, f) R(b1, a) R(b2, t) in a
 * right-handed basis b (|a| < 90 degrees). */
static void hinge_angles(const double b[3][3], const double Q[4], double out[3])
{
    double v[3], qi[4];
    pb_quat_rotate(Q, b[2], v);
    out[1] = asin(fmax(-1.0, fmin(1.0, dot(v, b[0]))));
    out[0] = atan2(-dot(v, b[1]), dot(v, b[2]));
    pb_quat_conj(Q, qi);
    pb_quat_rotate(qi, b[0], v);
    out[2] = atan2(-dot(v, b[1]), dot(v, b[0]));
}

/* The part of rotation q (unit) about unit axis e, as an angle in radians. */
static double twist_angle_about(const double q[4], const double e[3])
{
    double t[4];
    twist_part(q, e, t);
    if (t[3] < 0)
        for (int k = 0; k < 4; k++)
            t[k] = -t[k];
    return 2.0 * atan2(dot(t, e), t[3]);
}

/*
 * A spine joint or clavicle driven past its clinical range: the clip's
 * spine has more joints than the rig's (CMU's neck turns at three), so the
 * rig's joint may be asked for the turn of several. Keep it within its
 * range here; its children's targets are world rotations, so what it could
 * not take passes to them (a neck's excess to the head) and reaches
 * pose_set_joint's limits only where the chain as a whole runs out.
 */
static void range_overflow(const pb_hinge *H, double R[4])
{
    double Ni[4], Q[4], ang[3], q[4];
    pb_quat_conj(H->N, Ni);
    pb_quat_mul(R, Ni, Q);
    hinge_angles(H->b, Q, ang);
    ang[2] *= H->sign;
    int inside = 1;
    for (int i = 0; i < 3; i++)
        inside &= ang[i] >= H->lo[i] && ang[i] <= H->hi[i];
    if (inside)
        return;
    for (int i = 0; i < 3; i++)
        ang[i] = clamp_range(ang[i], H->lo[i], H->hi[i]);
    ang[2] *= H->sign;
    axis_quat(H->b[0], ang[0], R);
    axis_quat(H->b[1], ang[1], q);
    pb_quat_mul(R, q, R);
    axis_quat(H->b[2], ang[2], q);
    pb_quat_mul(R, q, R);
    pb_quat_mul(R, H->N, R);
}

/*
 * The local rotation of a rig hinge driven by a clip hinge, from the full
 * transfer R (pb_retarget_apply) decomposed about the hinge's axes:
 *  - flexion as the transfer gives it (the clip's flexion: libpose limits it);
 *  - abduction across the axis so that the bone lies as near the clip's
 *    bone as the joint's range allows: the two skeletons' hinges differ
 *    (the baked elbow's axis lies 10 degrees off the perpendicular to the
 *    humerus, CMU's on it), so flexion alone about the rig's axis puts the
 *    forearm up to 12 degrees beside the clip's, and what the transfer puts
 *    across the axis is that geometry, not a pose;
 *  - rotation about the long axis: where the hinge has a child whose long
 *    axis lies along its own (an elbow's wrist), the twist the child's
 *    target has about it, within the hinge's range: a clip turns the
 *    forearm at its wrist (CMU's wrists pronate), a rig at its elbow (the
 *    wrist's range about the forearm is 20 degrees); otherwise none, as the
 *    clip's hinge does not twist and the transfer's twist is geometry.
 */
static void hinge_pose(const pb_retarget *r, int j, const double base[4], double R[4])
{
    const pb_hinge *H = &r->hinge[j];
    double Ni[4], Q[4], ang[3], q0[4], q1[4], n[3], d[3], bi[4];
    pb_quat_conj(H->N, Ni);
    pb_quat_mul(R, Ni, Q);
    hinge_angles(H->b, Q, ang);
    /* Abduction v turns the neutral bone n about b1, leaving it the
     * component n0 cos v + n2 sin v = rho cos(v - phi) along the flexion
     * axis, which flexion keeps: solve it equal to the clip bone's (d, now,
     * in this joint's base frame), nearest to neutral, within the range. */
    pb_quat_rotate(H->N, H->dir, n);
    for (int a = 0; a < 3; a++)
        d[a] = r->wp[r->src[H->bone]][a] - r->wp[r->src[j]][a];
    pb_quat_rotate(r->G, d, d);
    pb_quat_conj(base, bi);
    pb_quat_rotate(bi, d, d);
    double n0 = dot(n, H->b[0]), n2 = dot(n, H->b[2]), rho = hypot(n0, n2), ld = pb_vec_len(d);
    if (rho > 1e-9 && ld > 1e-12) {
        double phi = atan2(n2, n0), w = acos(fmax(-1.0, fmin(1.0, dot(d, H->b[0]) / ld / rho)));
        double v1 = remainder(phi + w, 2.0 * PB_PI), v2 = remainder(phi - w, 2.0 * PB_PI);
        ang[1] = fabs(v1) < fabs(v2) ? v1 : v2;
    }
    ang[1] = clamp_range(ang[1], H->lo[1], H->hi[1]);
    axis_quat(H->b[0], ang[0], q0);
    axis_quat(H->b[1], ang[1], q1);
    pb_quat_mul(q0, q1, R);
    pb_quat_mul(R, H->N, R);
    if (H->child < 0)
        return;
    /* the child's target against the child's neutral on this pose */
    int k = H->child, sk = r->src[k];
    const pb_rig_joint *K = &r->rig->joints[k];
    double dk[4], wk[4], bk[4], bki[4], delta[4], f[3], fl[3], t[4];
    pb_quat_mul(r->wq[sk], r->ref_inv[sk], dk);
    pb_quat_mul(r->G, dk, dk);
    pb_quat_mul(dk, r->Gi, dk);
    pb_quat_mul(dk, r->target[k], wk);
    pb_quat_mul(base, R, bk);
    pb_quat_mul(bk, K->local_q, bk);
    pb_quat_mul(bk, r->hinge[k].N, bk);
    pb_quat_conj(bk, bki);
    pb_quat_mul(wk, bki, delta);
    pb_quat_mul(q0, q1, t);
    pb_quat_rotate(t, H->b[2], fl);
    pb_quat_rotate(base, fl, f);
    double rot = H->sign * clamp_range(H->sign * twist_angle_about(delta, f), H->lo[2], H->hi[2]);
    axis_quat(fl, rot, t);
    pb_quat_mul(t, R, R);
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
    r->origin_p = malloc(nc * sizeof *r->origin_p);
    r->target = malloc(nr * sizeof *r->target);
    r->wq = malloc(nc * sizeof *r->wq);
    r->wp = malloc(nc * sizeof *r->wp);
    r->rw = malloc(nr * sizeof *r->rw);
    r->hinge = calloc(nr, sizeof *r->hinge);
    r->nw = malloc(nr * sizeof *r->nw);
    r->np = malloc(nr * sizeof *r->np);
    double *scratch = malloc(nc * 7 * sizeof *scratch);
    if (!r->src || !r->ref_inv || !r->ref_p || !r->origin_p || !r->target || !r->wq || !r->wp || !r->rw ||
        !r->hinge || !r->nw || !r->np || !scratch) {
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
    /* The root-motion origin first: the reference FK below must be the last to fill r->wq. */
    if (map->root_from_first_frame && clip->frame_count > 0)
        pb_clip_fk(clip, pb_clip_frame(clip, 0), scratch, r->wq, r->origin_p);
    pb_clip_fk(clip, ref_values, scratch, r->wq, r->ref_p);
    if (!map->root_from_first_frame || clip->frame_count == 0)
        memcpy(r->origin_p, r->ref_p, nc * sizeof *r->ref_p);
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
    neutral_posture(r);
    compute_alignment(r, map, (const double (*)[3])hinge, hinge_ok);
    free(hinge_ok);
    free(scratch);
    if (mean_reference(r, map) != POSE_OK) {
        pb_retarget_free(r);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
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
            if (r->hinge[j].driven || r->hinge[j].overflow) {
                if (r->hinge[j].driven)
                    hinge_pose(r, j, base, R);
                else
                    range_overflow(&r->hinge[j], R);
                /* children see the joint as posed, so their directions still follow */
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
            d[a] = (r->wp[root_src][a] - r->origin_p[root_src][a]) * r->scale;
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
