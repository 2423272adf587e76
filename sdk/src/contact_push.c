/* SPDX-License-Identifier: Apache-2.0 */
/* pose/contact.h: pose_set_contact_response, and the pass that pushes the
 * skin out of bone at the end of pose_apply (contact_push.h). */
#include "contact_push.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "rt_quat.h"
#include "state_internal.h"

/* Distance kept from the bone by default: half the acceptance's 1 mm
 * (rig units; metres for pose-bake's rigs). */
#define DEFAULT_MARGIN 0.0005f

void pose__state_push_frames(pose_state *st)
{
    pose__push *p = st->push;
    for (size_t j = 0; j < p->bone_count; j++) {
        const pose__push_bone *b = &p->bones[j];
        const pose__xform *m = &st->skin[b->joint];
        float *f = p->frames + 12 * j, *s = p->bone_spheres + 4 * j;
        pose__quat_to_matrix(m->q, f);
        memcpy(f + 9, m->t, 3 * sizeof(float));
        for (int r = 0; r < 3; r++)
            s[r] = f[3 * r] * b->center[0] + f[3 * r + 1] * b->center[1] + f[3 * r + 2] * b->center[2] + f[9 + r];
        s[3] = b->radius;
    }
}

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

static uint8_t cell_state(const pose__push_bone *b, const float *q)
{
    size_t i[3];
    for (int d = 0; d < 3; d++) {
        const int c = (int)((q[d] - b->lo[d]) / b->cell);
        i[d] = (size_t)(c < 0 ? 0 : c >= b->dim[d] ? b->dim[d] - 1 : c);
    }
    return b->cells[(i[2] * (size_t)b->dim[1] + i[1]) * (size_t)b->dim[0] + i[0]];
}

/* Push x (posed) out of bone b (frame f) to the margin; the move's length,
 * or 0 when x is farther than the margin outside. */
static float push_vertex(const pose__push *p, const pose__push_bone *b, const float *f, float *x)
{
    float q[3];
    to_rest(f, x, q);
    if (!in_box(b, q, 0.0f))
        return 0.0f;
    const uint8_t state = cell_state(b, q);
    if (state == POSE__CELL_OUT)
        return 0.0f;
    /* A point of a NEAR cell is searched within the margin and a cell,
     * where the surface nearly always is (a hit within a shorter reach is
     * the nearest). Nothing there: outside, it is farther than the margin
     * and stays; inside (a ray says so), it searches on, as one of an IN
     * cell does. */
    const float near = p->margin + 1.7320508f * b->cell;
    float c[3], out[3];
    float sd = pose__push_distance(b, q, state == POSE__CELL_NEAR ? near : INFINITY, c, out);
    if (isinf(sd)) {
        if (pose__bvh_winding_along(&b->tree, b->rest, q, f) <= 0)
            return 0.0f;
        sd = pose__push_distance(b, q, INFINITY, c, out);
    }
    if (!(sd < p->margin))
        return 0.0f;
    /* Inside by the pseudo-normal is confirmed by the winding number (rays
     * along the model's +x and -x, as pose_contact_detect casts them): on an open
     * or self-overlapping bone mesh the two can disagree, and a push out of
     * a bone the point is not in would move it by more than any depth. */
    const float minus_x[3] = {-f[0], -f[1], -f[2]};
    if (sd < 0.0f && (pose__bvh_winding_along(&b->tree, b->rest, q, f) <= 0 ||
                      pose__bvh_winding_along(&b->tree, b->rest, q, minus_x) <= 0))
        return 0.0f;
    float y[3], moved = 0.0f;
    for (int k = 0; k < 3; k++)
        q[k] = c[k] + p->margin * out[k];
    for (int r = 0; r < 3; r++) {
        y[r] = f[3 * r] * q[0] + f[3 * r + 1] * q[1] + f[3 * r + 2] * q[2] + f[9 + r];
        moved += (y[r] - x[r]) * (y[r] - x[r]);
    }
    memcpy(x, y, sizeof y);
    return sqrtf(moved);
}

/* Clusters split by part: each vertex is moved by one part, bone after bone
 * in the rig's order, so any thread count gives the same bits. */
void pose__state_push_task(void *ctx, unsigned part, unsigned parts)
{
    pose_state *st = ctx;
    pose__push *p = st->push;
    size_t pushed = 0;
    float most = 0.0f;
    const size_t cb = pose__part_begin(p->cluster_count, part, parts),
                 ce = pose__part_begin(p->cluster_count, part + 1, parts);
    for (size_t c = cb; c < ce; c++) {
        const size_t vb = c * POSE__PUSH_CLUSTER,
                     ve = vb + POSE__PUSH_CLUSTER < p->vertex_count ? vb + POSE__PUSH_CLUSTER : p->vertex_count;
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = vb; i < ve; i++)
            for (int d = 0; d < 3; d++) {
                const float x = st->tissue_positions[3 * (size_t)p->order[i] + (size_t)d];
                lo[d] = x < lo[d] ? x : lo[d];
                hi[d] = x > hi[d] ? x : hi[d];
            }
        const float center[3] = {0.5f * (lo[0] + hi[0]), 0.5f * (lo[1] + hi[1]), 0.5f * (lo[2] + hi[2])};
        const float radius = 0.5f * sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                          (hi[2] - lo[2]) * (hi[2] - lo[2]));
        /* One push per vertex per frame: a vertex pushed out of one bone into
         * another stays there rather than move by more than its depth. */
        uint8_t done[POSE__PUSH_CLUSTER] = {0};
        for (size_t j = 0; j < p->bone_count; j++) {
            const pose__push_bone *b = &p->bones[j];
            const float *s = p->bone_spheres + 4 * j, *f = p->frames + 12 * j;
            const float dx = center[0] - s[0], dy = center[1] - s[1], dz = center[2] - s[2];
            const float reach = radius + s[3] + p->margin;
            if (dx * dx + dy * dy + dz * dz > reach * reach)
                continue;
            float q[3];
            to_rest(f, center, q);
            if (!in_box(b, q, radius))
                continue;
            for (size_t i = vb; i < ve; i++) {
                if (p->skip[i] || done[i - vb])
                    continue;
                const float m = push_vertex(p, b, f, st->tissue_positions + 3 * (size_t)p->order[i]);
                done[i - vb] = m > 0.0f;
                pushed += m > 0.0f;
                most = m > most ? m : most;
            }
        }
    }
    p->pushed[part] = pushed;
    p->max_push[part] = most;
}

void pose__state_push(pose_state *st)
{
    if (!st->push || !st->push_enabled)
        return;
    const double t0 = pose__seconds();
    memset(st->push->pushed, 0, sizeof st->push->pushed);
    memset(st->push->max_push, 0, sizeof st->push->max_push);
    pose__state_push_frames(st);
    pose__pool_run(st->pool, pose__state_push_task, st);
    st->push_seconds = pose__seconds() - t0;
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
        out->seconds = st->push_seconds;
    }
    return POSE_OK;
}
