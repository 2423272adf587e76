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
 * Resting contacts, inside the solve. A node held on bone step after step
 * (a load: the tissue presses it there) was pushed in by the solve and
 * out by the projection every step, and the solve restarted each step
 * from a velocity its forces contradict: 13 CG iterations a step held at
 * the knees where 1.5 do without contact. So a constraint that pushed
 * (lambda > 0) becomes the node's resting contact on that bone from the
 * next step on: the plane it was pushed to, fixed in the bone's frame,
 * and a multiplier F, the method of multipliers' augmented Lagrangian
 * inside the solve (pose__fem_dyn_contact): the force n (F - k (x' - a) . n)
 * with k = REST_STIFFNESS times the node's own elastic stiffness in A
 * (implicit, so the solve sees the contact's stiffness, and a stiff one
 * leaves the node within F / k of its plane in one step), and after the
 * step F -= k (y - a) . n at the end point y, which over the steps brings
 * F to the load and the node to its plane: then nothing changes from one
 * step to the next and the solve's warm start is its answer. The
 * projection still keeps the node out of that bone (target 0, the
 * surface) and keeps its other constraints. F starts at 0 (the step's
 * impulse was a collision's, not a load's; starting from it threw nodes
 * off), never pulls (clamped at 0), does not follow a node that another
 * bone pushed in the step (squeezed between two, it is off this plane by
 * that push, not by its load), and the contact ends when the node is
 * beyond its plane by more than a tenth of the margin (the plane moved
 * away, or the tissue drew the node off; closer, a squeezed node would
 * let go and come back every other step). A weak contact (k = 1 to 10
 * times) left the solve oscillating: 12-50 CG iterations a step held;
 * a stiffer one (100 to 300 times) 3-8. Measured on the knees and elbows
 * held (tests/contact): 1.9 CG iterations a step held against 1.5
 * without contact.
 *
 * Threads: clusters of POSE__PUSH_CLUSTER nodes (Morton order at rest) in
 * POSE__PUSH_ITEMS items; each node is written by one item; per-item
 * counts summed in item order: the same bits for any thread count. */
#include <math.h>
#include <string.h>

#include "contact_push.h"
#include "state_internal.h"

/** Most constraints of one node (bones it may touch at once). */
#define MAX_CONSTRAINTS POSE__PUSH_NODE_BONES
/** A resting contact's stiffness, a multiple of its node's own elastic
 *  stiffness (fem_dynamics.h stiff). */
#define REST_STIFFNESS 30.0f
/** Most projected Gauss-Seidel sweeps of one node's constraints. */
#define MAX_SWEEPS 16

typedef struct node_contact {
    int count;
    float n[MAX_CONSTRAINTS][3]; /**< outward normals, posed */
    float c[MAX_CONSTRAINTS];    /**< n . dv >= c */
    float q[MAX_CONSTRAINTS][3]; /**< the plane's point (bone's rest frame), */
    float out[MAX_CONSTRAINTS][3]; /**< and normal, should it rest there */
    uint16_t bone[MAX_CONSTRAINTS];
    float depth;                 /**< deepest in bone at the predicted position, >= 0 */
} node_contact;

/* Projected Gauss-Seidel on a node's constraints with B = s n_k . n_l:
 * dv = s sum_k n_k lambda_k. Returns the sweeps taken; the multipliers
 * into lam; the largest into *most. */
static int solve_node(const node_contact *nc, float s, float *dv, float *lam, float *most)
{
    for (int k = 0; k < MAX_CONSTRAINTS; k++)
        lam[k] = 0.0f;
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

/* A resting contact's plane where frame f puts it: point a, normal m. */
static void pose_plane(const float *f, const pose__push_rest *r, float *a, float *m)
{
    for (int e = 0; e < 3; e++) {
        a[e] = f[3 * e] * r->q[0] + f[3 * e + 1] * r->q[1] + f[3 * e + 2] * r->q[2] + f[9 + e];
        m[e] = f[3 * e] * r->n[0] + f[3 * e + 1] * r->n[1] + f[3 * e + 2] * r->n[2];
    }
}

/* Whether a node off a resting contact's plane by `off` has left it:
 * beyond it by more than a tenth of the margin. Closer, the contact
 * stays, and pushes with F - k off or nothing: a node squeezed between
 * two bones, which the other bone's constraint holds a little beyond
 * this plane, keeps the contact instead of letting go and coming back
 * every other step. */
static int left(float off, float margin)
{
    return off > 0.1f * margin;
}

/* The node's resting contact on bone j, or NULL. */
static pose__push_rest *rest_of(pose__push *p, size_t entry, size_t j)
{
    pose__push_rest *r = p->rests + POSE__PUSH_NODE_BONES * entry;
    for (int k = 0; k < p->rest_count[entry]; k++)
        if (r[k].bone == j)
            return &r[k];
    return NULL;
}

/* Where the node ends the step (x + dt v), relative to its resting
 * contacts' planes: the method of multipliers' update F -= k (y - a) . m
 * (F >= 0: contact pushes, never holds), so that over the steps F comes
 * to the force that holds the node on its plane; a node that has left
 * its plane (the bone moves away, or the tissue draws it off) ends that
 * contact. Then the constraints
 * this step's response pushed with (lam > 0) on bones it did not rest on
 * become resting contacts on their planes, from the next step on
 * (multiplier 0: the spring takes the load at once, the multiplier over
 * the steps; the step's impulse is a collision's, not a load's). */
static void rest_update(pose__push *p, size_t entry, float k, const float *x, const float *vel, float dt,
                        const node_contact *nc, const float *lam)
{
    pose__push_rest *r = p->rests + POSE__PUSH_NODE_BONES * entry;
    /* a node another bone pushed this step is squeezed between them: off
     * this plane by that push, not by its load */
    int squeezed = 0;
    for (int c = 0; nc && c < nc->count; c++)
        squeezed |= lam[c] > 0.0f && !rest_of(p, entry, nc->bone[c]);
    int n = 0, ended = 0;
    uint16_t gone[POSE__PUSH_NODE_BONES];
    for (int i = 0; i < p->rest_count[entry]; i++) {
        float off = 0.0f;
        for (int e = 0; e < 3; e++)
            off += r[i].m[e] * (x[e] + dt * vel[e] - r[i].a[e]);
        if (left(off, p->margin)) {
            gone[ended++] = r[i].bone;
            continue;
        }
        if (!squeezed)
            r[i].force = fmaxf(0.0f, r[i].force - k * off);
        r[n++] = r[i];
    }
    p->rest_count[entry] = (uint8_t)n; /* rest_of sees only the contacts kept */
    for (int c = 0; nc && c < nc->count && n < POSE__PUSH_NODE_BONES; c++) {
        /* a contact that ended in this step starts again from the next one
         * (at once, nodes let go and came back: 4.1 CG iterations a step held
         * at the knees against 1.9) */
        int again = 0;
        for (int g = 0; g < ended; g++)
            again |= gone[g] == nc->bone[c];
        if (!(lam[c] > 0.0f) || again || rest_of(p, entry, nc->bone[c]))
            continue;
        pose__push_rest *t = &r[n];
        p->rest_count[entry] = (uint8_t)++n;
        memcpy(t->q, nc->q[c], sizeof t->q);
        memcpy(t->n, nc->out[c], sizeof t->n);
        t->bone = nc->bone[c];
        t->force = 0.0f;
        pose_plane(p->frames + 12 * t->bone, t, t->a, t->m);
        /* a node the response could not bring to the plane this step (a
         * longer move than its depth plus the margin) rests where it ends:
         * the spring starts slack rather than kick it out (kicked: 9.7 CG
         * iterations a step held at the knees) */
        float off = 0.0f;
        for (int e = 0; e < 3; e++)
            off += t->m[e] * (x[e] + dt * vel[e] - t->a[e]);
        if (off < 0.0f) {
            for (int e = 0; e < 3; e++) {
                t->q[e] += off * t->n[e];
                t->a[e] += off * t->m[e];
            }
        }
    }
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
    float *bound = p->bound + item * p->joint_count;
    for (size_t c = cb; c < ce; c++) {
        const size_t vb = c * POSE__PUSH_CLUSTER,
                     ve = vb + POSE__PUSH_CLUSTER < p->node_count ? vb + POSE__PUSH_CLUSTER : p->node_count;
        const size_t count = ve - vb;
        float y[POSE__PUSH_CLUSTER][3], cluster[4], group[GROUPS][4];
        for (size_t i = 0; i < count; i++) {
            const size_t v = p->nodes[vb + i];
            for (int a = 0; a < 3; a++)
                y[i][a] = d->x[3 * v + (size_t)a] + dt * d->v[3 * v + (size_t)a];
        }
        node_contact nc[POSE__PUSH_CLUSTER];
        for (size_t i = 0; i < count; i++) {
            nc[i].count = 0;
            nc[i].depth = 0.0f;
        }
        /* a quiet cluster (contact_quiet.h) has no constraint: its nodes'
         * resting contacts are updated as the full pass would */
        const pose__quiet_pass pass =
            p->quiet_off ? POSE__QUIET_SEARCH
                         : pose__quiet_holds(&p->node_quiet, &p->quiet_joints, p->margin, c, &y[0][0], NULL, count);
        const int quiet = pass == POSE__QUIET_HOLDS;
        float *bounds = pass == POSE__QUIET_RECORD ? bound : NULL;
        if (bounds) {
            pose__quiet_begin(&p->node_quiet, c, &y[0][0], NULL, count);
            for (size_t k = 0; k < p->joint_count; k++)
                bounds[k] = INFINITY;
        }
        const size_t groups = quiet ? 0 : pose__push_spheres(&y[0][0], NULL, 0, count, cluster, group);
        pose__push_anchored anchored;
        if (!quiet)
            pose__push_anchors(p, p->node_anchor + vb, &y[0][0], NULL, NULL, count, &anchored);
        const uint32_t *near = p->near + item * p->bone_count;
        const size_t near_count = quiet ? 0 : pose__push_near_bones(p, item, cluster, NULL, bounds);
        for (size_t kb = 0; kb < near_count; kb++) {
            const size_t j = near[kb];
            const pose__push_bone *b = &p->bones[j];
            const float *f = p->frames + 12 * j;
            for (size_t g = 0; g < groups; g++) {
                if (anchored.group_joint[g] == b->joint) {
                    pose__quiet_bound(bounds, b->joint, anchored.group_clear[g]);
                    continue;
                }
                if (!pose__push_group_near(p, j, group[g], bounds))
                    continue;
                const size_t gb = g * POSE__PUSH_GROUP, ge = gb + POSE__PUSH_GROUP < count ? gb + POSE__PUSH_GROUP : count;
                for (size_t i = gb; i < ge; i++) {
                    if (anchored.joint[i] == b->joint) {
                        pose__quiet_bound(bounds, b->joint, anchored.clear[i]);
                        continue;
                    }
                    float sd, q[3], out[3], clear = 0.0f;
                    const int hit = nc[i].count < MAX_CONSTRAINTS &&
                                    pose__push_query(p, b, f, y[i], &p->node_cache[vb + i], &sd, q, out,
                                                     bounds ? &clear : NULL);
                    pose__quiet_bound(bounds, b->joint, clear);
                    if (!hit)
                        continue;
                    const float plane = p->node_bone[vb + i] == j ? p->node_gap[vb + i] : p->margin;
                    /* a resting contact holds the node at its plane: the
                     * constraint only keeps it out of the bone */
                    const float target = rest_of(p, vb + i, j) ? 0.0f : plane;
                    if (!(sd < target))
                        continue;
                    node_contact *k = &nc[i];
                    const int r = k->count++;
                    for (int e = 0; e < 3; e++)
                        k->n[r][e] = f[3 * e] * out[0] + f[3 * e + 1] * out[1] + f[3 * e + 2] * out[2];
                    k->c[r] = (target - sd) / dt;
                    k->bone[r] = (uint16_t)j;
                    for (int e = 0; e < 3; e++) { /* the plane, should the node rest on it */
                        k->q[r][e] = q[e] + plane * out[e];
                        k->out[r][e] = out[e];
                    }
                    k->depth = fmaxf(k->depth, -sd);
                }
            }
        }
        if (bounds)
            pose__quiet_end(&p->node_quiet, &p->quiet_joints, p->margin, c, bounds);
        for (size_t i = 0; i < count; i++) {
            const size_t v = p->nodes[vb + i];
            const float *b = pre + 6 * v, s = (b[0] + b[3] + b[5]) * (1.0f / 3.0f);
            const float k = REST_STIFFNESS * d->stiff[v];
            if (!nc[i].count || !(s > 0.0f)) {
                rest_update(p, vb + i, k, d->x + 3 * v, d->v + 3 * v, dt, NULL, NULL);
                continue;
            }
            float dv[3], lam[MAX_CONSTRAINTS];
            const int sw = solve_node(&nc[i], s, dv, lam, &impulse);
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
            rest_update(p, vb + i, k, d->x + 3 * v, d->v + 3 * v, dt, &nc[i], lam);
        }
    }
    p->constraints[item] = constraints;
    p->sweeps[item] = sweeps;
    p->max_impulse[item] = impulse;
    p->max_move[item] = moved;
    p->max_excess[item] = excess;
}

void pose__push_forget(pose__push *p, size_t tet_vertex_count)
{
    memset(p->rest_count, 0, p->node_count);
    memset(p->rest_on, 0, tet_vertex_count);
}

void pose__state_contact_rests(pose_state *st, float dt, pose__fem_dyn_contact *out)
{
    pose__push *p = st->push;
    pose__state_push_frames(st); /* the bones at the end of the step */
    const float beta = st->dyn_options.stiffness_damping;
    for (size_t i = 0; i < p->node_count; i++) {
        const size_t v = p->nodes[i];
        if (!p->rest_count[i]) {
            p->rest_on[v] = 0;
            continue;
        }
        const float k = REST_STIFFNESS * st->dyn.stiff[v], *x = st->dyn.x + 3 * v;
        float *S = p->rest_stiff + 6 * v, *g = p->rest_force + 3 * v;
        memset(S, 0, 6 * sizeof *S);
        memset(g, 0, 3 * sizeof *g);
        pose__push_rest *r = p->rests + POSE__PUSH_NODE_BONES * i;
        int n = 0;
        for (int c = 0; c < p->rest_count[i]; c++) {
            float a0[3];
            memcpy(a0, r[c].a, sizeof a0);
            pose_plane(p->frames + 12 * r[c].bone, &r[c], r[c].a, r[c].m);
            const float *a = r[c].a, *m = r[c].m;
            float off = 0.0f, moved = 0.0f;
            for (int e = 0; e < 3; e++) {
                off += m[e] * (x[e] - a[e]);
                moved += m[e] * (a[e] - a0[e]);
            }
            if (left(off, p->margin)) /* the plane has moved off the node */
                continue;
            /* the force at x, with the stiffness damping of the node's
             * motion relative to the plane's (as the couplings') */
            const float along = fmaxf(0.0f, r[c].force - k * off) + beta * k * moved / dt;
            for (int e = 0; e < 3; e++)
                g[e] += along * m[e];
            S[0] += k * m[0] * m[0];
            S[1] += k * m[0] * m[1];
            S[2] += k * m[0] * m[2];
            S[3] += k * m[1] * m[1];
            S[4] += k * m[1] * m[2];
            S[5] += k * m[2] * m[2];
            r[n++] = r[c];
        }
        p->rest_count[i] = (uint8_t)n;
        p->rest_on[v] = n > 0;
    }
    *out = (pose__fem_dyn_contact){.on = p->rest_on, .stiff = p->rest_stiff, .force = p->rest_force};
}

void pose__state_contact_step(pose_state *st, float dt)
{
    pose__push *p = st->push;
    p->step_dt = dt; /* the bones' frames: pose__state_contact_rests, before the solve */
    pose__pool_run_items(st->pool, contact_item, st, POSE__PUSH_ITEMS);
}
