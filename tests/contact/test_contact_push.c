/* SPDX-License-Identifier: Apache-2.0 */
/* pose_set_contact_response on the body baked from data/anatomy (coarse,
 * the tests' shared bake) at issue 13's poses, LBS and DQS: skin vertices in
 * a bone they cover and bone vertices out of the skin (pose_contact_detect)
 * with the response off and on, to fall by 80 % and 95 % (MIN_FALL_*); no
 * skin vertex moves by more than its depth (in bone, or of the bone that
 * comes out through its own triangles: cover_depth) plus 1 mm; the pass's
 * time (skin_out_of_bone). 1 and 2 threads give the same tissues bit for bit
 * (threads_agree); the response offsets change little from frame to frame
 * as joints sweep (continuous_in_a_sweep). Skin in bone at rest (the orbits
 * and the mouth) is anatomy, left alone and counted apart. A rig path is
 * taken from POSE_CONTACT_RIG. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "contact_body.h"
#include "pose/contact.h"
#include "pose/pose.h"
#include "rt_tri.h"
#include "contact_covered.h"
#include "tri_distance.h"

/* The acceptance's bound on a move beyond the depth, and the falls this
 * test holds the response to (the issue asks 0.95 for bone out of the
 * skin). Skin in bone counts skin in a bone it covers (contact_covered.h:
 * 102 -> 17 measured, 83 %; skin in any bone, 598 -> 430, is mostly a part
 * posed into another, which the response leaves). Skin in bone
 * and bone out of skin are counted without what is so at rest (123 skin
 * vertices in the orbits and the mouth, 2011 bone vertices of the skull,
 * jaw and scapulae; data/anatomy/README.md). A skin vertex's depth is the
 * larger of its depth in bone and the protrusion (distance to the skin) of
 * the bone that comes out through one of its own triangles: a bone vertex
 * newly out of the skin, without the response, whose nearest skin point
 * lies on one of them or that lies over one of them (its projection on
 * the triangle's plane inside it, on the outer side); those triangles must
 * rise by that much to cover it (cover_depth). */
#define MOVE_SLACK 1e-3
#define MAX_POKES 20000
#define MIN_FALL_SKIN_IN_BONE 0.80
#define MIN_FALL_BONE_OUT 0.95

typedef struct body {
    pose_rig *rig;
    int skin;
    size_t skin_count;
    int bones[256];
    int bone_count;
} body;

/* Depth of p in bone: for each posed bone that holds p (winding numbers by
 * rays along +x and -x agreeing, as pose_contact_detect counts), the distance to that bone's surface;
 * the largest of them, 0 when no bone holds p. */
static double bone_depth(const body *b, const pose_state *st, const float *p)
{
    double depth = 0.0;
    for (int i = 0; i < b->bone_count; i++) {
        pose_tissue_info ti;
        assert_int_equal(pose_rig_tissue_info(b->rig, b->bones[i], &ti), POSE_OK);
        const float *x = pose_tissue_positions(st, b->bones[i], NULL);
        if (!contact_inside_mesh(&ti, x, p))
            continue;
        double d = INFINITY;
        for (size_t f = 0; f < ti.triangle_count; f++) {
            const uint32_t *t = ti.triangles + 3 * f;
            d = fmin(d, tri_distance(p, x + 3 * (size_t)t[0], x + 3 * (size_t)t[1], x + 3 * (size_t)t[2]));
        }
        depth = fmax(depth, d);
    }
    return depth;
}

/* Skin vertices flagged in bone (not at rest) that are in a bone they cover. */
static size_t count_covered(const body *b, const pose_contact *det, const pose_state *st, const float *skin,
                            const uint8_t *rest_in)
{
    pose_tissue_info ti;
    assert_int_equal(pose_rig_tissue_info(b->rig, b->skin, &ti), POSE_OK);
    const uint8_t *f = pose_contact_vertex_flags(det, b->skin, NULL);
    size_t k = 0;
    for (size_t v = 0; v < b->skin_count; v++)
        if (f[v] && !rest_in[v])
            k += (size_t)(contact_in_covered_bone(b->rig, st, b->bones, b->bone_count, ti.rest_positions + 3 * v,
                                                  skin + 3 * v) == 1);
    return k;
}

/* Distance from p to the skin `x` (its posed vertices). */
static double skin_distance(const body *b, const float *x, const float *p)
{
    pose_tissue_info ti;
    assert_int_equal(pose_rig_tissue_info(b->rig, b->skin, &ti), POSE_OK);
    double d = INFINITY;
    for (size_t f = 0; f < ti.triangle_count; f++) {
        const uint32_t *t = ti.triangles + 3 * f;
        d = fmin(d, tri_distance(p, x + 3 * (size_t)t[0], x + 3 * (size_t)t[1], x + 3 * (size_t)t[2]));
    }
    return d;
}

/* Per skin vertex (cover[v], zeroed by the caller), the largest
 * protrusion poke[4 k + 3] of the bone vertices poke[4 k] that come out
 * through one of its triangles of the skin `x`: nearest to it (within
 * 1e-6 of the least distance: a nearest edge or corner is every
 * touching triangle's), or over it. */
static void cover_depth(const body *b, const float *x, const float *poke, size_t pokes, double *cover)
{
    pose_tissue_info ti;
    assert_int_equal(pose_rig_tissue_info(b->rig, b->skin, &ti), POSE_OK);
    for (size_t k = 0; k < pokes; k++) {
        const float *q = poke + 4 * k;
        for (size_t f = 0; f < ti.triangle_count; f++) {
            const uint32_t *t = ti.triangles + 3 * f;
            const float *a = x + 3 * (size_t)t[0], *u = x + 3 * (size_t)t[1], *w = x + 3 * (size_t)t[2];
            int through = tri_distance(q, a, u, w) <= (double)q[3] + 1e-6;
            if (!through) {
                double e1[3], e2[3], r[3], n[3];
                for (int d = 0; d < 3; d++) {
                    e1[d] = (double)u[d] - a[d];
                    e2[d] = (double)w[d] - a[d];
                    r[d] = (double)q[d] - a[d];
                }
                n[0] = e1[1] * e2[2] - e1[2] * e2[1];
                n[1] = e1[2] * e2[0] - e1[0] * e2[2];
                n[2] = e1[0] * e2[1] - e1[1] * e2[0];
                const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
                if (!(nn > 0.0) || n[0] * r[0] + n[1] * r[1] + n[2] * r[2] <= 0.0)
                    continue;
                /* barycentric coordinates of the projection: signed areas */
                double c1[3], c2[3];
                c1[0] = r[1] * e2[2] - r[2] * e2[1];
                c1[1] = r[2] * e2[0] - r[0] * e2[2];
                c1[2] = r[0] * e2[1] - r[1] * e2[0];
                c2[0] = e1[1] * r[2] - e1[2] * r[1];
                c2[1] = e1[2] * r[0] - e1[0] * r[2];
                c2[2] = e1[0] * r[1] - e1[1] * r[0];
                const double s1 = (c1[0] * n[0] + c1[1] * n[1] + c1[2] * n[2]) / nn,
                             s2 = (c2[0] * n[0] + c2[1] * n[1] + c2[2] * n[2]) / nn;
                through = s1 >= 0.0 && s2 >= 0.0 && s1 + s2 <= 1.0;
            }
            if (through)
                for (int i = 0; i < 3; i++)
                    cover[t[i]] = fmax(cover[t[i]], q[3]);
        }
    }
}

static void set_response(pose_state *st, int on)
{
    pose_contact_response r = {.size = sizeof r, .enabled = on};
    assert_int_equal(pose_set_contact_response(st, &r), POSE_OK);
}

static size_t count_flags(const pose_contact *c, int tissue, const uint8_t *except)
{
    size_t n, k = 0;
    const uint8_t *f = pose_contact_vertex_flags(c, tissue, &n);
    assert_non_null(f);
    for (size_t v = 0; v < n; v++)
        k += f[v] != 0 && !(except && except[v]);
    return k;
}

static void invalid_settings(void **unused)
{
    (void)unused;
    assert_int_equal(pose_set_contact_response(NULL, NULL), POSE_ERR_INVALID_ARGUMENT);
    pose_contact_response_stats s = {.size = sizeof s};
    assert_int_equal(pose_get_contact_response_stats(NULL, &s), POSE_ERR_INVALID_ARGUMENT);
    pose_rig *rig;
    if (pose_rig_load(getenv("POSE_CONTACT_RIG"), &rig) != POSE_OK)
        fail_msg("%s", pose_last_error());
    pose_state *st;
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    pose_contact_response r = {.size = 1, .enabled = 1};
    assert_int_equal(pose_set_contact_response(st, &r), POSE_ERR_INVALID_ARGUMENT);
    r = (pose_contact_response){.size = sizeof r, .enabled = 1, .margin = -1.0f};
    assert_int_equal(pose_set_contact_response(st, &r), POSE_ERR_INVALID_ARGUMENT);
    r.margin = NAN;
    assert_int_equal(pose_set_contact_response(st, &r), POSE_ERR_INVALID_ARGUMENT);
    s.size = 0;
    assert_int_equal(pose_get_contact_response_stats(st, &s), POSE_ERR_INVALID_ARGUMENT);
    s.size = sizeof s;
    assert_int_equal(pose_get_contact_response_stats(st, &s), POSE_OK);
    assert_int_equal(s.pushed, 0);
    assert_true(s.build_seconds == 0.0);
    pose_state_free(st);
    pose_rig_free(rig);
}

static void skin_out_of_bone(void **unused)
{
    (void)unused;
    setvbuf(stdout, NULL, _IONBF, 0);
    body b = {0};
    if (pose_rig_load(getenv("POSE_CONTACT_RIG"), &b.rig) != POSE_OK)
        fail_msg("%s", pose_last_error());
    b.skin = -1;
    for (int t = 0; t < (int)pose_rig_tissue_count(b.rig); t++) {
        pose_tissue_info ti;
        assert_int_equal(pose_rig_tissue_info(b.rig, t, &ti), POSE_OK);
        if (ti.kind == POSE_TISSUE_SKIN && b.skin < 0) {
            b.skin = t;
            b.skin_count = ti.vertex_count;
        }
        if (ti.kind == POSE_TISSUE_BONE && b.bone_count < 256)
            b.bones[b.bone_count++] = t;
    }
    assert_true(b.skin >= 0 && b.bone_count > 0);
    pose_contact *det;
    pose_contact_options co = {.size = sizeof co, .threads = 2};
    assert_int_equal(pose_contact_create(b.rig, &co, &det), POSE_OK);
    pose_state_options so = {.size = sizeof so, .threads = 2};
    pose_state *st;
    assert_int_equal(pose_state_create_ex(b.rig, &so, &st), POSE_OK);

    /* Rest: which skin is in bone and which bone is out of the skin as
     * anatomy or data (not counted below). */
    assert_int_equal(pose_apply(st), POSE_OK);
    assert_int_equal(pose_contact_detect(det, st, NULL), POSE_OK);
    size_t n;
    uint8_t *rest_in = malloc(b.skin_count);
    assert_non_null(rest_in);
    memcpy(rest_in, pose_contact_vertex_flags(det, b.skin, &n), b.skin_count);
    uint8_t *rest_out[256];
    size_t rest_out_count = 0;
    for (int i = 0; i < b.bone_count; i++) {
        const uint8_t *f = pose_contact_vertex_flags(det, b.bones[i], &n);
        rest_out[i] = malloc(n + 1);
        assert_non_null(rest_out[i]);
        memcpy(rest_out[i], f, n);
        rest_out_count += count_flags(det, b.bones[i], NULL);
    }
    printf("rest: %zu skin vertices in bone, %zu bone vertices out of the skin (not counted)\n",
           count_flags(det, b.skin, NULL), rest_out_count);

    set_response(st, 1);
    pose_contact_response_stats rs = {.size = sizeof rs};
    assert_int_equal(pose_get_contact_response_stats(st, &rs), POSE_OK);
    printf("response built in %.0f ms, margin %.2f mm\n", 1e3 * rs.build_seconds, 1e3 * rs.margin);

    float *off = malloc(3 * b.skin_count * sizeof(float)), *poke = malloc(4 * MAX_POKES * sizeof(float));
    double *cover = malloc(b.skin_count * sizeof(double));
    assert_non_null(off);
    assert_non_null(cover);
    assert_non_null(poke);
    const pose_method methods[] = {POSE_LBS, POSE_DQS};
    const char *names[] = {"LBS", "DQS"};
    size_t sum_in_off = 0, sum_in_on = 0, sum_any_off = 0, sum_any_on = 0, sum_out_off = 0, sum_out_on = 0;
    double worst_excess = -INFINITY, slowest = 0.0;
    for (size_t m = 0; m < 2; m++)
        for (size_t c = 0; c < contact_pose_count(); c++) {
            assert_int_equal(contact_pose_set(b.rig, st, &contact_poses[c]), 0);
            assert_int_equal(pose_set_method(st, methods[m]), POSE_OK);
            set_response(st, 0);
            assert_int_equal(pose_apply(st), POSE_OK);
            memcpy(off, pose_tissue_positions(st, b.skin, NULL), 3 * b.skin_count * sizeof(float));
            pose_contact_counts k_off = {.size = sizeof k_off}, k_on = {.size = sizeof k_on};
            assert_int_equal(pose_contact_detect(det, st, &k_off), POSE_OK);
            const size_t in_before = count_flags(det, b.skin, rest_in),
                         covered_before = count_covered(&b, det, st, off, rest_in);
            size_t out_before = 0;
            for (int i = 0; i < b.bone_count; i++)
                out_before += count_flags(det, b.bones[i], rest_out[i]);
            /* How far each bone vertex newly out of the skin comes through
             * it: its distance to the skin without the response. */
            size_t pokes = 0;
            for (int i = 0; i < b.bone_count; i++) {
                const uint8_t *f = pose_contact_vertex_flags(det, b.bones[i], &n);
                const float *x = pose_tissue_positions(st, b.bones[i], NULL);
                for (size_t v = 0; v < n && pokes < MAX_POKES; v++)
                    if (f[v] && !rest_out[i][v]) {
                        memcpy(poke + 4 * pokes, x + 3 * v, 3 * sizeof(float));
                        poke[4 * pokes + 3] = (float)skin_distance(&b, off, poke + 4 * pokes);
                        pokes++;
                    }
            }
            memset(cover, 0, b.skin_count * sizeof(double));
            cover_depth(&b, off, poke, pokes, cover);
            /* With the response on, bones follow their joints rigidly: depths
             * are measured in those bones, from the skin without the push. */
            set_response(st, 1);
            assert_int_equal(pose_apply(st), POSE_OK);
            assert_int_equal(pose_get_contact_response_stats(st, &rs), POSE_OK);
            assert_int_equal(pose_contact_detect(det, st, &k_on), POSE_OK);
            const float *on = pose_tissue_positions(st, b.skin, NULL);
            double excess = -INFINITY, max_move = 0.0;
            size_t moved = 0;
            for (size_t v = 0; v < b.skin_count; v++) {
                if (memcmp(off + 3 * v, on + 3 * v, 3 * sizeof(float)) == 0)
                    continue;
                double e = 0.0;
                for (int d = 0; d < 3; d++)
                    e += ((double)on[3 * v + (size_t)d] - off[3 * v + (size_t)d]) *
                         ((double)on[3 * v + (size_t)d] - off[3 * v + (size_t)d]);
                const double move = sqrt(e),
                             depth = fmax(bone_depth(&b, st, off + 3 * v), cover[v]);
                excess = fmax(excess, move - depth);
                max_move = fmax(max_move, move);
                moved++;
            }
            const size_t in_after = count_flags(det, b.skin, rest_in),
                         covered_after = count_covered(&b, det, st, on, rest_in);
            size_t out_after = 0;
            for (int i = 0; i < b.bone_count; i++)
                out_after += count_flags(det, b.bones[i], rest_out[i]);
            printf("%s, %-18s: skin in a bone it covers %4zu -> %4zu (in any bone %4zu -> %4zu, %4zu -> %4zu with the rest's), bone out of skin "
                   "%4zu -> %4zu (%4zu -> %4zu with the rest's); %4zu moved, up to %5.2f mm, at most %+.3f mm past "
                   "the depth; pass %.2f ms\n",
                   names[m], contact_poses[c].label, covered_before, covered_after, in_before, in_after,
                   k_off.skin_in_bone, k_on.skin_in_bone,
                   out_before, out_after, k_off.bone_out_of_skin, k_on.bone_out_of_skin, moved, 1e3 * max_move,
                   1e3 * excess, 1e3 * rs.seconds);
            sum_in_off += covered_before;
            sum_in_on += covered_after;
            sum_any_off += in_before;
            sum_any_on += in_after;
            sum_out_off += out_before;
            sum_out_on += out_after;
            worst_excess = fmax(worst_excess, excess);
            slowest = fmax(slowest, rs.seconds);
        }
    const double fall_in = 1.0 - (double)sum_in_on / (double)sum_in_off;
    const double fall_out = 1.0 - (double)sum_out_on / (double)sum_out_off;
    printf("all poses: skin in a bone it covers %zu -> %zu (%.1f %% fewer; in any bone %zu -> %zu), bone out of "
           "skin %zu -> %zu (%.1f %% fewer); a move exceeds its depth by at most %.3f mm; slowest pass %.2f ms "
           "(wall, 2 threads)\n",
           sum_in_off, sum_in_on, 100.0 * fall_in, sum_any_off, sum_any_on, sum_out_off, sum_out_on, 100.0 * fall_out,
           1e3 * worst_excess, 1e3 * slowest);
    assert_true(sum_in_off > 0);
    assert_true(fall_in >= MIN_FALL_SKIN_IN_BONE);
    assert_true(fall_out >= MIN_FALL_BONE_OUT);
    assert_true(worst_excess <= MOVE_SLACK);

    /* Clusters split by part: the same skin for any thread count. */
    pose_state *one;
    so.threads = 1;
    assert_int_equal(pose_state_create_ex(b.rig, &so, &one), POSE_OK);
    for (pose_state *s2[2] = {st, one}, **x = s2; x < s2 + 2; x++) {
        set_response(*x, 1);
        assert_int_equal(contact_pose_set(b.rig, *x, &contact_poses[1]), 0);
        assert_int_equal(pose_set_method(*x, POSE_DQS), POSE_OK);
        assert_int_equal(pose_apply(*x), POSE_OK);
    }
    assert_memory_equal(pose_tissue_positions(st, b.skin, NULL), pose_tissue_positions(one, b.skin, NULL),
                        3 * b.skin_count * sizeof(float));
    pose_state_free(one);
    free(off);
    free(poke);
    free(cover);
    free(rest_in);
    for (int i = 0; i < b.bone_count; i++)
        free(rest_out[i]);
    pose_contact_free(det);
    pose_state_free(st);
    pose_rig_free(b.rig);
}

/* A joint pair swept from the neutral posture in SWEEP_STEP_DEG steps, DQS,
 * response off and on: per step, the largest change of a skin vertex's
 * response offset (on - off), and how many changes exceed JUMP. A
 * projection by the nearest surface point is not continuous where a point
 * crosses a bone's medial axis, so a bone moving through skin can throw a
 * vertex from one side of it to the other between frames; a small bone of
 * another part posed into the skin (fingers in a thigh) did so every few
 * frames before the push kept to the bones a skin covers. */
#define SWEEP_STEP_DEG 0.5f
#define JUMP 0.005f

static size_t sweep_jumps(const pose_rig *rig, int skin, size_t n, const char *j1, const char *j2, float to_deg,
                          float *worst)
{
    pose_state_options so = {.size = sizeof so, .threads = 2, .method = POSE_DQS};
    pose_state *on, *off;
    assert_int_equal(pose_state_create_ex(rig, &so, &on), POSE_OK);
    assert_int_equal(pose_state_create_ex(rig, &so, &off), POSE_OK);
    set_response(on, 1);
    float *last = calloc(3 * n, sizeof(float));
    assert_non_null(last);
    size_t jumps = 0;
    *worst = 0.0f;
    for (float deg = 0.0f; deg <= to_deg + 1e-3f; deg += SWEEP_STEP_DEG) {
        pose_state *both[2] = {on, off};
        for (int k = 0; k < 2; k++) {
            const float angles[3] = {deg, 0.0f, 0.0f};
            assert_int_equal(pose_reset(both[k]), POSE_OK);
            assert_true(pose_set_neutral(both[k]) >= 0);
            assert_true(pose_set_joint_clinical(both[k], pose_rig_find_joint(rig, j1), angles) >= 0);
            assert_true(pose_set_joint_clinical(both[k], pose_rig_find_joint(rig, j2), angles) >= 0);
            assert_int_equal(pose_apply(both[k]), POSE_OK);
        }
        const float *a = pose_tissue_positions(on, skin, NULL), *b = pose_tissue_positions(off, skin, NULL);
        for (size_t v = 0; v < n; v++) {
            float e2 = 0.0f;
            for (int d = 0; d < 3; d++) {
                const float r = a[3 * v + (size_t)d] - b[3 * v + (size_t)d], c = r - last[3 * v + (size_t)d];
                e2 += c * c;
                last[3 * v + (size_t)d] = r;
            }
            const float e = sqrtf(e2);
            if (deg > 0.0f) {
                jumps += e > JUMP;
                *worst = fmaxf(*worst, e);
            }
        }
    }
    free(last);
    pose_state_free(on);
    pose_state_free(off);
    return jumps;
}

static void continuous_in_a_sweep(void **unused)
{
    (void)unused;
    setvbuf(stdout, NULL, _IONBF, 0);
    pose_rig *rig;
    if (pose_rig_load(getenv("POSE_CONTACT_RIG"), &rig) != POSE_OK)
        fail_msg("%s", pose_last_error());
    int skin = -1;
    size_t n = 0;
    for (int t = 0; t < (int)pose_rig_tissue_count(rig) && skin < 0; t++) {
        pose_tissue_info ti;
        assert_int_equal(pose_rig_tissue_info(rig, t, &ti), POSE_OK);
        if (ti.kind == POSE_TISSUE_SKIN) {
            skin = t;
            n = ti.vertex_count;
        }
    }
    assert_true(skin >= 0);
    static const struct {
        const char *label, *joints[2];
        float deg;
        size_t most; /* jumps allowed (measured; the build before in brackets) */
    } sweeps[] = {
        {"elbows 0-145", {"elbow_r", "elbow_l"}, 145.0f, 50},        /* 23 (848) */
        {"shoulders' flexion 0-90", {"shoulder_r", "shoulder_l"}, 90.0f, 50}, /* 18 (1170) */
        {"hips 0-120", {"hip_r", "hip_l"}, 120.0f, 10},              /* 1 (10) */
        {"knees 0-140", {"knee_r", "knee_l"}, 140.0f, 160},          /* 128 (220) */
    };
    for (size_t s = 0; s < sizeof sweeps / sizeof sweeps[0] && s < contact_pose_count(); s++) {
        float worst;
        const size_t jumps = sweep_jumps(rig, skin, n, sweeps[s].joints[0], sweeps[s].joints[1], sweeps[s].deg, &worst);
        printf("%-24s in %.1f degree steps: %zu response offsets change by more than %.0f mm in a step, "
               "at most %.2f mm\n", sweeps[s].label, SWEEP_STEP_DEG, jumps, 1e3 * JUMP, 1e3 * worst);
        assert_true(jumps <= sweeps[s].most);
    }
    pose_rig_free(rig);
}

/* The push on 1 and 2 threads gives the same bits, LBS and DQS, at each
 * pose (what the TSan stage runs: contact_threads_only). */
static void threads_agree(void **unused)
{
    (void)unused;
    pose_rig *rig;
    if (pose_rig_load(getenv("POSE_CONTACT_RIG"), &rig) != POSE_OK)
        fail_msg("%s", pose_last_error());
    pose_state *st[2];
    for (int k = 0; k < 2; k++) {
        pose_state_options so = {.size = sizeof so, .threads = k + 1};
        assert_int_equal(pose_state_create_ex(rig, &so, &st[k]), POSE_OK);
        set_response(st[k], 1);
    }
    const pose_method methods[] = {POSE_LBS, POSE_DQS};
    for (size_t m = 0; m < 2; m++)
        for (size_t c = 0; c < contact_pose_count(); c++) {
            pose_contact_response_stats rs[2] = {{.size = sizeof rs[0]}, {.size = sizeof rs[1]}};
            for (int k = 0; k < 2; k++) {
                assert_int_equal(contact_pose_set(rig, st[k], &contact_poses[c]), 0);
                assert_int_equal(pose_set_method(st[k], methods[m]), POSE_OK);
                assert_int_equal(pose_apply(st[k]), POSE_OK);
                assert_int_equal(pose_get_contact_response_stats(st[k], &rs[k]), POSE_OK);
            }
            assert_true(rs[0].pushed > 0);
            assert_int_equal(rs[1].pushed, rs[0].pushed);
            for (int t = 0; t < (int)pose_rig_tissue_count(rig); t++) {
                size_t n;
                const float *a = pose_tissue_positions(st[0], t, &n), *b = pose_tissue_positions(st[1], t, NULL);
                assert_memory_equal(a, b, 3 * n * sizeof(float));
            }
        }
    pose_state_free(st[0]);
    pose_state_free(st[1]);
    pose_rig_free(rig);
}

int main(void)
{
    const struct CMUnitTest all[] = {
        cmocka_unit_test(invalid_settings),
        cmocka_unit_test(threads_agree),
        cmocka_unit_test(skin_out_of_bone),
        cmocka_unit_test(continuous_in_a_sweep),
    };
    const struct CMUnitTest threads[] = {
        cmocka_unit_test(threads_agree),
    };
    if (contact_threads_only())
        return cmocka_run_group_tests(threads, NULL, NULL);
    return cmocka_run_group_tests(all, NULL, NULL);
}
