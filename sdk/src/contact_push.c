/* SPDX-License-Identifier: Apache-2.0 */
/* pose/contact.h: pose_set_contact_response, and the pass that pushes the
 * skin out of bone at the end of pose_apply (contact_push.h). */
#include "contact_push.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "contact_cover.h"
#include "error.h"
#include "rt_quat.h"
#include "state_internal.h"

/* Distance kept from the bone by default: half the acceptance's 1 mm
 * (rig units; metres for pose-bake's rigs). */
#define DEFAULT_MARGIN 0.0005f

/* The bones' frames for the pose, their posed spheres and joints'
 * spheres, and the joints' running moves (contact_quiet.h). */
void pose__state_push_frames(pose_state *st)
{
    pose__push *p = st->push;
    const size_t stride = 64 * p->bone_words;
    for (size_t j = 0; j < p->bone_count; j++) {
        const pose__push_bone *b = &p->bones[j];
        const pose__xform *m = &st->skin[b->joint];
        float *f = p->frames + 12 * j;
        pose__quat_to_matrix(m->q, f);
        memcpy(f + 9, m->t, 3 * sizeof(float));
        for (int r = 0; r < 3; r++)
            p->bone_spheres[(size_t)r * stride + j] =
                f[3 * r] * b->center[0] + f[3 * r + 1] * b->center[1] + f[3 * r + 2] * b->center[2] + f[9 + r];
        p->bone_spheres[3 * stride + j] = b->radius;
    }
    for (size_t k = 0; k < p->joint_count; k++) {
        if (p->joint_start[k + 1] == p->joint_start[k])
            continue;
        const float *f = p->frames + 12 * (size_t)p->joint_bones[p->joint_start[k]], *c = p->joint_spheres + 8 * k;
        for (int r = 0; r < 3; r++)
            p->joint_spheres[8 * k + 4 + (size_t)r] = f[3 * r] * c[0] + f[3 * r + 1] * c[1] + f[3 * r + 2] * c[2] + f[9 + r];
    }
    pose__quiet_joints_update(&p->quiet_joints, st->skin, p->joint_spheres);
}

/* Rounding room on an anchor's test (rig units: 1 micrometre on
 * pose-bake's metres): the point's distance to the joint's bones is
 * measured in their rest frame, through the frame's rounding. */
#define ANCHOR_SLACK 1e-6f

/* x (posed) into the bone's rest frame: R^T (x - t). */
static void to_rest(const float *f, const float *x, float *q)
{
    const float d[3] = {x[0] - f[9], x[1] - f[10], x[2] - f[11]};
    for (int c = 0; c < 3; c++)
        q[c] = f[c] * d[0] + f[3 + c] * d[1] + f[6 + c] * d[2];
}

static int in_box(const pose__push_bone *b, const float *q, float pad)
{
    return q[0] >= b->lo[0] - pad && q[1] >= b->lo[1] - pad && q[2] >= b->lo[2] - pad &&
           q[0] < b->hi[0] + pad && q[1] < b->hi[1] + pad && q[2] < b->hi[2] + pad;
}

/* q's cell, clamped to the grid, and its brick. */
static inline size_t brick_of(const pose__push_bone *b, const float *q, int *i)
{
    for (int d = 0; d < 3; d++) {
        const float e = (q[d] - b->lo[d]) * b->inv_cell;
        const int c = e <= 0.0f ? 0 : e >= (float)b->dim[d] ? b->dim[d] - 1 : (int)e;
        i[d] = c >= b->dim[d] ? b->dim[d] - 1 : c;
    }
    return ((size_t)(i[2] >> 2) * (size_t)b->bricks[1] + (size_t)(i[1] >> 2)) * (size_t)b->bricks[0] +
           (size_t)(i[0] >> 2);
}

/* The grid's code (contact_push.h) at q's cell. */
static inline uint8_t grid_code(const pose__push_bone *b, const float *q)
{
    int i[3];
    const size_t brick = brick_of(b, q, i);
    return b->grid[64 * brick + (size_t)((i[2] & 3) << 4 | (i[1] & 3) << 2 | (i[0] & 3))];
}

/* Point q is outside bone j by d or more: into the cache's slot of bone j,
 * else into slot 0, slot 0 moving to slot 1. */
static void remember(pose__push_cache *cache, const float *q, float d, uint32_t j)
{
    int k = 0;
    if (cache->slot[1].bone == j)
        k = 1;
    else if (cache->slot[0].bone != j)
        cache->slot[1] = cache->slot[0];
    cache->slot[k].q[0] = q[0];
    cache->slot[k].q[1] = q[1];
    cache->slot[k].q[2] = q[2];
    cache->slot[k].d = d;
    cache->slot[k].bone = j;
}

int pose__push_query(const pose__push *p, const pose__push_bone *b, const float *f, const float *x,
                     pose__push_cache *cache, float *signed_distance, float *closest, float *outward,
                     float *bound)
{
    float q[3], unknown;
    to_rest(f, x, q);
    if (!bound)
        bound = &unknown;
    *bound = 0.0f;
    const uint32_t j = (uint32_t)(b - p->bones);
    for (int k = 0; cache && k < 2; k++)
        if (cache->slot[k].bone == j) {
            /* outside by d at the slot's q (the bone's rest frame): a point
             * nearer to it than d - margin is outside by more than the
             * margin (the distance is 1-Lipschitz, and the way there
             * crosses no surface) */
            const float dx = q[0] - cache->slot[k].q[0], dy = q[1] - cache->slot[k].q[1],
                        dz = q[2] - cache->slot[k].q[2], room = cache->slot[k].d - p->margin;
            const float d2 = dx * dx + dy * dy + dz * dz;
            if (d2 < room * room) {
                if (bound != &unknown)
                    *bound = cache->slot[k].d - sqrtf(d2);
                return 0;
            }
        }
    if (!in_box(b, q, 0.0f)) {
        if (cache || bound != &unknown) { /* outside the box, which is the bone's grown by a cell and the margin */
            float e2 = 0.0f;
            for (int d = 0; d < 3; d++) {
                const float e = q[d] < b->lo[d] ? b->lo[d] - q[d] : q[d] > b->hi[d] ? q[d] - b->hi[d] : 0.0f;
                e2 += e * e;
            }
            *bound = sqrtf(e2) + b->cell + p->margin;
            if (cache)
                remember(cache, q, *bound, j);
        }
        return 0;
    }
    const uint8_t code = grid_code(b, q);
    if (code >= POSE__CELL_OUT) {
        /* every cell that is not OUT lies (gap - 1) cells or more away,
         * and the surface and its margin are in those */
        *bound = (float)(code - POSE__CELL_OUT) * b->cell + p->margin;
        if (cache && code > POSE__CELL_OUT)
            remember(cache, q, *bound, j);
        return 0;
    }
    /* A point of a NEAR_OUT cell is outside: only a triangle within the
     * margin matters (with a cache, the search goes as far as for a NEAR
     * cell, so that the distance found lets later queries skip). One of a
     * SURF or NEAR cell has a triangle within sqrt(3) (cell + margin)
     * (contact_push_build.c), so the search within that reach finds the
     * nearest (a hit within a shorter reach is the nearest). Nothing there
     * (rounding): outside, it is farther than the margin and stays; inside
     * (a ray says so), it searches on, as one of an IN cell does. */
    const float near = code == POSE__CELL_SURF ? 1.7320508f * b->cell * 1.003f /* crossed: within its diagonal */
                                               : 1.7320508f * (b->cell + p->margin) * 1.001f;
    float c[3], out[3];
    float sd = pose__push_distance(b, q,
                                   code == POSE__CELL_NEAR_OUT && !cache ? p->margin
                                   : code == POSE__CELL_IN               ? INFINITY
                                                                         : near,
                                   c, out);
    if (code == POSE__CELL_NEAR_OUT && !(fabsf(sd) < p->margin)) { /* nothing within the margin */
        *bound = !cache ? p->margin : isinf(sd) ? near : fabsf(sd);
        if (cache)
            remember(cache, q, *bound, j);
        return 0;
    }
    if (isinf(sd)) {
        if (pose__bvh_winding_along(&b->tree, b->rest, q, f) <= 0) {
            if (code != POSE__CELL_IN) {
                *bound = near;
                if (cache)
                    remember(cache, q, near, j);
            }
            return 0;
        }
        sd = pose__push_distance(b, q, INFINITY, c, out);
    }
    if (!(sd < p->margin)) {
        *bound = sd;
        if (cache)
            remember(cache, q, sd, j);
        return 0;
    }
    /* Inside by the pseudo-normal is confirmed by the winding number (rays
     * along the model's +x and -x, as pose_contact_detect casts them): on an open
     * or self-overlapping bone mesh the two can disagree, and a push out of
     * a bone the point is not in would move it by more than any depth. */
    const float minus_x[3] = {-f[0], -f[1], -f[2]};
    if (sd < 0.0f && (pose__bvh_winding_along(&b->tree, b->rest, q, f) <= 0 ||
                      pose__bvh_winding_along(&b->tree, b->rest, q, minus_x) <= 0))
        return 0;
    *signed_distance = sd;
    memcpy(closest, c, sizeof c);
    memcpy(outward, out, sizeof out);
    return 1;
}

/* Push x (posed) out of bone b (frame f) to the margin; the move's length,
 * or 0 when x is farther than the margin outside (what the query proved
 * of its distance into *bound). */
static float push_vertex(const pose__push *p, const pose__push_bone *b, const float *f, float *x,
                         pose__push_cache *cache, float *bound)
{
    float sd, c[3], out[3];
    if (!pose__push_query(p, b, f, x, cache, &sd, c, out, bound))
        return 0.0f;
    float q[3], y[3], moved = 0.0f;
    for (int k = 0; k < 3; k++)
        q[k] = c[k] + p->margin * out[k];
    for (int r = 0; r < 3; r++) {
        y[r] = f[3 * r] * q[0] + f[3 * r + 1] * q[1] + f[3 * r + 2] * q[2] + f[9 + r];
        moved += (y[r] - x[r]) * (y[r] - x[r]);
    }
    memcpy(x, y, sizeof y);
    return sqrtf(moved);
}

void pose__push_anchors(const pose__push *p, const pose__push_anchor *a, const float *pos, const uint32_t *idx,
                        const uint8_t *skip, size_t count, pose__push_anchored *out)
{
    enum { GROUPS = POSE__PUSH_CLUSTER / POSE__PUSH_GROUP };
    for (size_t g = 0; g < GROUPS; g++) {
        out->group_joint[g] = -2; /* none yet: any joint */
        out->group_clear[g] = INFINITY;
    }
    for (size_t i = 0; i < count; i++) {
        const size_t g = i / POSE__PUSH_GROUP;
        out->joint[i] = -1;
        if (skip && skip[i])
            continue;
        const int32_t j = a[i].joint;
        if (j >= 0) {
            /* |q - rest| is how far the point strays from where the joint
             * alone would carry it: its distance to the joint's bones is
             * at least the rest distance less that */
            float q[3];
            to_rest(p->frames + 12 * (size_t)p->joint_bones[p->joint_start[j]], pos + 3 * (size_t)(idx ? idx[i] : i), q);
            const float dx = q[0] - a[i].rest[0], dy = q[1] - a[i].rest[1], dz = q[2] - a[i].rest[2];
            const float u = sqrtf(dx * dx + dy * dy + dz * dz);
            if (u < a[i].room - ANCHOR_SLACK) {
                out->joint[i] = j;
                out->clear[i] = a[i].room + p->margin - u;
                out->group_clear[g] = out->clear[i] < out->group_clear[g] ? out->clear[i] : out->group_clear[g];
            }
        }
        out->group_joint[g] = out->group_joint[g] == -2 || out->group_joint[g] == out->joint[i] ? out->joint[i] : -1;
    }
}

/* Box lo, hi grown to hold the points pos[3 idx[i]] (pos[3 i] when idx is
 * NULL), i in [vb, ve) (the axes written out: the loop over them was not
 * unrolled). */
static void grow_box(const float *pos, const uint32_t *idx, size_t vb, size_t ve, float *lo, float *hi)
{
    float lx = lo[0], ly = lo[1], lz = lo[2], hx = hi[0], hy = hi[1], hz = hi[2];
    for (size_t i = vb; i < ve; i++) {
        const float *x = pos + 3 * (size_t)(idx ? idx[i] : i);
        lx = x[0] < lx ? x[0] : lx;
        ly = x[1] < ly ? x[1] : ly;
        lz = x[2] < lz ? x[2] : lz;
        hx = x[0] > hx ? x[0] : hx;
        hy = x[1] > hy ? x[1] : hy;
        hz = x[2] > hz ? x[2] : hz;
    }
    lo[0] = lx, lo[1] = ly, lo[2] = lz, hi[0] = hx, hi[1] = hy, hi[2] = hz;
}

/* A box's bounding sphere: its centre and half diagonal. */
static void box_sphere(const float *lo, const float *hi, float *sphere)
{
    for (int d = 0; d < 3; d++)
        sphere[d] = 0.5f * (lo[d] + hi[d]);
    sphere[3] = 0.5f * sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                             (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

void pose__push_sphere(const float *pos, const uint32_t *idx, size_t vb, size_t ve, float *sphere)
{
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    grow_box(pos, idx, vb, ve, lo, hi);
    box_sphere(lo, hi, sphere);
}

size_t pose__push_spheres(const float *pos, const uint32_t *idx, size_t vb, size_t ve, float *cluster,
                          float (*group)[4])
{
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t g = 0;
    for (size_t gb = vb; gb < ve; gb += POSE__PUSH_GROUP, g++) {
        float glo[3] = {INFINITY, INFINITY, INFINITY}, ghi[3] = {-INFINITY, -INFINITY, -INFINITY};
        grow_box(pos, idx, gb, gb + POSE__PUSH_GROUP < ve ? gb + POSE__PUSH_GROUP : ve, glo, ghi);
        box_sphere(glo, ghi, group[g]);
        for (int d = 0; d < 3; d++) {
            lo[d] = glo[d] < lo[d] ? glo[d] : lo[d];
            hi[d] = ghi[d] > hi[d] ? ghi[d] : hi[d];
        }
    }
    box_sphere(lo, hi, cluster);
    return g;
}

int pose__push_sphere_far(const pose__push *p, size_t j, const float *sphere, float *bound)
{
    const pose__push_bone *b = &p->bones[j];
    float q[3];
    to_rest(p->frames + 12 * j, sphere, q);
    if (!in_box(b, q, sphere[3])) { /* the box is the bone's grown by a cell and the margin */
        if (bound) {
            float e2 = 0.0f;
            for (int d = 0; d < 3; d++) {
                const float e = q[d] < b->lo[d] ? b->lo[d] - q[d] : q[d] > b->hi[d] ? q[d] - b->hi[d] : 0.0f;
                e2 += e * e;
            }
            pose__quiet_bound_root(bound, b->joint, e2, sphere[3] - b->cell - p->margin);
        }
        return 1;
    }
    int i[3];
    const size_t brick = brick_of(b, q, i);
    /* the brick's least gap (a small map, mostly in cache): a cell's gap
     * is at least its brick's; its non-OUT cells hold the surface and its
     * margin */
    const float reach = sphere[3] * 1.001f + 1e-6f;
    const int least = b->brick_gap[brick];
    if (least > 1 && ((float)least - 1.0f) * b->cell > reach) {
        pose__quiet_bound(bound, b->joint, ((float)least - 1.0f) * b->cell - sphere[3] + p->margin);
        return 1;
    }
    return 0;
}

int pose__push_group_near(const pose__push *p, size_t j, const float *group, float *bound)
{
    if (!pose__push_spheres_near(p, j, group)) {
        pose__push_spheres_bound(p, j, group, bound);
        return 0;
    }
    return !pose__push_sphere_far(p, j, group, bound);
}

/* How far a joint's sphere may lie from a cluster's for its gap to stand
 * for its bones' in the cluster's quiet bound (rig units: 30 mm), instead
 * of each bone's own: a cluster stays quiet that long either way. */
#define QUIET_FAR 0.03f

/* What the sphere tests proved of the bones not hit (hit: a byte per
 * bone), into bound: per joint, its sphere's gap when far, else its
 * bones' own. */
static void bound_spheres(const pose__push *p, const float *cluster, const uint8_t *hit, float *bound)
{
    for (size_t k = 0; k < p->joint_count; k++) {
        const float *js = p->joint_spheres + 8 * k + 4;
        const float dx = cluster[0] - js[0], dy = cluster[1] - js[1], dz = cluster[2] - js[2];
        const float gap = sqrtf(dx * dx + dy * dy + dz * dz) - cluster[3] - js[3];
        if (gap > QUIET_FAR) {
            pose__quiet_bound(bound, (int)k, gap);
            continue;
        }
        for (uint32_t e = p->joint_start[k]; e < p->joint_start[k + 1]; e++)
            if (!hit[p->joint_bones[e]])
                pose__push_spheres_bound(p, p->joint_bones[e], cluster, bound);
    }
}

size_t pose__push_near_bones(const pose__push *p, size_t item, const float *cluster, const uint64_t *mask,
                             float *bound)
{
    uint32_t *near = p->near + item * p->bone_count;
    uint8_t *hit = p->hit + item * p->bone_count;
    size_t n = 0;
    for (size_t w = 0; w < p->bone_words; w++) {
        uint64_t bits = 0;
        if (mask) { /* the few bones it marks */
            for (uint64_t m = mask[w]; m; m &= m - 1) {
                const size_t j = 64 * w + (size_t)__builtin_ctzll(m);
                if (pose__push_spheres_near(p, j, cluster))
                    bits |= m & -m;
                else
                    pose__push_spheres_bound(p, j, cluster, bound);
            }
        } else { /* all: 64 side by side (no branch), then their bits */
            uint8_t *h = hit + 64 * w;
            const size_t count = p->bone_count - 64 * w < 64 ? p->bone_count - 64 * w : 64;
            for (size_t k = 0; k < count; k++)
                h[k] = (uint8_t)pose__push_spheres_near(p, 64 * w + k, cluster);
            for (size_t k = 0; k < count; k++)
                bits |= (uint64_t)h[k] << k;
        }
        for (; bits; bits &= bits - 1) {
            const size_t j = 64 * w + (size_t)__builtin_ctzll(bits);
            if (!pose__push_sphere_far(p, j, cluster, bound))
                near[n++] = (uint32_t)j;
        }
    }
    if (bound && !mask)
        bound_spheres(p, cluster, hit, bound);
    return n;
}

/* Clusters split into items: each vertex is moved by one item, bone after
 * bone in the rig's order, and each item writes its own counts, so any
 * thread count and any assignment of items give the same bits. A cluster
 * still quiet (contact_quiet.h) is left as it is; the others are tested
 * against a bone's sphere, box and grid, then their groups of
 * POSE__PUSH_GROUP against sphere and grid, then their vertices. */
void pose__state_push_item(void *ctx, size_t item)
{
    pose_state *st = ctx;
    pose__push *p = st->push;
    size_t pushed = 0;
    float most = 0.0f;
    enum { GROUPS = POSE__PUSH_CLUSTER / POSE__PUSH_GROUP };
    const size_t cb = pose__part_begin(p->cluster_count, (unsigned)item, POSE__PUSH_ITEMS),
                 ce = pose__part_begin(p->cluster_count, (unsigned)item + 1, POSE__PUSH_ITEMS);
    float *bound = p->bound + item * p->joint_count;
    for (size_t c = cb; c < ce; c++) {
        const size_t vb = c * POSE__PUSH_CLUSTER,
                     ve = vb + POSE__PUSH_CLUSTER < p->vertex_count ? vb + POSE__PUSH_CLUSTER : p->vertex_count;
        const pose__quiet_pass pass =
            p->quiet_off ? POSE__QUIET_SEARCH
                         : pose__quiet_holds(&p->skin_quiet, &p->quiet_joints, p->margin, c, st->tissue_positions,
                                             p->order + vb, ve - vb);
        if (pass == POSE__QUIET_HOLDS)
            continue;
        float *bounds = pass == POSE__QUIET_RECORD ? bound : NULL;
        if (bounds) {
            pose__quiet_begin(&p->skin_quiet, c, st->tissue_positions, p->order + vb, ve - vb);
            for (size_t k = 0; k < p->joint_count; k++)
                bounds[k] = INFINITY;
        }
        float cluster[4], group[GROUPS][4];
        const size_t groups = pose__push_spheres(st->tissue_positions, p->order, vb, ve, cluster, group);
        /* One push per vertex per frame: a vertex pushed out of one bone into
         * another stays there rather than move by more than its depth. (A
         * vertex not yet pushed has not moved: the spheres hold it.) */
        uint8_t done[POSE__PUSH_CLUSTER] = {0};
        pose__push_anchored anchored;
        pose__push_anchors(p, p->anchor + vb, st->tissue_positions, p->order + vb, p->skip + vb, ve - vb, &anchored);
        const uint32_t *near = p->near + item * p->bone_count;
        const size_t near_count = pose__push_near_bones(p, item, cluster, p->reach + c * p->bone_words, bounds);
        for (size_t k = 0; k < near_count; k++) {
            const pose__push_bone *b = &p->bones[near[k]];
            const float *f = p->frames + 12 * (size_t)near[k];
            for (size_t g = 0; g < groups; g++) {
                if (anchored.group_joint[g] == b->joint) {
                    pose__quiet_bound(bounds, b->joint, anchored.group_clear[g]);
                    continue;
                }
                if (!pose__push_group_near(p, near[k], group[g], bounds))
                    continue;
                const size_t gb = vb + g * POSE__PUSH_GROUP, ge = gb + POSE__PUSH_GROUP < ve ? gb + POSE__PUSH_GROUP : ve;
                for (size_t i = gb; i < ge; i++) {
                    if (p->skip[i] || done[i - vb])
                        continue;
                    if (anchored.joint[i - vb] == b->joint) {
                        pose__quiet_bound(bounds, b->joint, anchored.clear[i - vb]);
                        continue;
                    }
                    float *x = st->tissue_positions + 3 * (size_t)p->order[i], before[3], clear = 0.0f;
                    memcpy(before, x, sizeof before);
                    float m = push_vertex(p, b, f, x, &p->cache[i], bounds ? &clear : NULL);
                    pose__quiet_bound(bounds, b->joint, clear);
                    done[i - vb] = m > 0.0f;
                    if (m > 0.0f) {
                        /* lifted first: counted by the cover, its whole move here */
                        const float whole = pose__cover_bound(p, b, f, i, before, x);
                        pushed += !(whole >= 0.0f);
                        m = whole >= 0.0f ? whole : m;
                    }
                    most = m > most ? m : most;
                }
            }
        }
        if (bounds)
            pose__quiet_end(&p->skin_quiet, &p->quiet_joints, p->margin, c, bounds);
    }
    p->pushed[item] = pushed;
    p->max_push[item] = most;
}

/* The response's pass: the bones' frames, then (pose_apply) the cover's
 * lifts, then the push, item by item. */
static void push_pass(pose_state *st, int cover)
{
    if (!st->push || !st->push_enabled)
        return;
    const double t0 = pose__seconds();
    memset(st->push->pushed, 0, sizeof st->push->pushed);
    memset(st->push->max_push, 0, sizeof st->push->max_push);
    pose__state_push_frames(st);
    pose__cover *c = st->push->cover;
    c->moved = 0;
    c->max_move = 0.0f;
    if (cover)
        pose__state_cover(st); /* contact_cover.c: skin lifted over bone that came out through it */
    pose__pool_run_items(st->pool, pose__state_push_item, st, POSE__PUSH_ITEMS);
    pose__cover_finish(c);
    st->push_seconds = pose__seconds() - t0;
}

void pose__state_push(pose_state *st)
{
    push_pass(st, 0);
}

void pose__state_push_cover(pose_state *st)
{
    push_pass(st, 1);
}

void pose__state_push_free(pose_state *st)
{
    if (!st->push)
        return;
    pose__push_release(st->push);
    pose__free(&st->allocator, st->push);
    st->push = NULL;
}

pose_status pose_set_contact_response(pose_state *st, const pose_contact_response *settings)
{
    pose__clear_error();
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_contact_response: state is NULL");
    pose_contact_response s = {0};
    if (settings) {
        if (settings->size != 0 && settings->size != sizeof s)
            return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_contact_response: size %zu (expected %zu or 0)",
                              settings->size, sizeof s);
        s = *settings;
    }
    if (!isfinite(s.margin) || s.margin < 0.0f)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_contact_response: margin %g", (double)s.margin);
    const float margin = s.margin > 0.0f ? s.margin : DEFAULT_MARGIN;
    if (s.enabled && (!st->push || st->push->margin != margin)) {
        pose__state_push_free(st);
        pose__push *p = pose__calloc(&st->allocator, sizeof *p, POSE__ALIGN);
        if (!p)
            return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for the contact response");
        p->allocator = st->allocator;
        st->push = p;
        const pose_status r = pose__push_build(p, st, margin);
        if (r != POSE_OK) {
            pose__state_push_free(st);
            st->push_enabled = 0;
            return r;
        }
    }
    if (s.enabled && !st->push_enabled && st->push->nodes_built) /* contacts from before it was off */
        pose__push_forget(st->push, st->rig->tet_vertex_count);
    st->push_enabled = s.enabled != 0;
    return POSE_OK;
}

pose_status pose_get_contact_response_stats(const pose_state *st, pose_contact_response_stats *out)
{
    pose__clear_error();
    if (!st || !out || out->size != sizeof *out)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_get_contact_response_stats: state, and out with its size set, are required");
    const size_t size = out->size;
    memset(out, 0, sizeof *out);
    out->size = size;
    if (!st->push)
        return POSE_OK;
    out->margin = st->push->margin;
    out->build_seconds = st->push->build_seconds;
    if (st->push_enabled) {
        for (size_t k = 0; k < sizeof st->push->pushed / sizeof st->push->pushed[0]; k++) {
            out->pushed += st->push->pushed[k];
            out->max_push = st->push->max_push[k] > out->max_push ? st->push->max_push[k] : out->max_push;
        }
        const pose__cover *c = st->push->cover;
        out->pushed += c->moved;
        out->max_push = c->max_move > out->max_push ? c->max_move : out->max_push;
        out->seconds = st->push_seconds;
    }
    return POSE_OK;
}
