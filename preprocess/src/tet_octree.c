/* SPDX-License-Identifier: Apache-2.0
 *
 * The graded variant of the built-in mesher: a balanced octree over the
 * cell grid, tetrahedralized by fans from cell and face centres.
 *
 * Leaves: every cell next to a different label (26-neighbourhood, outside
 * included) is a one-cell leaf; elsewhere a leaf is the largest aligned
 * block of up to 2^grading cells that is uniform in label. Leaves are then
 * split until face-, edge- and vertex-neighbours differ by at most one level
 * (strong 2:1 balance), so the size grows by at most 2x per layer away from
 * skin and bone boundaries.
 *
 * Tets: a leaf with no finer neighbour and no edge midpoint takes the six
 * Kuhn tets of its cube (as the uniform lattice does, so regular regions
 * cost one vertex per leaf); any other leaf is coned from its centre to a
 * triangulation of its six faces. A face whose neighbour is finer is split into its four quarter
 * squares; any other face is one square, cut along its (min, min)-(max,
 * max) diagonal, or fanned from its centre when an edge midpoint is a vertex
 * (a finer leaf touches that edge). Both leaves that share a face derive the
 * same triangulation from the same vertices, so the mesh conforms; balance
 * rules out the cases this does not cover (a quarter square with midpoints).
 * Coordinates are integers in half-cell units, so orientation is exact.
 */
#include "tet_build.h"
#include "voxelize.h"

#include <stdlib.h>
#include <string.h>

#define NO_LEVEL 255

typedef struct vhash {
    uint64_t *key;
    uint32_t *val;
    size_t cap, count;
} vhash;

static uint64_t vkey(int64_t x, int64_t y, int64_t z)
{
    return ((uint64_t)x << 42) | ((uint64_t)y << 21) | (uint64_t)z;
}

static size_t vslot(uint64_t k, size_t cap)
{
    k ^= k >> 31;
    k *= 0x9e3779b97f4a7c15ull;
    k ^= k >> 29;
    return (size_t)k & (cap - 1);
}

static int vhash_grow(vhash *h)
{
    size_t cap = h->cap ? 2 * h->cap : 1 << 16;
    uint64_t *key = malloc(cap * sizeof *key);
    uint32_t *val = malloc(cap * sizeof *val);
    if (!key || !val) {
        free(key);
        free(val);
        return -1;
    }
    memset(key, 0xff, cap * sizeof *key);
    for (size_t i = 0; i < h->cap; i++) {
        if (h->key[i] == UINT64_MAX)
            continue;
        size_t s = vslot(h->key[i], cap);
        while (key[s] != UINT64_MAX)
            s = (s + 1) & (cap - 1);
        key[s] = h->key[i];
        val[s] = h->val[i];
    }
    free(h->key);
    free(h->val);
    h->key = key;
    h->val = val;
    h->cap = cap;
    return 0;
}

/* Id of vertex k, created as *next when `create`; UINT32_MAX when absent (or
 * no memory). */
static uint32_t vhash_get(vhash *h, uint64_t k, int create, uint32_t *next)
{
    if (create && 2 * (h->count + 1) > h->cap && vhash_grow(h) != 0)
        return UINT32_MAX;
    if (!h->cap)
        return UINT32_MAX;
    size_t s = vslot(k, h->cap);
    while (h->key[s] != UINT64_MAX) {
        if (h->key[s] == k)
            return h->val[s];
        s = (s + 1) & (h->cap - 1);
    }
    if (!create)
        return UINT32_MAX;
    h->key[s] = k;
    h->val[s] = (*next)++;
    h->count++;
    return h->val[s];
}

typedef struct builder {
    const pp_cells *L;
    uint8_t *lvl;
    /* Vertices at whole-cell coordinates (leaf corners, edge midpoints, centres
     * of leaves two or more cells wide) live in a dense grid; the odd ones
     * (centres of one-cell leaves and of their faces) in a hash. */
    uint32_t *dense;
    size_t dn[3];
    vhash vh;
    uint32_t nv;
    uint32_t *tets;
    uint16_t *labels;
    size_t tet_count, tet_cap;
    int oom;
} builder;

static uint8_t level_at(const builder *b, int x, int y, int z)
{
    const pp_cells *L = b->L;
    if (x < 0 || y < 0 || z < 0 || x >= L->m[0] || y >= L->m[1] || z >= L->m[2])
        return NO_LEVEL;
    return b->lvl[(size_t)x + (size_t)L->m[0] * ((size_t)y + (size_t)L->m[1] * z)];
}

/* Initial levels: 0 along label boundaries, else the largest uniform block. */
static int initial_levels(builder *b, int grading)
{
    const pp_cells *L = b->L;
    size_t n = (size_t)L->m[0] * L->m[1] * L->m[2];
    /* blk: label of a uniform, boundary-free block; 0 otherwise (0 = outside
     * is never a valid block label) */
    uint16_t *blk = malloc(n * sizeof *blk);
    if (!blk)
        return -1;
    for (int z = 0; z < L->m[2]; z++)
        for (int y = 0; y < L->m[1]; y++)
            for (int x = 0; x < L->m[0]; x++) {
                size_t i = (size_t)x + (size_t)L->m[0] * ((size_t)y + (size_t)L->m[1] * z);
                uint16_t l = L->cell[i];
                b->lvl[i] = l == PP_VOXEL_OUTSIDE ? NO_LEVEL : 0;
                int inner = l != PP_VOXEL_OUTSIDE;
                for (int dz = -1; dz <= 1 && inner; dz++)
                    for (int dy = -1; dy <= 1 && inner; dy++)
                        for (int dx = -1; dx <= 1 && inner; dx++)
                            inner = pp_cells_at(L, x + dx, y + dy, z + dz) == l;
                blk[i] = inner ? l : 0;
            }
    /* Level k block (bx, by, bz) is valid when its 8 level-(k-1) children
     * are valid and equal; blk is updated in place at the block's first cell. */
    for (int k = 1; k <= grading; k++) {
        int s = 1 << k, h = s >> 1;
        for (int z = 0; z + s <= L->m[2]; z += s)
            for (int y = 0; y + s <= L->m[1]; y += s)
                for (int x = 0; x + s <= L->m[0]; x += s) {
                    size_t i0 = (size_t)x + (size_t)L->m[0] * ((size_t)y + (size_t)L->m[1] * z);
                    uint16_t l = blk[i0];
                    for (int c = 1; c < 8 && l; c++) {
                        int cx = x + (c & 1) * h, cy = y + (c >> 1 & 1) * h, cz = z + (c >> 2) * h;
                        if (blk[(size_t)cx + (size_t)L->m[0] * ((size_t)cy + (size_t)L->m[1] * cz)] != l)
                            l = 0;
                    }
                    if (!l) {
                        blk[i0] = 0; /* invalid at this level and above */
                        continue;
                    }
                    for (int dz = 0; dz < s; dz++)
                        for (int dy = 0; dy < s; dy++)
                            for (int dx = 0; dx < s; dx++)
                                b->lvl[(size_t)(x + dx) + (size_t)L->m[0] * ((size_t)(y + dy) +
                                                                          (size_t)L->m[1] * (z + dz))] =
                                    (uint8_t)k;
                }
        /* blocks that failed at level k must not be read as valid at k + 1:
         * only first cells of level-k blocks are read next, and those were
         * cleared above when invalid; children that are not block-aligned at
         * level k are never read again. */
    }
    free(blk);
    return 0;
}

static void split_leaf(builder *b, int nx, int ny, int nz, uint8_t ln)
{
    const pp_cells *L = b->L;
    int s = 1 << ln;
    int bx = nx & ~(s - 1), by = ny & ~(s - 1), bz = nz & ~(s - 1);
    for (int dz = 0; dz < s; dz++)
        for (int dy = 0; dy < s; dy++)
            for (int dx = 0; dx < s; dx++)
                b->lvl[(size_t)(bx + dx) +
                       (size_t)L->m[0] * ((size_t)(by + dy) + (size_t)L->m[1] * (bz + dz))] =
                    (uint8_t)(ln - 1);
}

/* Split leaves until neighbours (26-connected) differ by at most one level.
 * Each leaf scans the one-cell shell around its block; sweeps repeat until
 * nothing changes (levels only go down, so this ends). */
static void balance(builder *b)
{
    const pp_cells *L = b->L;
    int changed = 1;
    while (changed) {
        changed = 0;
        for (int z = 0; z < L->m[2]; z++)
            for (int y = 0; y < L->m[1]; y++)
                for (int x = 0; x < L->m[0]; x++) {
                    uint8_t l = level_at(b, x, y, z);
                    int s = 1 << (l == NO_LEVEL ? 0 : l);
                    if (l == NO_LEVEL || (x | y | z) & (s - 1))
                        continue;
                    for (int dz = -1; dz <= s; dz++)
                        for (int dy = -1; dy <= s; dy++) {
                            int inner = dz >= 0 && dz < s && dy >= 0 && dy < s;
                            for (int dx = -1; dx <= s; dx += inner ? s + 1 : 1) {
                                uint8_t ln = level_at(b, x + dx, y + dy, z + dz);
                                if (ln == NO_LEVEL || ln <= l + 1)
                                    continue;
                                split_leaf(b, x + dx, y + dy, z + dz, ln);
                                changed = 1;
                            }
                        }
                }
    }
}

static void add_tet(builder *b, const int64_t p[4][3], const uint32_t v[4], uint16_t label)
{
    if (b->tet_count == b->tet_cap) {
        size_t cap = b->tet_cap ? 2 * b->tet_cap : 1 << 16;
        uint32_t *t = realloc(b->tets, 4 * cap * sizeof *t);
        if (!t) {
            b->oom = 1;
            return;
        }
        b->tets = t;
        uint16_t *l = realloc(b->labels, cap * sizeof *l);
        if (!l) {
            b->oom = 1;
            return;
        }
        b->labels = l;
        b->tet_cap = cap;
    }
    int64_t a[3], c[3], d[3];
    for (int k = 0; k < 3; k++) {
        a[k] = p[1][k] - p[0][k];
        c[k] = p[2][k] - p[0][k];
        d[k] = p[3][k] - p[0][k];
    }
    int64_t det = a[0] * (c[1] * d[2] - c[2] * d[1]) - a[1] * (c[0] * d[2] - c[2] * d[0]) +
                  a[2] * (c[0] * d[1] - c[1] * d[0]);
    uint32_t *t = b->tets + 4 * b->tet_count;
    t[0] = v[0];
    t[1] = det > 0 ? v[1] : v[2];
    t[2] = det > 0 ? v[2] : v[1];
    t[3] = v[3];
    b->labels[b->tet_count++] = label;
}

/* Point on face: plane axis a at coordinate pa, in-plane (u, w) = (pu, pw). */
static void face_point(int a, int64_t pa, int64_t pu, int64_t pw, int64_t out[3])
{
    out[a] = pa;
    out[(a + 1) % 3] = pu;
    out[(a + 2) % 3] = pw;
}

static uint32_t vid_of(builder *b, const int64_t p[3], int create)
{
    if (!((p[0] | p[1] | p[2]) & 1)) {
        uint32_t *d = &b->dense[(size_t)(p[0] / 2) +
                                b->dn[0] * ((size_t)(p[1] / 2) + b->dn[1] * (size_t)(p[2] / 2))];
        if (*d == UINT32_MAX && create)
            *d = b->nv++;
        return *d;
    }
    uint32_t id = vhash_get(&b->vh, vkey(p[0], p[1], p[2]), create, &b->nv);
    if (create && id == UINT32_MAX)
        b->oom = 1;
    return id;
}

/* The tet from triangle tri to the leaf centre. */
static void cone(builder *b, const int64_t ctr[3], uint32_t cid, const int64_t tri[3][3],
                 uint16_t label)
{
    int64_t p[4][3];
    uint32_t v[4];
    for (int k = 0; k < 3; k++) {
        memcpy(p[k], tri[k], sizeof p[k]);
        v[k] = vid_of(b, tri[k], 1);
    }
    memcpy(p[3], ctr, sizeof p[3]);
    v[3] = cid;
    add_tet(b, p, v, label);
}

/* Remember the vertices of an outer face with its axis and side (for the
 * snapping directions built at the end). */
static void record_outer(builder *b, uint32_t **of, size_t *count, size_t *cap,
                         const int64_t ring[][3], int nr, int a, int side)
{
    if (*count + (size_t)nr > *cap) {
        size_t c = *cap ? 2 * *cap : 1 << 14;
        while (c < *count + (size_t)nr)
            c *= 2;
        uint32_t *t = realloc(*of, 2 * c * sizeof *t);
        if (!t) {
            b->oom = 1;
            return;
        }
        *of = t;
        *cap = c;
    }
    for (int k = 0; k < nr; k++) {
        (*of)[2 * *count] = vid_of(b, ring[k], 1);
        (*of)[2 * *count + 1] = (uint32_t)(2 * a + side);
        (*count)++;
    }
}

/* A leaf none of whose neighbours is finer and none of whose edges has a
 * midpoint vertex: its faces are plain squares cut along the (min, min)-
 * (max, max) diagonal, exactly the faces of a Kuhn cube, so it takes the six
 * Kuhn tets and no centre vertex. */
static int plain_leaf(builder *b, int x, int y, int z, uint8_t l)
{
    int s = 1 << l;
    for (int f = 0; f < 6; f++) {
        int a = f / 2, side = f & 1;
        int nb[3] = {x, y, z};
        nb[a] = side ? nb[a] + s : nb[a] - 1;
        uint8_t ln = level_at(b, nb[0], nb[1], nb[2]);
        if (ln != NO_LEVEL && ln < l)
            return 0;
    }
    /* the 12 edge midpoints */
    int64_t S = 2 * (int64_t)s, c0[3] = {2 * (int64_t)x, 2 * (int64_t)y, 2 * (int64_t)z};
    for (int a = 0; a < 3; a++)
        for (int e = 0; e < 4; e++) {
            int64_t p[3];
            p[a] = c0[a] + S / 2;
            p[(a + 1) % 3] = c0[(a + 1) % 3] + (e & 1) * S;
            p[(a + 2) % 3] = c0[(a + 2) % 3] + (e >> 1) * S;
            if (vid_of(b, p, 0) != UINT32_MAX)
                return 0;
        }
    return 1;
}

static void kuhn_leaf(builder *b, const int64_t c0[3], int64_t S, uint16_t label)
{
    static const int kuhn[6][4] = {{0, 1, 3, 7}, {0, 4, 5, 7}, {0, 2, 6, 7},
                                   {0, 3, 2, 7}, {0, 5, 1, 7}, {0, 6, 4, 7}};
    int64_t p[8][3];
    uint32_t v[8];
    for (int k = 0; k < 8; k++) {
        p[k][0] = c0[0] + (k & 1) * S;
        p[k][1] = c0[1] + (k >> 1 & 1) * S;
        p[k][2] = c0[2] + (k >> 2) * S;
        v[k] = vid_of(b, p[k], 1);
    }
    for (int t = 0; t < 6; t++) {
        int64_t q[4][3];
        uint32_t w[4];
        for (int k = 0; k < 4; k++) {
            memcpy(q[k], p[kuhn[t][k]], sizeof q[k]);
            w[k] = v[kuhn[t][k]];
        }
        add_tet(b, q, w, label);
    }
}

pose_status pp_tet_octree_build(const pp_cells *L, int grading, pp_tetmesh *out, int8_t **dir_out)
{
    memset(out, 0, sizeof *out);
    *dir_out = NULL;
    builder b = {0};
    b.L = L;
    size_t n = (size_t)L->m[0] * L->m[1] * L->m[2];
    if ((size_t)L->m[0] * 2 >= (1u << 21) || (size_t)L->m[1] * 2 >= (1u << 21) ||
        (size_t)L->m[2] * 2 >= (1u << 21))
        return POSE_ERR_INVALID_ARGUMENT;
    for (int k = 0; k < 3; k++)
        b.dn[k] = (size_t)L->m[k] + 1;
    b.lvl = malloc(n ? n : 1);
    b.dense = malloc(b.dn[0] * b.dn[1] * b.dn[2] * sizeof *b.dense);
    if (!b.lvl || !b.dense || initial_levels(&b, grading) != 0) {
        free(b.lvl);
        free(b.dense);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    memset(b.dense, 0xff, b.dn[0] * b.dn[1] * b.dn[2] * sizeof *b.dense);
    balance(&b);

    /* Phase A: leaf corners, so that edge midpoints can be looked up. */
    for (int z = 0; z < L->m[2] && !b.oom; z++)
        for (int y = 0; y < L->m[1]; y++)
            for (int x = 0; x < L->m[0]; x++) {
                uint8_t l = level_at(&b, x, y, z);
                if (l == NO_LEVEL)
                    continue;
                int s = 1 << l;
                if ((x | y | z) & (s - 1))
                    continue;
                for (int k = 0; k < 8; k++) {
                    int64_t p[3] = {2 * (int64_t)(x + (k & 1) * s), 2 * (int64_t)(y + (k >> 1 & 1) * s),
                                    2 * (int64_t)(z + (k >> 2) * s)};
                    vid_of(&b, p, 1);
                }
            }
    /* Outer faces, recorded as (vertex, axis, sign) to build dir at the end. */
    size_t of_count = 0, of_cap = 0;
    uint32_t *of = NULL;
    /* Phase B: faces and cones. */
    for (int z = 0; z < L->m[2] && !b.oom; z++)
        for (int y = 0; y < L->m[1]; y++)
            for (int x = 0; x < L->m[0]; x++) {
                uint8_t l = level_at(&b, x, y, z);
                if (l == NO_LEVEL)
                    continue;
                int s = 1 << l;
                if ((x | y | z) & (s - 1))
                    continue;
                uint16_t label = (uint16_t)(pp_cells_at(L, x, y, z) - 1);
                int64_t S = 2 * (int64_t)s, cell[3] = {x, y, z};
                int64_t c0[3] = {2 * (int64_t)x, 2 * (int64_t)y, 2 * (int64_t)z};
                int64_t ctr[3] = {c0[0] + S / 2, c0[1] + S / 2, c0[2] + S / 2};
                if (plain_leaf(&b, x, y, z, l)) {
                    kuhn_leaf(&b, c0, S, label);
                    for (int f = 0; f < 6; f++) {
                        int a = f / 2, side = f & 1;
                        int nb[3] = {x, y, z};
                        nb[a] = side ? nb[a] + s : nb[a] - 1;
                        if (level_at(&b, nb[0], nb[1], nb[2]) != NO_LEVEL)
                            continue;
                        int64_t ring[4][3];
                        int u = (a + 1) % 3, w = (a + 2) % 3;
                        static const int cu[4] = {0, 1, 1, 0}, cw[4] = {0, 0, 1, 1};
                        for (int k = 0; k < 4; k++)
                            face_point(a, c0[a] + side * S, c0[u] + cu[k] * S, c0[w] + cw[k] * S, ring[k]);
                        record_outer(&b, &of, &of_count, &of_cap, ring, 4, a, side);
                    }
                    continue;
                }
                uint32_t cid = vid_of(&b, ctr, 1);
                for (int f = 0; f < 6; f++) {
                    int a = f / 2, side = f & 1, u = (a + 1) % 3, w = (a + 2) % 3;
                    int nb[3] = {(int)cell[0], (int)cell[1], (int)cell[2]};
                    nb[a] = side ? (int)cell[a] + s : (int)cell[a] - 1;
                    uint8_t ln = level_at(&b, nb[0], nb[1], nb[2]);
                    int64_t pa = c0[a] + side * S, u0 = c0[u], w0 = c0[w];
                    int64_t tri[3][3];
                    int outer = ln == NO_LEVEL;
                    if (!outer && ln < l) {
                        /* neighbour finer: four quarter squares */
                        int64_t h = S / 2;
                        for (int q = 0; q < 4; q++) {
                            int64_t qu = u0 + (q & 1) * h, qw = w0 + (q >> 1) * h;
                            face_point(a, pa, qu, qw, tri[0]);
                            face_point(a, pa, qu + h, qw, tri[1]);
                            face_point(a, pa, qu + h, qw + h, tri[2]);
                            cone(&b, ctr, cid, (const int64_t(*)[3])tri, label);
                            face_point(a, pa, qu + h, qw + h, tri[1]);
                            face_point(a, pa, qu, qw + h, tri[2]);
                            cone(&b, ctr, cid, (const int64_t(*)[3])tri, label);
                        }
                        continue;
                    }
                    /* one square: ring of corners and present edge midpoints */
                    int64_t ring[8][3];
                    int nr = 0, mids = 0;
                    static const int cu[4] = {0, 1, 1, 0}, cw[4] = {0, 0, 1, 1};
                    for (int k = 0; k < 4; k++) {
                        int k2 = (k + 1) & 3;
                        face_point(a, pa, u0 + cu[k] * S, w0 + cw[k] * S, ring[nr++]);
                        int64_t m[3];
                        face_point(a, pa, u0 + (cu[k] + cu[k2]) * S / 2, w0 + (cw[k] + cw[k2]) * S / 2, m);
                        if (vid_of(&b, m, 0) != UINT32_MAX) {
                            memcpy(ring[nr++], m, sizeof m);
                            mids++;
                        }
                    }
                    if (!mids) {
                        memcpy(tri[0], ring[0], sizeof tri[0]);
                        memcpy(tri[1], ring[1], sizeof tri[1]);
                        memcpy(tri[2], ring[2], sizeof tri[2]);
                        cone(&b, ctr, cid, (const int64_t(*)[3])tri, label);
                        memcpy(tri[1], ring[2], sizeof tri[1]);
                        memcpy(tri[2], ring[3], sizeof tri[2]);
                        cone(&b, ctr, cid, (const int64_t(*)[3])tri, label);
                    } else {
                        int64_t fc[3];
                        face_point(a, pa, u0 + S / 2, w0 + S / 2, fc);
                        for (int k = 0; k < nr; k++) {
                            memcpy(tri[0], fc, sizeof tri[0]);
                            memcpy(tri[1], ring[k], sizeof tri[1]);
                            memcpy(tri[2], ring[(k + 1) % nr], sizeof tri[2]);
                            cone(&b, ctr, cid, (const int64_t(*)[3])tri, label);
                        }
                        if (outer) {
                            memcpy(ring[nr], fc, sizeof fc);
                            nr++;
                        }
                    }
                    if (outer)
                        record_outer(&b, &of, &of_count, &of_cap, (const int64_t(*)[3])ring, nr, a,
                                     side);
                }
            }
    free(b.lvl);
    size_t nv = b.nv;
    out->positions = malloc((nv ? nv : 1) * 3 * sizeof *out->positions);
    int8_t *dir = calloc(nv ? 3 * nv : 1, 1);
    if (b.oom || !out->positions || !dir || nv > UINT32_MAX) {
        free(b.vh.key);
        free(b.vh.val);
        free(b.dense);
        free(b.tets);
        free(b.labels);
        free(of);
        free(dir);
        free(out->positions);
        out->positions = NULL;
        return b.oom || !out->positions ? POSE_ERR_OUT_OF_MEMORY : POSE_ERR_INVALID_ARGUMENT;
    }
    const double hc = 0.5 * L->c;
    for (size_t z = 0; z < b.dn[2]; z++)
        for (size_t y = 0; y < b.dn[1]; y++)
            for (size_t x = 0; x < b.dn[0]; x++) {
                uint32_t v = b.dense[x + b.dn[0] * (y + b.dn[1] * z)];
                if (v == UINT32_MAX)
                    continue;
                out->positions[3 * (size_t)v] = (float)(L->o[0] + (double)x * L->c);
                out->positions[3 * (size_t)v + 1] = (float)(L->o[1] + (double)y * L->c);
                out->positions[3 * (size_t)v + 2] = (float)(L->o[2] + (double)z * L->c);
            }
    free(b.dense);
    for (size_t i = 0; i < b.vh.cap; i++) {
        uint64_t k = b.vh.key[i];
        if (k == UINT64_MAX)
            continue;
        uint32_t v = b.vh.val[i];
        int64_t p[3] = {(int64_t)(k >> 42), (int64_t)(k >> 21 & 0x1fffff), (int64_t)(k & 0x1fffff)};
        for (int q = 0; q < 3; q++)
            out->positions[3 * (size_t)v + q] = (float)(L->o[q] + (double)p[q] * hc);
    }
    for (size_t i = 0; i < of_count; i++) {
        int a = (int)(of[2 * i + 1] / 2), side = (int)(of[2 * i + 1] & 1);
        int8_t *d = dir + 3 * (size_t)of[2 * i] + a;
        *d = (int8_t)(*d + (side ? 1 : -1));
    }
    free(of);
    free(b.vh.key);
    free(b.vh.val);
    out->vertex_count = nv;
    out->tet_count = b.tet_count;
    out->tets = b.tets;
    out->labels = b.labels;
    *dir_out = dir;
    return POSE_OK;
}
