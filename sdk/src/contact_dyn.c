/* SPDX-License-Identifier: Apache-2.0 */
/* The contact response in pose_step (pose/contact.h, design §2; Otaduy et
 * al. §5.3): velocity-level non-penetration constraints between the tet
 * mesh's soft nodes and the bones, solved by projected Gauss-Seidel after
 * the unconstrained CG solve and before x' = x + dt v'.
 *
 * Constraint. A node at x with the solve's velocity v* would end at
 * y = x + dt v*; the bones are where the step's skinning put them (rigid,
 * kinematic). For every bone that holds y or lies within the margin of it
 * (pose__push_query, the kinematic response's query: grid, BVH, pseudo-
 * normals, inside confirmed by rays), with signed distance s and outward
 * normal n at the nearest surface point, the end position keeps the
 * target distance g (the margin; a node nearer at rest keeps its rest
 * distance to that bone):
 *
 *   s + dt n . (v' - v*) >= g,  i.e.  n . dv >= (g - s) / dt.
 *
 * This is n . (v' - v_bone) >= (g - s_x) / dt, the constraint at the start
 * of the step, linearized about the predicted end point instead: the
 * bone's motion is in its end position, so a node riding on a bone needs
 * no impulse, and a node still outside may approach by what separates it
 * (speculative: no bounce, no energy put in). Stabilization: the whole
 * depth in one step, not a Baumgarte fraction. Penetration here is what
 * one step of posing drives in (the prediction catches it before it
 * happens), so the correction is a step's approach, and the velocity it
 * leaves is the bone's; a fraction would leave nodes inside for several
 * steps while the joint keeps closing.
 *
 * Solve. With A = D_A - L_A - U_A and v* the CG solution, Otaduy's Eq. 6
 * is the LCP  0 <= lambda _|_ B lambda >= d,  B = J D_A^-1 J^T,
 * dv = D_A^-1 J^T lambda per contact island (coupling islands joined by
 * shared constraints). Bones are kinematic, so no constraint joins two
 * coupling islands, and each acts on one node: B couples only the
 * constraints of one node (a node between two bones), and a node's
 * constraints are solved alone, by projected Gauss-Seidel (up to
 * MAX_SWEEPS sweeps); L_A and U_A reach the neighbours through the next
 * step's solve, which starts from v'. D_A's block enters through its
 * isotropic part s = tr(D_A^-1) / 3, so dv = s sum n_k lambda_k lies along
 * the normals: with the full block, dv = D_A^-1 n lambda also has the
 * block's anisotropy, which on the body moved nodes sideways by up to
 * 4.8 mm beyond their depth (measured; the acceptance allows 1 mm). A
 * node squeezed between two bones (normals 125-165 degrees apart at the
 * knee) has constraints that only a longer move meets together, or none
 * (projected Gauss-Seidel then pushes it 1.7-2.5 mm for 0.1-1.2 mm of
 * depth): its dv is scaled back to its depth plus the margin, which the
 * next steps' constraints start from. So no node moves by more than its
 * depth in bone plus the margin, and the impulses are lambda = (n . dv) / s,
 * N s.
 *
 * Threads: clusters of POSE__PUSH_CLUSTER nodes (Morton order at rest) in
 * POSE__PUSH_ITEMS items; each node is written by one item; per-item
 * counts summed in item order: the same bits for any thread count. */
#include <math.h>
#include <string.h>

#include "contact_push.h"
#include "state_internal.h"

/** Most constraints of one node (bones it may touch at once). */
#define MAX_CONSTRAINTS 4
/** Most projected Gauss-Seidel sweeps of one node's constraints. */
#define MAX_SWEEPS 16

typedef struct node_contact {
    int count;
    float n[MAX_CONSTRAINTS][3]; /**< outward normals, posed */
    float c[MAX_CONSTRAINTS];    /**< n . dv >= c */
    float depth;                 /**< deepest in bone at the predicted position, >= 0 */
} node_contact;

/* Projected Gauss-Seidel on a node's constraints with B = s n_k . n_l:
 * dv = s sum_k n_k lambda_k. Returns the sweeps taken; the largest lambda
 * into *most. */
static int solve_node(const node_contact *nc, float s, float *dv, float *most)
{
    float lam[MAX_CONSTRAINTS] = {0};
    dv[0] = dv[1] = dv[2] = 0.0f;
    int sweeps = 0;
    float scale = 0.0f;
    for (int k = 0; k < nc->count; k++)
        scale = fmaxf(scale, fabsf(nc->c[k]));
    while (sweeps < MAX_SWEEPS) {
        sweeps++;
        float change = 0.0f;
        for (int k = 0; k < nc->count; k++) {
            const float *n = nc->n[k];
            const float r = nc->c[k] - (n[0] * dv[0] + n[1] * dv[1] + n[2] * dv[2]);
            const float l = fmaxf(0.0f, lam[k] + r / s), dl = l - lam[k];
            for (int a = 0; a < 3; a++)
                dv[a] += s * dl * n[a];
            lam[k] = l;
            change = fmaxf(change, fabsf(dl) * s); /* velocity along n */
        }
        if (nc->count == 1 || change <= 1e-4f * scale)
            break;
    }
    for (int k = 0; k < nc->count; k++)
        *most = fmaxf(*most, lam[k]);
    return sweeps;
}

static void contact_item(void *ctx, size_t item)
{
    pose_state *st = ctx;
    pose__push *p = st->push;
    pose__fem_dyn *d = &st->dyn;
    const float dt = p->step_dt, *pre = st->fem_work.pre;
    enum { GROUPS = POSE__PUSH_CLUSTER / POSE__PUSH_GROUP };
    size_t constraints = 0;
    int sweeps = 0;
    float impulse = 0.0f, moved = 0.0f, excess = 0.0f;
    const size_t cb = pose__part_begin(p->node_clusters, (unsigned)item, POSE__PUSH_ITEMS),
                 ce = pose__part_begin(p->node_clusters, (unsigned)item + 1, POSE__PUSH_ITEMS);
    for (size_t c = cb; c < ce; c++) {
        const size_t vb = c * POSE__PUSH_CLUSTER,
                     ve = vb + POSE__PUSH_CLUSTER < p->node_count ? vb + POSE__PUSH_CLUSTER : p->node_count;
        const size_t count = ve - vb, groups = (count + POSE__PUSH_GROUP - 1) / POSE__PUSH_GROUP;
        float y[POSE__PUSH_CLUSTER][3], cluster[4], group[GROUPS][4];
        for (size_t i = 0; i < count; i++) {
            const size_t v = p->nodes[vb + i];
            for (int a = 0; a < 3; a++)
                y[i][a] = d->x[3 * v + (size_t)a] + dt * d->v[3 * v + (size_t)a];
        }
        pose__push_sphere(&y[0][0], NULL, 0, count, cluster);
        for (size_t g = 0; g < groups; g++) {
            const size_t gb = g * POSE__PUSH_GROUP;
            pose__push_sphere(&y[0][0], NULL, gb, gb + POSE__PUSH_GROUP < count ? gb + POSE__PUSH_GROUP : count,
                              group[g]);
        }
        node_contact nc[POSE__PUSH_CLUSTER];
        for (size_t i = 0; i < count; i++) {
            nc[i].count = 0;
            nc[i].depth = 0.0f;
        }
        for (size_t j = 0; j < p->bone_count; j++) {
            if (!pose__push_cluster_near(p, j, cluster))
                continue;
            const pose__push_bone *b = &p->bones[j];
            const float *f = p->frames + 12 * j;
            for (size_t g = 0; g < groups; g++) {
                if (!pose__push_sphere_near(b, f, group[g], 0))
                    continue;
                const size_t gb = g * POSE__PUSH_GROUP, ge = gb + POSE__PUSH_GROUP < count ? gb + POSE__PUSH_GROUP : count;
                for (size_t i = gb; i < ge; i++) {
                    float sd, q[3], out[3];
                    if (nc[i].count == MAX_CONSTRAINTS ||
                        !pose__push_query(p, b, f, y[i], &p->node_cache[vb + i], &sd, q, out))
                        continue;
                    const float target = p->node_bone[vb + i] == j ? p->node_gap[vb + i] : p->margin;
                    if (!(sd < target))
                        continue;
                    node_contact *k = &nc[i];
                    for (int r = 0; r < 3; r++)
                        k->n[k->count][r] = f[3 * r] * out[0] + f[3 * r + 1] * out[1] + f[3 * r + 2] * out[2];
                    k->c[k->count] = (target - sd) / dt;
                    k->depth = fmaxf(k->depth, -sd);
                    k->count++;
                }
            }
        }
        for (size_t i = 0; i < count; i++) {
            if (!nc[i].count)
                continue;
            const size_t v = p->nodes[vb + i];
            const float *b = pre + 6 * v, s = (b[0] + b[3] + b[5]) * (1.0f / 3.0f);
            if (!(s > 0.0f))
                continue;
            float dv[3];
            const int sw = solve_node(&nc[i], s, dv, &impulse);
            sweeps = sw > sweeps ? sw : sweeps;
            constraints += (size_t)nc[i].count;
            float m = dt * sqrtf(dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]);
            const float cap = nc[i].depth + p->margin; /* squeezed between bones */
            if (m > cap) {
                for (int a = 0; a < 3; a++)
                    dv[a] *= cap / m;
                m = cap;
            }
            for (int a = 0; a < 3; a++)
                d->v[3 * v + (size_t)a] += dv[a];
            moved = fmaxf(moved, m);
            excess = fmaxf(excess, m - nc[i].depth);
        }
    }
    p->constraints[item] = constraints;
    p->sweeps[item] = sweeps;
    p->max_impulse[item] = impulse;
    p->max_move[item] = moved;
    p->max_excess[item] = excess;
}

void pose__state_contact_step(pose_state *st, float dt)
{
    pose__push *p = st->push;
    p->step_dt = dt;
    pose__state_push_frames(st); /* the bones at the end of the step */
    pose__pool_run_items(st->pool, contact_item, st, POSE__PUSH_ITEMS);
}
