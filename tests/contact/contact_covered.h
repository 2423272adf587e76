/* SPDX-License-Identifier: Apache-2.0 */
/* Skin in bone that the contact response is held to: in a bone that lies
 * within CONTACT_COVERED_REACH of the skin vertex at rest, a bone its skin
 * covers (the library's POSE__PUSH_REACH, which it takes per cluster of 32
 * skin vertices, so it pushes these and some more). Skin inside a bone
 * farther away at rest is in another part of the body (a thigh's skin in
 * the fingers of a hand the neutral posture puts into it, a foot's in the
 * other foot's bones at both knees flexed): moving that skin cannot take
 * the part out, so the response leaves it, and the tests count it apart.
 * Brute force over the posed bone meshes (rays along +x and -x agreeing, as
 * pose_contact_detect counts) and the rest ones (distances). */
#ifndef POSE_TEST_CONTACT_COVERED_H
#define POSE_TEST_CONTACT_COVERED_H

#include "pose/pose.h"
#include "rt_tri.h"
#include "tri_distance.h"

#define CONTACT_COVERED_REACH 0.04

/* Whether p lies inside the bone mesh x (the triangles of ti): crossings of
 * rays along +x and -x both positive, as pose_contact_detect counts (a few
 * bone meshes are open). */
static inline int contact_inside_mesh(const pose_tissue_info *ti, const float *x, const float *p)
{
    static const float minus_x[3] = {-1.0f, 0.0f, 0.0f};
    int w = 0, w2 = 0;
    for (size_t f = 0; f < ti->triangle_count; f++) {
        const uint32_t *t = ti->triangles + 3 * f;
        const float *u = x + 3 * (size_t)t[0], *v = x + 3 * (size_t)t[1], *q = x + 3 * (size_t)t[2];
        w += pose__ray_x_crossing(p, u, v, q);
        w2 += pose__ray_crossing(p, minus_x, u, v, q);
    }
    return w > 0 && w2 > 0;
}

/* Whether p (posed) lies inside one of the bones (tissue indices) that
 * lies within the reach of rest_p at rest. -1: a tissue could not be read. */
static inline int contact_in_covered_bone(const pose_rig *rig, const pose_state *st, const int *bones,
                                          int bone_count, const float *rest_p, const float *p)
{
    for (int i = 0; i < bone_count; i++) {
        pose_tissue_info ti;
        if (pose_rig_tissue_info(rig, bones[i], &ti) != POSE_OK)
            return -1;
        if (!contact_inside_mesh(&ti, pose_tissue_positions(st, bones[i], NULL), p))
            continue;
        const float *r = ti.rest_positions;
        for (size_t f = 0; f < ti.triangle_count; f++) {
            const uint32_t *t = ti.triangles + 3 * f;
            if (tri_distance(rest_p, r + 3 * (size_t)t[0], r + 3 * (size_t)t[1], r + 3 * (size_t)t[2]) <=
                CONTACT_COVERED_REACH)
                return 1;
        }
    }
    return 0;
}

#endif /* POSE_TEST_CONTACT_COVERED_H */
