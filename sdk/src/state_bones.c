/* SPDX-License-Identifier: Apache-2.0 */
/* Bone tissues moved by their joint's rigid motion (POSE_FEM, dynamics).
 *
 * The bake embeds a bone surface's vertices in whatever tet holds them: a
 * voxelized bone is not its mesh, so part of them lie in soft tets around
 * the bone, and at a joint a few lie in the next bone's tets (on the
 * baked body 21-23 of a femur's 456 vertices, at its head, and 2 of a
 * humerus' at the elbow: 32 and 25 mm from the bone's rigid motion at hip
 * flexion 90 and elbow flexion 120, with every method). The refinement and
 * the dynamics also move the soft tets (by up to 0.9 mm from rigid at the
 * bone surfaces under the dynamics' ramps). Both treat the bones as rigid
 * bodies, their tets' vertices held at, or sprung to, the skinned pose, so
 * a bone tissue of joint j is placed by j's skinning transform itself:
 * rest position and normal, rotated and moved. Vertex by vertex, as the
 * transfer: the same bits on any thread count. */
#include "state_internal.h"

void pose__state_place_bones(pose_state *st, size_t begin, size_t end)
{
    const pose_rig *rig = st->rig;
    const size_t *offset = st->rt->tissue_offset;
    for (size_t t = 0; t < rig->tissue_count; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        if (ts->kind != POSE_TISSUE_BONE || ts->joint < 0)
            continue;
        const size_t b = offset[t] > begin ? offset[t] : begin;
        const size_t e = offset[t + 1] < end ? offset[t + 1] : end;
        const pose__xform *m = &st->skin[ts->joint];
        for (size_t v = b; v < e; v++) {
            float *p = st->tissue_positions + 3 * v, *n = st->tissue_normals + 3 * v;
            pose__quat_rotate(p, m->q, ts->positions + 3 * (v - offset[t]));
            p[0] += m->t[0];
            p[1] += m->t[1];
            p[2] += m->t[2];
            pose__quat_rotate(n, m->q, st->rt->rest_normals + 3 * v);
        }
    }
}
