/* SPDX-License-Identifier: Apache-2.0 */
/* pose/contact.h detection on the body baked from data/anatomy (coarse,
 * the tests' shared bake) at issue 13's poses: the BVH counts of skin
 * self-intersecting triangle pairs, skin vertices in bone and bone vertices
 * out of the skin equal brute-force counts with the same narrow phase
 * (runtime/rt_tri.h) and no hierarchy; 1 and 2 threads agree; invalid
 * arguments are refused. A rig path is taken from POSE_CONTACT_RIG. */
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

/* Bone vertices checked by brute force: every BONE_STRIDE-th (all of them
 * against 27 k skin triangles would take ~4e9 tests per pose). */
#define BONE_STRIDE 7

typedef struct mesh {
    size_t vertex_count, triangle_count;
    uint32_t *tris;  /* indices into all tissue vertices */
    uint32_t *verts; /* the mesh's vertices, the same way */
    int *tissue;     /* per triangle */
    size_t run[256][2]; /* per tissue: its triangles [run[t][0], run[t][1]) */
} mesh;

typedef struct body {
    pose_rig *rig;
    size_t total;          /* tissue vertices, all tissues */
    size_t *offset;        /* tissue_count + 1 */
    mesh skin, bone;
} body;

static void mesh_add(mesh *m, const pose_tissue_info *ti, size_t base, int t)
{
    assert_true(t < 256);
    m->run[t][0] = m->triangle_count;
    m->run[t][1] = m->triangle_count + ti->triangle_count;
    m->tris = realloc(m->tris, 3 * (m->triangle_count + ti->triangle_count) * sizeof(uint32_t));
    m->tissue = realloc(m->tissue, (m->triangle_count + ti->triangle_count) * sizeof(int));
    m->verts = realloc(m->verts, (m->vertex_count + ti->vertex_count) * sizeof(uint32_t));
    assert_non_null(m->tris);
    assert_non_null(m->tissue);
    assert_non_null(m->verts);
    for (size_t f = 0; f < ti->triangle_count; f++) {
        for (int k = 0; k < 3; k++)
            m->tris[3 * (m->triangle_count + f) + (size_t)k] = (uint32_t)(base + ti->triangles[3 * f + (size_t)k]);
        m->tissue[m->triangle_count + f] = t;
    }
    for (size_t v = 0; v < ti->vertex_count; v++)
        m->verts[m->vertex_count + v] = (uint32_t)(base + v);
    m->triangle_count += ti->triangle_count;
    m->vertex_count += ti->vertex_count;
}

static void body_load(body *b)
{
    const char *path = getenv("POSE_CONTACT_RIG");
    assert_non_null(path);
    memset(b, 0, sizeof *b);
    if (pose_rig_load(path, &b->rig) != POSE_OK)
        fail_msg("%s", pose_last_error());
    const size_t nt = pose_rig_tissue_count(b->rig);
    b->offset = calloc(nt + 1, sizeof(size_t));
    assert_non_null(b->offset);
    for (size_t t = 0; t < nt; t++) {
        pose_tissue_info ti;
        assert_int_equal(pose_rig_tissue_info(b->rig, (int)t, &ti), POSE_OK);
        b->offset[t + 1] = b->offset[t] + ti.vertex_count;
        if (ti.kind == POSE_TISSUE_SKIN)
            mesh_add(&b->skin, &ti, b->offset[t], (int)t);
        else if (ti.kind == POSE_TISSUE_BONE)
            mesh_add(&b->bone, &ti, b->offset[t], (int)t);
    }
    b->total = b->offset[nt];
    assert_true(b->skin.triangle_count > 0 && b->bone.triangle_count > 0);
}

static void mesh_free(mesh *m)
{
    free(m->tris);
    free(m->verts);
    free(m->tissue);
}

static void body_free(body *b)
{
    pose_rig_free(b->rig);
    free(b->offset);
    mesh_free(&b->skin);
    mesh_free(&b->bone);
}

/* All tissue vertices of the state in one array, as the library lays them out. */
static float *gather_positions(const body *b, const pose_state *st)
{
    float *x = malloc(3 * b->total * sizeof(float));
    assert_non_null(x);
    for (size_t t = 0; t + 1 < (size_t)pose_rig_tissue_count(b->rig) + 1; t++) {
        size_t n;
        const float *p = pose_tissue_positions(st, (int)t, &n);
        assert_non_null(p);
        memcpy(x + 3 * b->offset[t], p, 3 * n * sizeof(float));
    }
    return x;
}

typedef struct box {
    float lo[3], hi[3];
} box;

static box *triangle_boxes(const mesh *m, const float *x)
{
    box *bx = malloc(m->triangle_count * sizeof *bx);
    assert_non_null(bx);
    for (size_t f = 0; f < m->triangle_count; f++)
        for (int d = 0; d < 3; d++) {
            const float a = x[3 * (size_t)m->tris[3 * f] + (size_t)d], c = x[3 * (size_t)m->tris[3 * f + 1] + (size_t)d],
                        e = x[3 * (size_t)m->tris[3 * f + 2] + (size_t)d];
            bx[f].lo[d] = fminf(fminf(a, c), e);
            bx[f].hi[d] = fmaxf(fmaxf(a, c), e);
        }
    return bx;
}

/* Every pair of skin triangles: a box test, then the library's predicate. */
static size_t brute_pairs(const mesh *m, const float *x)
{
    box *bx = triangle_boxes(m, x);
    size_t hits = 0;
    for (size_t i = 0; i < m->triangle_count; i++)
        for (size_t j = i + 1; j < m->triangle_count; j++) {
            if (bx[i].lo[0] > bx[j].hi[0] || bx[j].lo[0] > bx[i].hi[0] || bx[i].lo[1] > bx[j].hi[1] ||
                bx[j].lo[1] > bx[i].hi[1] || bx[i].lo[2] > bx[j].hi[2] || bx[j].lo[2] > bx[i].hi[2])
                continue;
            const uint32_t *s = m->tris + 3 * i, *t = m->tris + 3 * j;
            if (pose__tris_share_vertex(s, t))
                continue;
            const float *a[3] = {x + 3 * (size_t)s[0], x + 3 * (size_t)s[1], x + 3 * (size_t)s[2]};
            const float *c[3] = {x + 3 * (size_t)t[0], x + 3 * (size_t)t[1], x + 3 * (size_t)t[2]};
            hits += (size_t)pose__tri_tri_intersect(a, c);
        }
    free(bx);
    return hits;
}

static const box *sweep_boxes; /* the boxes sorted by sweep_order */

static int by_lo_x(const void *a, const void *b)
{
    const float x = sweep_boxes[*(const uint32_t *)a].lo[0], y = sweep_boxes[*(const uint32_t *)b].lo[0];
    return x < y ? -1 : x > y;
}

/* Pairs of bone triangles of two different tissues that intersect: a sweep
 * along x over the triangles' boxes (no hierarchy), the library's
 * predicate. */
static size_t sweep_bone_pairs(const mesh *m, const float *x)
{
    box *bx = triangle_boxes(m, x);
    uint32_t *order = malloc(m->triangle_count * sizeof *order);
    assert_non_null(order);
    for (size_t f = 0; f < m->triangle_count; f++)
        order[f] = (uint32_t)f;
    sweep_boxes = bx;
    qsort(order, m->triangle_count, sizeof *order, by_lo_x);
    size_t hits = 0;
    for (size_t i = 0; i < m->triangle_count; i++) {
        const box *a = &bx[order[i]];
        for (size_t j = i + 1; j < m->triangle_count && bx[order[j]].lo[0] <= a->hi[0]; j++) {
            const box *c = &bx[order[j]];
            if (m->tissue[order[i]] == m->tissue[order[j]] || a->lo[1] > c->hi[1] || c->lo[1] > a->hi[1] ||
                a->lo[2] > c->hi[2] || c->lo[2] > a->hi[2])
                continue;
            const uint32_t *s = m->tris + 3 * (size_t)order[i], *t = m->tris + 3 * (size_t)order[j];
            const float *p[3] = {x + 3 * (size_t)s[0], x + 3 * (size_t)s[1], x + 3 * (size_t)s[2]};
            const float *q[3] = {x + 3 * (size_t)t[0], x + 3 * (size_t)t[1], x + 3 * (size_t)t[2]};
            hits += (size_t)pose__tri_tri_intersect(p, q);
        }
    }
    free(order);
    free(bx);
    return hits;
}

/* Box of each tissue's triangles (they are contiguous in m). */
static box *tissue_boxes(const mesh *m, const box *bx, size_t tissues)
{
    box *tb = malloc(256 * sizeof *tb);
    assert_true(tissues <= 256);
    assert_non_null(tb);
    for (size_t t = 0; t < 256; t++)
        for (int d = 0; d < 3; d++) {
            tb[t].lo[d] = INFINITY;
            tb[t].hi[d] = -INFINITY;
        }
    for (size_t f = 0; f < m->triangle_count; f++)
        for (int d = 0; d < 3; d++) {
            box *t = &tb[m->tissue[f]];
            t->lo[d] = fminf(t->lo[d], bx[f].lo[d]);
            t->hi[d] = fmaxf(t->hi[d], bx[f].hi[d]);
        }
    return tb;
}

/* The ray from p along +x misses box b. */
static int misses(const box *b, const float *p)
{
    return p[1] < b->lo[1] || p[1] > b->hi[1] || p[2] < b->lo[2] || p[2] > b->hi[2] || p[0] > b->hi[0];
}

/* Winding number at p over every triangle of m: each tissue whose box the
 * ray meets, and in it each triangle whose box the ray meets. */
static int brute_winding(const mesh *m, const box *bx, const box *tb, const float *x, const float *p)
{
    int w = 0;
    for (size_t t = 0; t < 256; t++) {
        if (m->run[t][0] == m->run[t][1] || misses(&tb[t], p))
            continue;
        for (size_t f = m->run[t][0]; f < m->run[t][1]; f++) {
            if (misses(&bx[f], p))
                continue;
            const uint32_t *v = m->tris + 3 * f;
            w += pose__ray_x_crossing(p, x + 3 * (size_t)v[0], x + 3 * (size_t)v[1], x + 3 * (size_t)v[2]);
        }
    }
    return w;
}

/* Winding number at p by the ray along -x, over every triangle (the
 * library's second ray for skin in bone). */
static int brute_winding_minus_x(const mesh *m, const float *x, const float *p)
{
    static const float d[3] = {-1.0f, 0.0f, 0.0f};
    int w = 0;
    for (size_t f = 0; f < m->triangle_count; f++) {
        const uint32_t *v = m->tris + 3 * f;
        const float *a = x + 3 * (size_t)v[0], *b = x + 3 * (size_t)v[1], *c = x + 3 * (size_t)v[2];
        if (a[0] > p[0] && b[0] > p[0] && c[0] > p[0])
            continue; /* wholly ahead of the +x side: the ray goes the other way */
        w += pose__ray_crossing(p, d, a, b, c);
    }
    return w;
}

static void set_pose(const body *b, pose_state *st, const contact_pose *p)
{
    assert_int_equal(contact_pose_set(b->rig, st, p), 0);
    assert_int_equal(pose_apply(st), POSE_OK);
}

static const uint8_t *flags_of(const pose_contact *c, const body *b, uint32_t v)
{
    size_t t = 0;
    while (b->offset[t + 1] <= v)
        t++;
    size_t n;
    const uint8_t *f = pose_contact_vertex_flags(c, (int)t, &n);
    assert_non_null(f);
    return f + (v - b->offset[t]);
}

static void invalid_arguments(void **unused)
{
    (void)unused;
    body b;
    body_load(&b);
    pose_contact *c = (pose_contact *)&b; /* must be cleared */
    assert_int_equal(pose_contact_create(NULL, NULL, &c), POSE_ERR_INVALID_ARGUMENT);
    assert_null(c);
    assert_int_equal(pose_contact_create(b.rig, NULL, NULL), POSE_ERR_INVALID_ARGUMENT);
    pose_contact_options o = {.size = 3};
    assert_int_equal(pose_contact_create(b.rig, &o, &c), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(pose_last_error(), "options.size"));
    o = (pose_contact_options){.size = sizeof o, .threads = -1};
    assert_int_equal(pose_contact_create(b.rig, &o, &c), POSE_ERR_INVALID_ARGUMENT);
    o = (pose_contact_options){.size = sizeof o, .threads = 1};
    assert_int_equal(pose_contact_create(b.rig, &o, &c), POSE_OK);
    pose_state *st;
    assert_int_equal(pose_state_create(b.rig, &st), POSE_OK);
    pose_contact_counts n = {.size = 1};
    assert_int_equal(pose_contact_detect(c, st, &n), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_contact_detect(NULL, st, NULL), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pose_contact_detect(c, NULL, NULL), POSE_ERR_INVALID_ARGUMENT);
    /* A caller built before bone_pairs was added: counted, bone_pairs untouched. */
    pose_contact_counts first = {.size = offsetof(pose_contact_counts, bone_pairs), .bone_pairs = 12345};
    assert_int_equal(pose_apply(st), POSE_OK);
    assert_int_equal(pose_contact_detect(c, st, &first), POSE_OK);
    assert_true(first.skin_pairs > 0);
    assert_int_equal(first.bone_pairs, 12345);
    assert_null(pose_contact_vertex_flags(c, -1, NULL));
    assert_null(pose_contact_vertex_flags(c, (int)pose_rig_tissue_count(b.rig), NULL));
    assert_null(pose_contact_vertex_flags(NULL, 0, NULL));
    pose_contact_free(c);
    pose_contact_free(NULL);
    pose_state_free(st);
    body_free(&b);
}

static void counts_match_brute_force(void **unused)
{
    (void)unused;
    setvbuf(stdout, NULL, _IONBF, 0);
    body b;
    body_load(&b);
    pose_contact *one, *two;
    pose_contact_options o1 = {.size = sizeof o1, .threads = 1}, o2 = {.size = sizeof o2, .threads = 2};
    assert_int_equal(pose_contact_create(b.rig, &o1, &one), POSE_OK);
    assert_int_equal(pose_contact_create(b.rig, &o2, &two), POSE_OK);
    pose_state *st;
    assert_int_equal(pose_state_create(b.rig, &st), POSE_OK);
    printf("skin: %zu vertices, %zu triangles; bones: %zu vertices, %zu triangles\n",
           b.skin.vertex_count, b.skin.triangle_count, b.bone.vertex_count, b.bone.triangle_count);

    /* Rest (the T-pose the meshes came in) first: the source skin already
     * crosses itself at the mouth (~660 pairs) and the skull and jaw come
     * out of it (data/anatomy/README.md); then the issue's poses. */
    size_t pairs_rest = 0, pairs_posed = 0, bone_pairs_rest = 0, bone_pairs_posed = 0;
    const int threads_only = contact_threads_only(); /* 1 thread against 2, no brute force */
    for (size_t c = 0; c <= contact_pose_count(); c++) {
        const char *label = c ? contact_poses[c - 1].label : "rest (T-pose)";
        if (c)
            set_pose(&b, st, &contact_poses[c - 1]);
        else
            assert_int_equal(pose_apply(st), POSE_OK);
        pose_contact_counts n1 = {.size = sizeof n1}, n2 = {.size = sizeof n2};
        assert_int_equal(pose_contact_detect(one, st, &n1), POSE_OK);
        assert_int_equal(pose_contact_detect(two, st, &n2), POSE_OK);
        assert_int_equal(n2.skin_pairs, n1.skin_pairs);
        assert_int_equal(n2.bone_pairs, n1.bone_pairs);
        assert_int_equal(n2.skin_in_bone, n1.skin_in_bone);
        assert_int_equal(n2.bone_out_of_skin, n1.bone_out_of_skin);
        for (size_t t = 0; t < pose_rig_tissue_count(b.rig); t++) {
            size_t nv;
            const uint8_t *f1 = pose_contact_vertex_flags(one, (int)t, &nv), *f2 = pose_contact_vertex_flags(two, (int)t, NULL);
            assert_memory_equal(f1, f2, nv);
        }
        assert_true(n1.skin_pairs > 0 && n1.bone_pairs > 0);
        if (threads_only)
            continue;
        float *x = gather_positions(&b, st);
        const size_t pairs = brute_pairs(&b.skin, x), bone_pairs = sweep_bone_pairs(&b.bone, x);
        box *bone_box = triangle_boxes(&b.bone, x), *skin_box = triangle_boxes(&b.skin, x);
        const size_t nt = pose_rig_tissue_count(b.rig);
        box *bone_tb = tissue_boxes(&b.bone, bone_box, nt), *skin_tb = tissue_boxes(&b.skin, skin_box, nt);
        size_t in_bone = 0, out_checked = 0, out_brute = 0;
        for (size_t i = 0; i < b.skin.vertex_count; i++) {
            const uint32_t v = b.skin.verts[i];
            const int in = brute_winding(&b.bone, bone_box, bone_tb, x, x + 3 * (size_t)v) > 0 &&
                           brute_winding_minus_x(&b.bone, x, x + 3 * (size_t)v) > 0;
            in_bone += (size_t)in;
            assert_int_equal(*flags_of(one, &b, v), in ? POSE_CONTACT_SKIN_IN_BONE : 0);
        }
        for (size_t i = 0; i < b.bone.vertex_count; i += BONE_STRIDE) {
            const uint32_t v = b.bone.verts[i];
            const int out = brute_winding(&b.skin, skin_box, skin_tb, x, x + 3 * (size_t)v) <= 0;
            out_brute += (size_t)out;
            out_checked += (size_t)((*flags_of(one, &b, v) & POSE_CONTACT_BONE_OUT_OF_SKIN) != 0);
            assert_int_equal(*flags_of(one, &b, v), out ? POSE_CONTACT_BONE_OUT_OF_SKIN : 0);
        }
        printf("%-18s: %5zu skin pairs (brute force %zu), %4zu skin vertices in bone (%zu), "
               "%5zu bone vertices out of skin (every %dth: %zu, brute force %zu); %.2f ms on 1 thread, "
               "%.2f on 2\n", label, n1.skin_pairs, pairs, n1.skin_in_bone, in_bone,
               n1.bone_out_of_skin, BONE_STRIDE, out_checked, out_brute, 1e3 * n1.seconds, 1e3 * n2.seconds);
        printf("%-18s  %5zu pairs of two bones (sweep %zu)\n", "", n1.bone_pairs, bone_pairs);
        assert_int_equal(n1.skin_pairs, pairs);
        assert_int_equal(n1.bone_pairs, bone_pairs);
        assert_int_equal(n1.skin_in_bone, in_bone);
        if (c) {
            pairs_posed = n1.skin_pairs > pairs_posed ? n1.skin_pairs : pairs_posed;
            bone_pairs_posed = n1.bone_pairs > bone_pairs_posed ? n1.bone_pairs : bone_pairs_posed;
        } else {
            pairs_rest = n1.skin_pairs;
            bone_pairs_rest = n1.bone_pairs;
        }
        free(bone_box);
        free(skin_box);
        free(bone_tb);
        free(skin_tb);
        free(x);
    }
    /* The issue's poses bring skin through skin: limbs against each other
     * (the hands into the thighs, the arms into the trunk, with both knees
     * or both elbows flexed the feet through each other and the hands
     * through each other) more than folds at the joints. The bones touch at
     * rest (jaw and skull, vertebrae, carpals); with both knees at 140 the
     * feet and shins cross, with both elbows at 145 the fingers cross and
     * the forearms enter the ribcage. */
    if (!threads_only) {
        assert_true(pairs_rest > 0 && pairs_posed > pairs_rest);
        assert_true(bone_pairs_rest > 0 && bone_pairs_posed > bone_pairs_rest);
    }
    pose_contact_free(one);
    pose_contact_free(two);
    pose_state_free(st);
    body_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(invalid_arguments),
        cmocka_unit_test(counts_match_brute_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
