/* SPDX-License-Identifier: Apache-2.0 */
/* Bone tissues moved by their joint's rigid motion, with every method.
 *
 * The bake embeds a bone surface's vertices in whatever tet holds them: a
 * voxelized bone is not its mesh, so part of them lie in soft tets around
 * the bone, and at a joint a few lie in the next bone's tets (on the
 * baked body 21-23 of a femur's 456 vertices, at its head, and 2 of a
 * humerus' at the elbow: 32 and 25 mm from the bone's rigid motion at hip
 * flexion 90 and elbow flexion 120, with every method). The refinement and
 * the dynamics also move the soft tets (by up to 0.9 mm from rigid at the
 * bone surfaces under the dynamics' ramps). Bones are rigid bodies (and
 * the simulation holds their tets' vertices at, or springs them to, the
 * skinned pose), so a bone tissue of joint j is placed by j's skinning
 * transform itself:
 * rest position and normal, rotated and moved, and the transfer skips the
 * blocks that hold bone vertices only. Vertex by vertex, as the transfer:
 * the same bits on any thread count. */
#include "rt_transfer.h"
#include "state_internal.h"

/* Tissue ts is placed by its joint, not by the transfer. */
static int rigid(const pose__tissue *ts)
{
    return ts->kind == POSE_TISSUE_BONE && ts->joint >= 0;
}

size_t pose__state_transfer_soft(pose_state *st, size_t begin, size_t end, uint32_t *flagged)
{
    /* Bones are most of a body's tissue vertices (144 k of 158 k on the
     * coarse bake): the transfer runs on the blocks holding any other
     * vertex, runs of tissues at a time, each block once. */
    const pose_rig *rig = st->rig;
    const size_t *offset = st->rt->tissue_offset;
    size_t count = 0, done = begin;
    for (size_t t = 0; t < rig->tissue_count;) {
        if (rigid(&rig->tissues[t])) {
            t++;
            continue;
        }
        const size_t v0 = offset[t];
        while (t < rig->tissue_count && !rigid(&rig->tissues[t]))
            t++;
        const size_t v1 = offset[t];
        size_t b = v0 / POSE__BLOCK, e = (v1 + POSE__BLOCK - 1) / POSE__BLOCK;
        b = b > done ? b : done;
        e = e < end ? e : end;
        if (v1 > v0 && b < e) {
            count += pose__transfer(&st->rt->transfer, st->tet_positions, b, e,
                                    st->tissue_positions, st->tissue_normals, flagged + count);
            done = e;
        }
    }
    return count;
}

/* `count` points r and normals n through (R, t) into p and o: the matrix in
 * locals and the arrays restrict, so that no store makes the compiler
 * reload them. */
static void place_rigid(const float *R, const float *t, const float *restrict r, const float *restrict n,
                        float *restrict p, float *restrict o, size_t count)
{
    const float r00 = R[0], r01 = R[1], r02 = R[2], r10 = R[3], r11 = R[4], r12 = R[5], r20 = R[6], r21 = R[7],
                r22 = R[8], t0 = t[0], t1 = t[1], t2 = t[2];
    for (size_t v = 0; v < 3 * count; v += 3) {
        const float x = r[v], y = r[v + 1], z = r[v + 2], a = n[v], b = n[v + 1], c = n[v + 2];
        p[v] = r00 * x + r01 * y + r02 * z + t0;
        p[v + 1] = r10 * x + r11 * y + r12 * z + t1;
        p[v + 2] = r20 * x + r21 * y + r22 * z + t2;
        o[v] = r00 * a + r01 * b + r02 * c;
        o[v + 1] = r10 * a + r11 * b + r12 * c;
        o[v + 2] = r20 * a + r21 * b + r22 * c;
    }
}

void pose__state_place_bones(pose_state *st, size_t begin, size_t end)
{
    const pose_rig *rig = st->rig;
    const size_t *offset = st->rt->tissue_offset;
    for (size_t t = 0; t < rig->tissue_count; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        const size_t b = offset[t] > begin ? offset[t] : begin;
        const size_t e = offset[t + 1] < end ? offset[t + 1] : end;
        if (!rigid(ts) || b >= e)
            continue;
        const pose__xform *m = &st->skin[ts->joint];
        float R[9];
        pose__quat_to_matrix(m->q, R);
        place_rigid(R, m->t, ts->positions + 3 * (b - offset[t]), st->rt->rest_normals + 3 * b,
                    st->tissue_positions + 3 * b, st->tissue_normals + 3 * b, e - b);
    }
}
