/* SPDX-License-Identifier: Apache-2.0 */
/* Which simulated tets are not tissue: those whose centre lies outside the
 * skin at rest. A coarse bake's lattice fills the gaps between limbs that
 * touch (between the thighs, hand to thigh, arm to trunk) and a shell
 * around the skin; deep flexion stretches those tets several times over and
 * turns them inside out, where the co-rotational rotation changes branch
 * from one step to the next and the body never came to rest (a limit
 * cycle). In the dynamics they turn with the skeleton instead: with the
 * blend of the joints that move their corners (fem_dyn_tets.h,
 * pose__fem_dyn_set_skeletal). */
#include "alloc.h"
#include "contact_build.h"
#include "fem_dyn_tets.h"
#include "state_internal.h"

/* Skin (the fem surface) at rest: its vertices from their embedding in the
 * rig's rest tets. */
static void surface_at_rest(const pose__fem_surface *s, const float *tet_positions, float *out)
{
    for (size_t v = 0; v < s->vertex_count; v++) {
        const uint32_t *tv = s->tets + 4 * (size_t)s->tet[v];
        for (int a = 0; a < 3; a++) {
            float p = 0.0f;
            for (int k = 0; k < 4; k++)
                p += s->bary[4 * v + k] * tet_positions[3 * (size_t)tv[k] + a];
            out[3 * v + a] = p;
        }
    }
}

/* Tet t's (the mesh's) four strongest joints by its corners' skinning
 * weights, summed; their weights normalized. Returns how many (1..4). */
static int tet_joints(const pose_rig *rig, const uint32_t v[4], uint32_t joint[4], float weight[4])
{
    uint32_t j[4 * POSE__MAX_INFLUENCES];
    float w[4 * POSE__MAX_INFLUENCES];
    int n = 0;
    for (int k = 0; k < 4; k++)
        for (unsigned i = 0; i < rig->influences; i++) {
            const size_t at = (size_t)v[k] * rig->influences + i;
            const float wi = rig->weights[at];
            if (!(wi > 0.0f))
                continue;
            int s = 0;
            while (s < n && j[s] != rig->weight_joints[at])
                s++;
            if (s == n) {
                j[n] = rig->weight_joints[at];
                w[n++] = 0.0f;
            }
            w[s] += wi;
        }
    int m = 0;
    float total = 0.0f;
    for (; m < 4 && m < n; m++) { /* selection of the m-th largest */
        int best = m;
        for (int s = m + 1; s < n; s++)
            if (w[s] > w[best] || (w[s] == w[best] && j[s] < j[best]))
                best = s;
        const uint32_t tj = j[m];
        const float tw = w[m];
        j[m] = j[best], w[m] = w[best];
        j[best] = tj, w[best] = tw;
        joint[m] = j[m];
        weight[m] = w[m];
        total += w[m];
    }
    if (m == 0) { /* no weights: the root */
        joint[0] = 0;
        weight[0] = 1.0f;
        return 1;
    }
    for (int i = 0; i < m; i++)
        weight[i] /= total;
    return m;
}

pose_status pose__state_mark_outside_tets(pose_state *st)
{
    const pose__fem_mesh *m = &st->rt->fem;
    const pose__fem_surface *s = &m->surface;
    if (s->vertex_count == 0 || s->triangle_count == 0)
        return POSE_OK; /* no closed skin: every tet is tissue */
    float *rest = pose__alloc(&st->allocator, 3 * s->vertex_count * sizeof(float), POSE__ALIGN);
    if (!rest)
        return POSE_ERR_OUT_OF_MEMORY;
    surface_at_rest(s, st->rig->tet_positions, rest);
    pose__bvh tree = {0};
    pose_status r =
        pose__bvh_build(&tree, &st->allocator, s->triangles, (uint32_t)s->triangle_count, rest);
    if (r == POSE_OK) {
        const float *x = st->rig->tet_positions;
        static const float minus_x[3] = {-1.0f, 0.0f, 0.0f};
        for (size_t t = 0; t < m->tet_count; t++) {
            float c[3] = {0.0f, 0.0f, 0.0f};
            for (int k = 0; k < 4; k++)
                for (int a = 0; a < 3; a++)
                    c[a] += 0.25f * x[3 * (size_t)m->tets[t].v[k] + a];
            /* outside by both rays: where they disagree (a ray grazing an
             * edge), the tet stays tissue */
            const int out = pose__bvh_winding(&tree, rest, c) == 0 &&
                            pose__bvh_winding_along(&tree, rest, c, minus_x) == 0;
            uint32_t joint[4];
            float weight[4];
            const int n = out ? tet_joints(st->rig, m->tets[t].v, joint, weight) : 0;
            pose__fem_dyn_set_skeletal(st->dyn.tets, t, n, joint, weight);
        }
    }
    pose__bvh_release(&tree, &st->allocator);
    pose__free(&st->allocator, rest);
    return r;
}
