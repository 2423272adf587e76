/* SPDX-License-Identifier: Apache-2.0 */
#include "rt_fk.h"

/* D = rotation Q q Q* about the rest origin c: p -> r (p - c) + c = r p + (c - r c). */
static void joint_delta(pose__xform *d, const pose__xform *rest, const float q[4])
{
    if (pose__quat_is_identity(q)) {
        pose__xform_identity(d);
        return;
    }
    float tmp[4], conj[4];
    pose__quat_mul(tmp, rest->q, q);
    pose__quat_conj(conj, rest->q);
    pose__quat_mul(d->q, tmp, conj);
    pose__quat_normalize(d->q);
    float rc[3];
    pose__quat_rotate(rc, d->q, rest->t);
    d->t[0] = rest->t[0] - rc[0];
    d->t[1] = rest->t[1] - rc[1];
    d->t[2] = rest->t[2] - rc[2];
}

void pose__fk(size_t joint_count, const int32_t *parents, const pose__xform *rest_model,
              const float (*local)[4], const pose__xform *root, pose__xform *skin,
              pose__xform *world)
{
    for (size_t j = 0; j < joint_count; j++) {
        pose__xform d;
        joint_delta(&d, &rest_model[j], local[j]);
        const pose__xform *parent = parents[j] < 0 ? root : &skin[parents[j]];
        pose__xform_compose(&skin[j], parent, &d);
        pose__xform_compose(&world[j], &skin[j], &rest_model[j]);
    }
}
