/* SPDX-License-Identifier: Apache-2.0 */
/* contact_push.h: the bones' query structures and the skin's clusters,
 * built when the response is first enabled. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "contact_build.h"
#include "contact_cover.h"
#include "contact_push.h"
#include "error.h"
#include "morton.h"
#include "state_internal.h"

/* Grid spacing: a 128th of the bone's longest side, within [2, 4] mm (rig
 * in metres): fine enough that only skin within a few mm of a bone needs
 * an exact query (the per-frame cost), coarse enough that the thorax's
 * grid stays near 2 M cells of one byte. */
#define CELL_MIN 0.002f
#define CELL_MAX 0.004f
#define CELL_DIVISIONS 128.0f

static void normalize3(float *v)
{
    const float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0f)
        for (int d = 0; d < 3; d++)
            v[d] /= l;
}

typedef struct edge_key {
    uint32_t a, b, slot; /* a < b; slot = 3 * triangle + k */
} edge_key;

static int cmp_edge(const void *x, const void *y)
{
    const edge_key *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return p->slot < q->slot ? -1 : p->slot > q->slot;
}

/* Face, edge and angle-weighted vertex pseudo-normals of a bone. */
static pose_status pseudo_normals(pose__push_bone *b, const pose__tissue *ts, const pose_allocator *a)
{
    const size_t nt = ts->triangle_count, nv = ts->vertex_count;
    b->face_n = pose__alloc(a, 3 * nt * sizeof(float), POSE__ALIGN);
    b->edge_n = pose__calloc(a, 9 * nt * sizeof(float), POSE__ALIGN);
    b->vert_n = pose__calloc(a, 3 * nv * sizeof(float), POSE__ALIGN);
    edge_key *e = pose__alloc(a, 3 * nt * sizeof *e, POSE__ALIGN);
    if (!b->face_n || !b->edge_n || !b->vert_n || !e) {
        pose__free(a, e);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a bone's normals");
    }
    for (size_t f = 0; f < nt; f++) {
        const uint32_t *t = ts->triangles + 3 * f;
        const float *x[3] = {ts->positions + 3 * (size_t)t[0], ts->positions + 3 * (size_t)t[1],
                             ts->positions + 3 * (size_t)t[2]};
        float *n = b->face_n + 3 * f, u[3], v[3];
        for (int d = 0; d < 3; d++) {
            u[d] = x[1][d] - x[0][d];
            v[d] = x[2][d] - x[0][d];
        }
        n[0] = u[1] * v[2] - u[2] * v[1];
        n[1] = u[2] * v[0] - u[0] * v[2];
        n[2] = u[0] * v[1] - u[1] * v[0];
        normalize3(n);
        for (int k = 0; k < 3; k++) {
            /* The angle of the triangle at vertex k weighs its normal there. */
            float p[3], q[3];
            for (int d = 0; d < 3; d++) {
                p[d] = x[(k + 1) % 3][d] - x[k][d];
                q[d] = x[(k + 2) % 3][d] - x[k][d];
            }
            normalize3(p);
            normalize3(q);
            const float c = p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
            const float angle = acosf(c < -1.0f ? -1.0f : c > 1.0f ? 1.0f : c);
            for (int d = 0; d < 3; d++)
                b->vert_n[3 * (size_t)t[k] + (size_t)d] += angle * n[d];
            const uint32_t i = t[k], j = t[(k + 1) % 3];
            e[3 * f + (size_t)k] = (edge_key){i < j ? i : j, i < j ? j : i, (uint32_t)(3 * f + (size_t)k)};
        }
    }
    /* An edge's pseudo-normal: the sum of its faces' normals (one face at a
     * border of an open mesh). */
    qsort(e, 3 * nt, sizeof *e, cmp_edge);
    for (size_t i = 0; i < 3 * nt;) {
        size_t j = i;
        float s[3] = {0.0f, 0.0f, 0.0f};
        while (j < 3 * nt && e[j].a == e[i].a && e[j].b == e[i].b) {
            for (int d = 0; d < 3; d++)
                s[d] += b->face_n[3 * (size_t)(e[j].slot / 3) + (size_t)d];
            j++;
        }
        for (size_t k = i; k < j; k++)
            memcpy(b->edge_n + 3 * (size_t)e[k].slot, s, sizeof s);
        i = j;
    }
    pose__free(a, e);
    return POSE_OK;
}

float pose__push_distance(const pose__push_bone *b, const float *q, float max_dist, float *closest,
                          float *outward)
{
    pose__bvh_near n;
    const float d = pose__bvh_nearest(&b->tree, b->rest, q, max_dist, &n);
    if (n.triangle == UINT32_MAX)
        return INFINITY;
    const uint32_t *t = b->tree.triangles + 3 * (size_t)n.triangle;
    const float *pn;
    if (n.feature == POSE__NEAR_FACE)
        pn = b->face_n + 3 * (size_t)n.triangle;
    else if (n.feature <= POSE__NEAR_V2)
        pn = b->vert_n + 3 * (size_t)t[n.feature - POSE__NEAR_V0];
    else
        pn = b->edge_n + 9 * (size_t)n.triangle + 3 * (size_t)(n.feature - POSE__NEAR_E01);
    float r[3] = {q[0] - n.point[0], q[1] - n.point[1], q[2] - n.point[2]};
    const float side = r[0] * pn[0] + r[1] * pn[1] + r[2] * pn[2];
    memcpy(closest, n.point, sizeof n.point);
    if (d > 1e-7f) {
        const float s = side >= 0.0f ? 1.0f / d : -1.0f / d;
        for (int k = 0; k < 3; k++)
            outward[k] = r[k] * s;
    } else {
        memcpy(outward, pn, 3 * sizeof(float));
        normalize3(outward);
    }
    return side >= 0.0f ? d : -d;
}

static inline double min_d(double a, double b)
{
    return a < b ? a : b;
}

static inline double max_d(double a, double b)
{
    return a > b ? a : b;
}

/* Triangle abc overlaps the cube of centre c and half side h: no
 * separating axis among the cube's 3, the triangle's normal and the 9
 * edge x axis products (Akenine-Moller 2001), in double. (min_d and max_d,
 * not fmin and fmax: no NaN comes here, and libm's are calls, a fifth of
 * the bones' grids' build.) */
static int tri_box_overlap(const double *c, double h, const float *a, const float *b, const float *d)
{
    double v[3][3], e[3][3];
    for (int k = 0; k < 3; k++) {
        v[0][k] = (double)a[k] - c[k];
        v[1][k] = (double)b[k] - c[k];
        v[2][k] = (double)d[k] - c[k];
    }
    for (int k = 0; k < 3; k++) {
        const double lo = min_d(min_d(v[0][k], v[1][k]), v[2][k]), hi = max_d(max_d(v[0][k], v[1][k]), v[2][k]);
        if (lo > h || hi < -h)
            return 0;
    }
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++)
            e[k][i] = v[(k + 1) % 3][i] - v[k][i];
    const double n[3] = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                         e[0][0] * e[1][1] - e[0][1] * e[1][0]};
    const double dn = n[0] * v[0][0] + n[1] * v[0][1] + n[2] * v[0][2];
    if (fabs(dn) > h * (fabs(n[0]) + fabs(n[1]) + fabs(n[2])))
        return 0;
    for (int k = 0; k < 3; k++)      /* edge */
        for (int ax = 0; ax < 3; ax++) { /* cube axis: edge x axis */
            double m[3] = {0.0, 0.0, 0.0};
            m[(ax + 1) % 3] = e[k][(ax + 2) % 3];
            m[(ax + 2) % 3] = -e[k][(ax + 1) % 3];
            double lo = INFINITY, hi = -INFINITY;
            for (int i = 0; i < 3; i++) {
                const double p = m[0] * v[i][0] + m[1] * v[i][1] + m[2] * v[i][2];
                lo = min_d(lo, p);
                hi = max_d(hi, p);
            }
            const double r = h * (fabs(m[0]) + fabs(m[1]) + fabs(m[2]));
            if (lo > r || hi < -r)
                return 0;
        }
    return 1;
}

/* The runtime grid: per cell its state and, for an OUT cell, the Chebyshev
 * distance (in cells, capped at 254) to the nearest cell that is not OUT:
 * a breadth-first search over the 26 neighbours from those cells. A point
 * of a cell with gap k is farther than (k - 1) cells from any point of a
 * non-OUT cell, so a cluster of skin whose sphere is smaller than that has
 * no vertex to test. Stored in bricks of 4 x 4 x 4 cells (one cache line):
 * a cluster's vertices read a few lines instead of a line per row. */
static void bone_gap(pose__push_bone *b, const uint8_t *cells, uint32_t *queue, uint8_t *code)
{
    const size_t sy = (size_t)b->dim[0], sz = (size_t)b->dim[0] * (size_t)b->dim[1];
    const size_t cells_n = sz * (size_t)b->dim[2];
    const size_t bricks = (size_t)b->bricks[0] * (size_t)b->bricks[1] * (size_t)b->bricks[2];
    size_t head = 0, tail = 0;
    for (size_t i = 0; i < cells_n; i++) {
        code[i] = cells[i] == POSE__CELL_OUT ? 255 : cells[i];
        if (cells[i] != POSE__CELL_OUT)
            queue[tail++] = (uint32_t)i;
    }
    ptrdiff_t step[26]; /* the 26 neighbours' index offsets */
    int steps = 0;
    for (int dz = -1; dz <= 1; dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++)
                if (dx || dy || dz)
                    step[steps++] = (ptrdiff_t)dz * (ptrdiff_t)sz + (ptrdiff_t)dy * (ptrdiff_t)sy + dx;
    while (head < tail) {
        const size_t i = queue[head++];
        const int x = (int)(i % sy), y = (int)((i / sy) % (size_t)b->dim[1]), z = (int)(i / sz);
        /* POSE__CELL_OUT - 1 + gap of the neighbours: a non-OUT cell's have
         * gap 1 (code POSE__CELL_OUT), an OUT cell's one more than its own. */
        const int next = code[i] < POSE__CELL_OUT ? POSE__CELL_OUT : code[i] + 1;
        if (next >= 255)
            continue;
        if (x > 0 && y > 0 && z > 0 && x < b->dim[0] - 1 && y < b->dim[1] - 1 && z < b->dim[2] - 1) {
            /* inside the grid: every neighbour exists (most cells; the same
             * neighbours in the same order as the border's loop below) */
            for (int k = 0; k < 26; k++) {
                const size_t j = (size_t)((ptrdiff_t)i + step[k]);
                if (code[j] > next) {
                    code[j] = (uint8_t)next;
                    queue[tail++] = (uint32_t)j;
                }
            }
            continue;
        }
        for (int dz = -1; dz <= 1; dz++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    const int u = x + dx, w = y + dy, t = z + dz;
                    if (u < 0 || w < 0 || t < 0 || u >= b->dim[0] || w >= b->dim[1] || t >= b->dim[2])
                        continue;
                    const size_t j = (size_t)t * sz + (size_t)w * sy + (size_t)u;
                    if (code[j] > next) {
                        code[j] = (uint8_t)next;
                        queue[tail++] = (uint32_t)j;
                    }
                }
    }
    memset(b->grid, 255, 64 * bricks);
    for (int z = 0; z < b->dim[2]; z++)
        for (int y = 0; y < b->dim[1]; y++)
            for (int x = 0; x < b->dim[0]; x++) {
                const size_t brick = ((size_t)(z >> 2) * (size_t)b->bricks[1] + (size_t)(y >> 2)) * (size_t)b->bricks[0] +
                                     (size_t)(x >> 2);
                b->grid[64 * brick + (size_t)((z & 3) << 4 | (y & 3) << 2 | (x & 3))] =
                    code[(size_t)z * sz + (size_t)y * sy + (size_t)x];
            }
    for (size_t k = 0; k < bricks; k++) {
        uint8_t least = 255;
        for (size_t c = 0; c < 64; c++)
            least = b->grid[64 * k + c] < least ? b->grid[64 * k + c] : least;
        b->brick_gap[k] = least >= POSE__CELL_OUT ? (uint8_t)(least - (POSE__CELL_OUT - 1)) : 0;
    }
}

/* The bone's sphere, and its grid's box, spacing and bricks; returns the
 * grid's cell count. */
static size_t bone_grid_size(pose__push_bone *b, const pose__tissue *ts, float margin)
{
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < ts->vertex_count; v++)
        for (int d = 0; d < 3; d++) {
            lo[d] = fminf(lo[d], ts->positions[3 * v + (size_t)d]);
            hi[d] = fmaxf(hi[d], ts->positions[3 * v + (size_t)d]);
        }
    float longest = 0.0f;
    for (int d = 0; d < 3; d++) {
        b->center[d] = 0.5f * (lo[d] + hi[d]);
        longest = fmaxf(longest, hi[d] - lo[d]);
    }
    b->radius = 0.0f;
    for (size_t v = 0; v < ts->vertex_count; v++) {
        const float *x = ts->positions + 3 * v;
        const float dx = x[0] - b->center[0], dy = x[1] - b->center[1], dz = x[2] - b->center[2];
        b->radius = fmaxf(b->radius, sqrtf(dx * dx + dy * dy + dz * dz));
    }
    b->cell = fminf(fmaxf(longest / CELL_DIVISIONS, CELL_MIN), CELL_MAX);
    const float pad = margin + b->cell;
    size_t cells = 1;
    for (int d = 0; d < 3; d++) {
        b->lo[d] = lo[d] - pad;
        b->dim[d] = (int)ceilf((hi[d] + pad - b->lo[d]) / b->cell);
        b->hi[d] = b->lo[d] + (float)b->dim[d] * b->cell;
        cells *= (size_t)b->dim[d];
    }
    b->inv_cell = 1.0f / b->cell;
    for (int d = 0; d < 3; d++)
        b->bricks[d] = (b->dim[d] + 3) / 4;
    return cells;
}

/* Fill bone b's grid (sized and allocated by the build; contact_push.h's
 * cell states): cells a triangle crosses are SURF, the others that a
 * triangle touches grown by the margin NEAR_OUT or NEAR_IN, the rest OUT or
 * IN, by a flood fill from the grid's border (with a rounding allowance on
 * each test). No point of an OUT cell is inside or within the margin; every
 * point of a SURF or NEAR cell has a triangle within sqrt(3) (cell +
 * margin); a NEAR_OUT cell is all outside. (Where a bone's mesh is open the
 * fill leaks in and its inside reads outside: such points are not pushed.)
 * Then the gap to the non-OUT cells. `state`, `queue` and `code` are
 * scratch of at least its cell count (bytes, 32-bit entries, bytes): no
 * allocation, so bones are filled on the state's threads. */
static void bone_grid_fill(pose__push_bone *b, const pose__tissue *ts, float margin, uint8_t *state, uint32_t *queue,
                           uint8_t *code)
{
    const size_t cells = (size_t)b->dim[0] * (size_t)b->dim[1] * (size_t)b->dim[2];
    enum { NEAR = 1, SURF = 2, SEEN = 4 }; /* build bits */
    memset(state, 0, cells);
    const size_t sx = 1, sy = (size_t)b->dim[0], sz = (size_t)b->dim[0] * (size_t)b->dim[1];
    for (size_t f = 0; f < ts->triangle_count; f++) {
        int c0[3], c1[3];
        for (int d = 0; d < 3; d++) {
            const float *x = ts->positions;
            const uint32_t *t = ts->triangles + 3 * f;
            const float u = fminf(fminf(x[3 * (size_t)t[0] + (size_t)d], x[3 * (size_t)t[1] + (size_t)d]), x[3 * (size_t)t[2] + (size_t)d]);
            const float w = fmaxf(fmaxf(x[3 * (size_t)t[0] + (size_t)d], x[3 * (size_t)t[1] + (size_t)d]), x[3 * (size_t)t[2] + (size_t)d]);
            c0[d] = (int)floorf((u - margin - b->lo[d]) / b->cell);
            c1[d] = (int)floorf((w + margin - b->lo[d]) / b->cell);
            c0[d] = c0[d] < 1 ? 0 : c0[d] - 1; /* a cell more: the rounding allowance */
            c1[d] = c1[d] >= b->dim[d] - 1 ? b->dim[d] - 1 : c1[d] + 1;
        }
        const uint32_t *t = ts->triangles + 3 * f;
        const float *x0 = ts->positions + 3 * (size_t)t[0], *x1 = ts->positions + 3 * (size_t)t[1],
                    *x2 = ts->positions + 3 * (size_t)t[2];
        const double hs = 0.5 * (double)b->cell + 1e-3 * (double)b->cell, h = hs + (double)margin;
        double tlo[3], thi[3]; /* the triangle's box: tri_box_overlap's first test, before its call */
        for (int d = 0; d < 3; d++) {
            tlo[d] = min_d(min_d(x0[d], x1[d]), x2[d]);
            thi[d] = max_d(max_d(x0[d], x1[d]), x2[d]);
        }
        for (int z = c0[2]; z <= c1[2]; z++)
            for (int y = c0[1]; y <= c1[1]; y++)
                for (int x = c0[0]; x <= c1[0]; x++) {
                    const size_t i = (size_t)z * sz + (size_t)y * sy + (size_t)x * sx;
                    const double c[3] = {b->lo[0] + (x + 0.5) * (double)b->cell, b->lo[1] + (y + 0.5) * (double)b->cell,
                                         b->lo[2] + (z + 0.5) * (double)b->cell};
                    if (tlo[0] - c[0] > h || thi[0] - c[0] < -h || tlo[1] - c[1] > h || thi[1] - c[1] < -h ||
                        tlo[2] - c[2] > h || thi[2] - c[2] < -h)
                        continue;
                    if (!(state[i] & SURF) && tri_box_overlap(c, h, x0, x1, x2))
                        state[i] |= NEAR | (tri_box_overlap(c, hs, x0, x1, x2) ? SURF : 0);
                }
    }
    /* Flood from the border through the cells no triangle crosses (each
     * wholly on one side of the surface, and two such neighbours on the
     * same side: a triangle on their common face would touch both): the
     * cells reached are outside, the others inside. */
    size_t head = 0, tail = 0;
    for (int z = 0; z < b->dim[2]; z++)
        for (int y = 0; y < b->dim[1]; y++)
            for (int x = 0; x < b->dim[0]; x++) {
                const int border = x == 0 || y == 0 || z == 0 || x == b->dim[0] - 1 || y == b->dim[1] - 1 ||
                                   z == b->dim[2] - 1;
                const size_t i = (size_t)z * sz + (size_t)y * sy + (size_t)x;
                if (border && !(state[i] & SURF)) {
                    state[i] |= SEEN;
                    queue[tail++] = (uint32_t)i;
                }
            }
    while (head < tail) {
        const size_t i = queue[head++];
        const int x = (int)(i % sy), y = (int)((i / sy) % (size_t)b->dim[1]), z = (int)(i / sz);
        const int nx[6] = {x - 1, x + 1, x, x, x, x}, ny[6] = {y, y, y - 1, y + 1, y, y},
                  nz[6] = {z, z, z, z, z - 1, z + 1};
        for (int k = 0; k < 6; k++) {
            if (nx[k] < 0 || ny[k] < 0 || nz[k] < 0 || nx[k] >= b->dim[0] || ny[k] >= b->dim[1] || nz[k] >= b->dim[2])
                continue;
            const size_t j = (size_t)nz[k] * sz + (size_t)ny[k] * sy + (size_t)nx[k];
            if (!(state[j] & (SURF | SEEN))) {
                state[j] |= SEEN;
                queue[tail++] = (uint32_t)j;
            }
        }
    }
    for (size_t i = 0; i < cells; i++)
        state[i] = state[i] & SURF   ? POSE__CELL_SURF
                   : state[i] & NEAR ? (state[i] & SEEN ? POSE__CELL_NEAR_OUT : POSE__CELL_NEAR_IN)
                                     : (state[i] & SEEN ? POSE__CELL_OUT : POSE__CELL_IN);
    bone_gap(b, state, queue, code);
}

/* Skin vertices in Morton order of their rest positions: consecutive runs
 * of POSE__PUSH_CLUSTER are compact clusters. */
static pose_status skin_order(pose__push *p, const pose_state *st)
{
    const pose_rig *rig = st->rig;
    size_t n = 0;
    for (size_t t = 0; t < rig->tissue_count; t++)
        if (rig->tissues[t].kind == POSE_TISSUE_SKIN)
            n += rig->tissues[t].vertex_count;
    p->vertex_count = n;
    p->cluster_count = (n + POSE__PUSH_CLUSTER - 1) / POSE__PUSH_CLUSTER;
    p->order = pose__alloc(&p->allocator, (n + 1) * sizeof *p->order, POSE__ALIGN);
    p->skip = pose__calloc(&p->allocator, n + 1, POSE__ALIGN);
    p->cache = pose__alloc(&p->allocator, (n + 1) * sizeof *p->cache, POSE__ALIGN);
    pose__morton *k = pose__alloc(&p->allocator, (n + 1) * sizeof *k, POSE__ALIGN);
    if (!p->order || !p->skip || !p->cache || !k) {
        pose__free(&p->allocator, k);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu skin vertices", n);
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t t = 0; t < rig->tissue_count; t++)
        if (rig->tissues[t].kind == POSE_TISSUE_SKIN)
            for (size_t v = 0; v < 3 * rig->tissues[t].vertex_count; v++) {
                lo[v % 3] = fminf(lo[v % 3], rig->tissues[t].positions[v]);
                hi[v % 3] = fmaxf(hi[v % 3], rig->tissues[t].positions[v]);
            }
    size_t i = 0;
    for (size_t t = 0; t < rig->tissue_count; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        if (ts->kind != POSE_TISSUE_SKIN)
            continue;
        for (size_t v = 0; v < ts->vertex_count; v++, i++)
            k[i] = (pose__morton){pose__morton_key(ts->positions + 3 * v, lo, hi), (uint32_t)(st->rt->tissue_offset[t] + v)};
    }
    qsort(k, n, sizeof *k, pose__morton_cmp);
    for (i = 0; i < n; i++) {
        p->order[i] = k[i].index;
        p->cache[i].slot[0].bone = p->cache[i].slot[1].bone = UINT32_MAX;
    }
    pose__free(&p->allocator, k);
    return POSE_OK;
}

/* Skin inside a bone at rest is anatomy (the orbits' and the mouth's skin in
 * the skull and jaw): those vertices are left where skinning puts them. */
static void mark_rest_inside(pose__push *p, const pose_state *st)
{
    const float *rest = NULL;
    for (size_t i = 0; i < p->vertex_count; i++) {
        const uint32_t v = p->order[i];
        size_t t = 0;
        while (st->rt->tissue_offset[t + 1] <= v)
            t++;
        rest = st->rig->tissues[t].positions + 3 * (v - st->rt->tissue_offset[t]);
        for (size_t j = 0; j < p->bone_count && !p->skip[i]; j++) {
            const pose__push_bone *b = &p->bones[j];
            float c[3], o[3];
            if (rest[0] < b->lo[0] || rest[1] < b->lo[1] || rest[2] < b->lo[2] || rest[0] >= b->hi[0] ||
                rest[1] >= b->hi[1] || rest[2] >= b->hi[2])
                continue;
            p->skip[i] = pose__push_distance(b, rest, INFINITY, c, o) < 0.0f;
        }
    }
}

/* Which bones each cluster of skin covers at rest (pose__push.reach). */
static pose_status mark_reach(pose__push *p, const pose_state *st)
{
    p->reach = pose__calloc(&p->allocator, (p->cluster_count * p->bone_words + 1) * sizeof *p->reach, POSE__ALIGN);
    float *rest = pose__alloc(&p->allocator, (3 * p->vertex_count + 1) * sizeof(float), POSE__ALIGN);
    if (!p->reach || !rest) {
        pose__free(&p->allocator, rest);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu skin clusters", p->cluster_count);
    }
    for (size_t i = 0; i < p->vertex_count; i++) {
        const uint32_t v = p->order[i];
        size_t t = 0;
        while (st->rt->tissue_offset[t + 1] <= v)
            t++;
        memcpy(rest + 3 * i, st->rig->tissues[t].positions + 3 * (v - st->rt->tissue_offset[t]), 3 * sizeof(float));
    }
    for (size_t c = 0; c < p->cluster_count; c++) {
        const size_t vb = c * POSE__PUSH_CLUSTER,
                     ve = vb + POSE__PUSH_CLUSTER < p->vertex_count ? vb + POSE__PUSH_CLUSTER : p->vertex_count;
        float sphere[4];
        pose__push_sphere(rest, NULL, vb, ve, sphere);
        for (size_t j = 0; j < p->bone_count; j++) {
            const pose__push_bone *b = &p->bones[j];
            const float reach = sphere[3] + POSE__PUSH_REACH;
            float e2 = 0.0f, q[3], o[3];
            for (int d = 0; d < 3; d++) { /* the bone's box first */
                const float e = sphere[d] < b->lo[d] ? b->lo[d] - sphere[d] : sphere[d] > b->hi[d] ? sphere[d] - b->hi[d] : 0.0f;
                e2 += e * e;
            }
            if (e2 <= reach * reach && pose__push_distance(b, sphere, reach, q, o) <= reach)
                p->reach[c * p->bone_words + j / 64] |= (uint64_t)1 << (j % 64);
        }
    }
    pose__free(&p->allocator, rest);
    return POSE_OK;
}

/* The joint carrying most of a point that blends tet vertices v[c] by
 * share[c], c < count (a skin vertex: its tet's corners by its barycentric
 * coordinates): the largest of its blended skinning weights. */
static int heaviest_joint(const pose_rig *rig, const uint32_t *v, const float *share, int count)
{
    enum { MOST = 4 * POSE__MAX_INFLUENCES };
    const unsigned K = rig->influences;
    int joints[MOST], n = 0, best = -1;
    float w[MOST], most = 0.0f;
    for (int c = 0; c < count; c++)
        for (unsigned k = 0; k < K && share[c] != 0.0f; k++) {
            const int j = rig->weight_joints[K * (size_t)v[c] + k];
            int e = 0;
            while (e < n && joints[e] != j)
                e++;
            if (e == n) {
                joints[n] = j;
                w[n++] = 0.0f;
            }
            w[e] += share[c] * rig->weights[K * (size_t)v[c] + k];
        }
    for (int e = 0; e < n; e++)
        if (w[e] > most) {
            most = w[e];
            best = joints[e];
        }
    return best;
}

/* A rest point's anchor (pose__push_anchor) on `joint`: its distance to the
 * joint's bones, counted up to POSE__PUSH_REACH (farther: that much). */
static void anchor_at(const pose__push *p, const float *x, int joint, pose__push_anchor *a)
{
    memcpy(a->rest, x, sizeof a->rest);
    a->room = 0.0f;
    a->joint = -1;
    if (joint < 0 || (size_t)joint >= p->joint_count || p->joint_start[joint + 1] == p->joint_start[joint])
        return;
    float nearest = POSE__PUSH_REACH;
    for (uint32_t e = p->joint_start[joint]; e < p->joint_start[joint + 1]; e++) {
        const pose__push_bone *b = &p->bones[p->joint_bones[e]];
        float e2 = 0.0f, c[3], o[3];
        for (int d = 0; d < 3; d++) { /* the bone's box first */
            const float g = x[d] < b->lo[d] ? b->lo[d] - x[d] : x[d] > b->hi[d] ? x[d] - b->hi[d] : 0.0f;
            e2 += g * g;
        }
        if (e2 >= nearest * nearest)
            continue;
        const float sd = pose__push_distance(b, x, nearest, c, o);
        if (sd < 0.0f) /* inside a bone at rest */
            return;
        nearest = sd < nearest ? sd : nearest;
    }
    if (nearest > p->margin) {
        a->joint = joint;
        a->room = nearest - p->margin;
    }
}

/* The skin's anchors, in the pass's order. */
static pose_status anchor_skin(pose__push *p, const pose_state *st)
{
    const pose_rig *rig = st->rig;
    p->anchor = pose__alloc(&p->allocator, (p->vertex_count + 1) * sizeof *p->anchor, POSE__ALIGN);
    if (!p->anchor)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu skin vertices", p->vertex_count);
    for (size_t i = 0; i < p->vertex_count; i++) {
        const uint32_t v = p->order[i];
        size_t t = 0;
        while (st->rt->tissue_offset[t + 1] <= v)
            t++;
        const pose__tissue *ts = &rig->tissues[t];
        const size_t local = v - st->rt->tissue_offset[t];
        const uint32_t *corners = rig->tets + 4 * (size_t)ts->tet[local];
        anchor_at(p, ts->positions + 3 * local, heaviest_joint(rig, corners, ts->bary + 4 * local, 4), &p->anchor[i]);
    }
    return POSE_OK;
}

/* Each joint's bones, and a sphere holding their rest spheres (the
 * clusters' quiet bounds: contact_quiet.h). */
static pose_status joint_spheres(pose__push *p)
{
    const size_t nj = p->joint_count;
    p->joint_start = pose__calloc(&p->allocator, (nj + 2) * sizeof *p->joint_start, POSE__ALIGN);
    p->joint_bones = pose__alloc(&p->allocator, (p->bone_count + 1) * sizeof *p->joint_bones, POSE__ALIGN);
    p->joint_spheres = pose__alloc(&p->allocator, (8 * nj + 1) * sizeof *p->joint_spheres, POSE__ALIGN);
    if (!p->joint_start || !p->joint_bones || !p->joint_spheres)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu joints", nj);
    for (size_t j = 0; j < p->bone_count; j++)
        p->joint_start[p->bones[j].joint + 1]++;
    for (size_t k = 0; k < nj; k++)
        p->joint_start[k + 1] += p->joint_start[k];
    for (size_t j = 0; j < p->bone_count; j++) /* in the rig's order within each joint */
        p->joint_bones[p->joint_start[p->bones[j].joint]++] = (uint32_t)j;
    for (size_t k = nj; k > 0; k--) /* the pass above moved each start to the next one's */
        p->joint_start[k] = p->joint_start[k - 1];
    p->joint_start[0] = 0;
    for (size_t k = 0; k < nj; k++) {
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, *js = p->joint_spheres + 8 * k;
        for (uint32_t e = p->joint_start[k]; e < p->joint_start[k + 1]; e++) {
            const pose__push_bone *b = &p->bones[p->joint_bones[e]];
            for (int d = 0; d < 3; d++) {
                lo[d] = fminf(lo[d], b->center[d] - b->radius);
                hi[d] = fmaxf(hi[d], b->center[d] + b->radius);
            }
        }
        float r = 0.0f;
        for (int d = 0; d < 3; d++)
            js[d] = p->joint_start[k + 1] > p->joint_start[k] ? 0.5f * (lo[d] + hi[d]) : 0.0f;
        for (uint32_t e = p->joint_start[k]; e < p->joint_start[k + 1]; e++) {
            const pose__push_bone *b = &p->bones[p->joint_bones[e]];
            const float dx = b->center[0] - js[0], dy = b->center[1] - js[1], dz = b->center[2] - js[2];
            r = fmaxf(r, sqrtf(dx * dx + dy * dy + dz * dz) + b->radius);
        }
        js[3] = p->joint_start[k + 1] > p->joint_start[k] ? r * 1.0001f : -INFINITY; /* none: never near */
        memcpy(js + 4, js, 4 * sizeof *js);
    }
    return POSE_OK;
}

void pose__push_release(pose__push *p)
{
    const pose_allocator *a = &p->allocator;
    for (size_t j = 0; p->bones && j < p->bone_count; j++) {
        pose__push_bone *b = &p->bones[j];
        pose__bvh_release(&b->tree, a);
        pose__free(a, b->face_n);
        pose__free(a, b->edge_n);
        pose__free(a, b->vert_n);
        pose__free(a, b->grid);
        pose__free(a, b->brick_gap);
    }
    pose__free(a, p->bones);
    pose__free(a, p->order);
    pose__free(a, p->skip);
    pose__free(a, p->cache);
    pose__free(a, p->anchor);
    pose__free(a, p->reach);
    pose__free(a, p->frames);
    pose__free(a, p->bone_spheres);
    pose__free(a, p->near);
    pose__free(a, p->hit);
    pose__quiet_joints_release(&p->quiet_joints, a);
    pose__free(a, p->bound);
    pose__free(a, p->joint_start);
    pose__free(a, p->joint_bones);
    pose__free(a, p->joint_spheres);
    pose__quiet_release(&p->skin_quiet, a);
    pose__quiet_release(&p->node_quiet, a);
    pose__free(a, p->nodes);
    pose__free(a, p->node_cache);
    pose__free(a, p->node_anchor);
    pose__free(a, p->node_bone);
    pose__free(a, p->node_gap);
    pose__free(a, p->rest_count);
    pose__free(a, p->rests);
    pose__free(a, p->rest_on);
    pose__free(a, p->rest_stiff);
    pose__free(a, p->rest_force);
    if (p->cover)
        pose__cover_release(p->cover, a);
    pose__free(a, p->cover);
    const pose_allocator keep = *a;
    memset(p, 0, sizeof *p);
    p->allocator = keep;
}

/* The bones' grids: sized and allocated one bone after another (the
 * allocator is not promised to be thread-safe), then filled on the state's
 * threads, bone k by part k mod parts, each part with its own scratch. */
typedef struct grid_build {
    pose__push *p;
    float margin;
    const pose__tissue **tissue; /* per bone */
    size_t most;                 /* cells of the largest grid */
    uint8_t *scratch;            /* per part: queue (4 most bytes), state (most), code (most) */
} grid_build;

static pose_status grid_alloc(pose__push_bone *b, const pose__tissue *ts, float margin, const pose_allocator *a,
                              size_t *most)
{
    const size_t cells = bone_grid_size(b, ts, margin);
    const size_t bricks = (size_t)b->bricks[0] * (size_t)b->bricks[1] * (size_t)b->bricks[2];
    b->grid = pose__alloc(a, 64 * bricks, POSE__ALIGN);
    b->brick_gap = pose__alloc(a, bricks, POSE__ALIGN);
    if (!b->grid || !b->brick_gap)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a bone grid of %zu cells", cells);
    *most = cells > *most ? cells : *most;
    return POSE_OK;
}

static size_t grid_scratch_bytes(size_t most)
{
    return (6 * most + 63) & ~(size_t)63;
}

static void grid_task(void *ctx, unsigned part, unsigned parts)
{
    grid_build *g = ctx;
    uint8_t *base = g->scratch + part * grid_scratch_bytes(g->most); /* 64-byte aligned */
    uint32_t *queue = (uint32_t *)(void *)base;
    uint8_t *state = base + 4 * g->most, *code = state + g->most;
    for (size_t k = part; k < g->p->bone_count; k += parts)
        bone_grid_fill(&g->p->bones[k], g->tissue[k], g->margin, state, queue, code);
}

static pose_status grids_fill(grid_build *g, pose__pool *pool)
{
    if (g->p->bone_count == 0)
        return POSE_OK;
    const unsigned parts = pose__pool_threads(pool);
    g->scratch = pose__alloc(&g->p->allocator, parts * grid_scratch_bytes(g->most), POSE__ALIGN);
    if (!g->scratch)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for building the bones' grids (%zu cells)", g->most);
    pose__pool_run(pool, grid_task, g);
    pose__free(&g->p->allocator, g->scratch);
    return POSE_OK;
}

pose_status pose__push_build(pose__push *p, const pose_state *st, float margin)
{
    const double t0 = pose__seconds();
    const pose_rig *rig = st->rig;
    p->margin = margin;
    size_t nb = 0;
    for (size_t t = 0; t < rig->tissue_count; t++)
        nb += rig->tissues[t].kind == POSE_TISSUE_BONE && rig->tissues[t].joint >= 0 &&
              rig->tissues[t].triangle_count > 0;
    p->bones = pose__calloc(&p->allocator, (nb + 1) * sizeof *p->bones, POSE__ALIGN);
    p->frames = pose__alloc(&p->allocator, (nb + 1) * 12 * sizeof(float), POSE__ALIGN);
    p->bone_words = (nb + 63) / 64;
    p->bone_spheres = pose__alloc(&p->allocator, (4 * 64 * p->bone_words + 1) * sizeof(float), POSE__ALIGN);
    p->near = pose__alloc(&p->allocator, (POSE__PUSH_ITEMS * nb + 1) * sizeof *p->near, POSE__ALIGN);
    p->hit = pose__alloc(&p->allocator, POSE__PUSH_ITEMS * nb + 1, POSE__ALIGN);
    p->joint_count = rig->joint_count;
    p->bound = pose__alloc(&p->allocator, (POSE__PUSH_ITEMS * p->joint_count + 1) * sizeof *p->bound, POSE__ALIGN);
    if (!p->bones || !p->frames || !p->bone_spheres || !p->near || !p->hit || !p->bound)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu bones", nb);
    for (size_t j = 0; j < 4 * 64 * p->bone_words; j++) /* the padding never near (x infinite) */
        p->bone_spheres[j] = j < 64 * p->bone_words ? INFINITY : 0.0f;
    pose_status s = POSE_OK;
    grid_build g = {.p = p, .margin = margin};
    g.tissue = pose__alloc(&p->allocator, (nb + 1) * sizeof *g.tissue, POSE__ALIGN);
    if (!g.tissue)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu bones", nb);
    for (size_t t = 0; t < rig->tissue_count && s == POSE_OK; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        if (ts->kind != POSE_TISSUE_BONE || ts->joint < 0 || ts->triangle_count == 0)
            continue;
        g.tissue[p->bone_count] = ts;
        pose__push_bone *b = &p->bones[p->bone_count++];
        b->joint = ts->joint;
        b->rest = ts->positions;
        s = pose__bvh_build(&b->tree, &p->allocator, ts->triangles, (uint32_t)ts->triangle_count, ts->positions);
        if (s == POSE_OK)
            s = pseudo_normals(b, ts, &p->allocator);
        if (s == POSE_OK)
            s = grid_alloc(b, ts, margin, &p->allocator, &g.most);
    }
    if (s == POSE_OK)
        s = grids_fill(&g, st->pool);
    pose__free(&p->allocator, g.tissue);
    if (s == POSE_OK)
        s = joint_spheres(p);
    if (s == POSE_OK)
        s = pose__quiet_joints_build(&p->quiet_joints, p->joint_count, &p->allocator);
    if (s == POSE_OK)
        s = skin_order(p, st);
    if (s == POSE_OK)
        s = pose__quiet_build(&p->skin_quiet, p->cluster_count, p->joint_count, &p->allocator);
    if (s != POSE_OK)
        return s;
    mark_rest_inside(p, st);
    if ((s = anchor_skin(p, st)) != POSE_OK || (s = mark_reach(p, st)) != POSE_OK)
        return s;
    p->cover = pose__calloc(&p->allocator, sizeof *p->cover, POSE__ALIGN);
    if (!p->cover)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for the contact cover");
    if ((s = pose__cover_build(p->cover, st, p)) != POSE_OK)
        return s;
    p->build_seconds = pose__seconds() - t0;
    return POSE_OK;
}

/* The bone a rest point lies within the margin of (nearest), and its
 * distance, into *bone and *gap; 1 when it is inside a bone at rest. */
static int rest_gap(const pose__push *p, const float *x, uint16_t *bone, float *gap)
{
    static const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    *bone = UINT16_MAX;
    *gap = INFINITY;
    for (size_t j = 0; j < p->bone_count && j < UINT16_MAX; j++) {
        float sd, c[3], o[3];
        if (!pose__push_query(p, &p->bones[j], identity, x, NULL, &sd, c, o, NULL))
            continue;
        if (sd < 0.0f)
            return 1;
        if (sd < *gap) {
            *gap = sd;
            *bone = (uint16_t)j;
        }
    }
    return 0;
}

/* The dynamic response's nodes: every tet vertex the simulation moves
 * freely (mass, a soft tet, no bone spring: fem_dynamics.h), in Morton
 * order of its rest position, but those inside a bone at rest (the tet
 * mesh's bone region and the bones' meshes differ: anatomy, left alone as
 * the skin in bone at rest is). A node within the margin of a bone at rest
 * keeps its rest distance to it as its target there, so rest stays rest. */
pose_status pose__push_build_nodes(pose__push *p, const pose_state *st)
{
    const pose_allocator *a = &p->allocator;
    const pose__fem_mesh *m = &st->rt->fem;
    const float *rest = st->rig->tet_positions;
    const size_t nv = m->vertex_count;
    p->nodes = pose__alloc(a, (nv + 1) * sizeof *p->nodes, POSE__ALIGN);
    p->node_bone = pose__alloc(a, (nv + 1) * sizeof *p->node_bone, POSE__ALIGN);
    p->node_gap = pose__alloc(a, (nv + 1) * sizeof *p->node_gap, POSE__ALIGN);
    p->node_cache = pose__alloc(a, (nv + 1) * sizeof *p->node_cache, POSE__ALIGN);
    p->node_anchor = pose__alloc(a, (nv + 1) * sizeof *p->node_anchor, POSE__ALIGN);
    p->rest_count = pose__alloc(a, nv + 1, POSE__ALIGN);
    p->rests = pose__alloc(a, POSE__PUSH_NODE_BONES * (nv + 1) * sizeof *p->rests, POSE__ALIGN);
    p->rest_on = pose__alloc(a, nv + 1, POSE__ALIGN);
    p->rest_stiff = pose__alloc(a, 6 * (nv + 1) * sizeof(float), POSE__ALIGN);
    p->rest_force = pose__alloc(a, 3 * (nv + 1) * sizeof(float), POSE__ALIGN);
    pose__morton *k = pose__alloc(a, (nv + 1) * sizeof *k, POSE__ALIGN);
    if (!p->nodes || !p->node_bone || !p->node_gap || !p->node_cache || !p->node_anchor || !p->rest_count || !p->rests ||
        !p->rest_on || !p->rest_stiff || !p->rest_force || !k) {
        pose__free(a, k);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for %zu nodes of the contact response", nv);
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < 3 * nv; v++) {
        lo[v % 3] = fminf(lo[v % 3], rest[v]);
        hi[v % 3] = fmaxf(hi[v % 3], rest[v]);
    }
    size_t n = 0;
    for (size_t v = 0; v < nv; v++)
        if (m->corner_offset[v + 1] > m->corner_offset[v] && m->mass[v] > 0.0f && m->inv_diag[v] != 0.0f)
            k[n++] = (pose__morton){pose__morton_key(rest + 3 * v, lo, hi), (uint32_t)v};
    qsort(k, n, sizeof *k, pose__morton_cmp);
    size_t kept = 0;
    for (size_t i = 0; i < n; i++) {
        const uint32_t v = k[i].index;
        if (rest_gap(p, rest + 3 * (size_t)v, &p->node_bone[kept], &p->node_gap[kept]))
            continue;
        p->node_cache[kept].slot[0].bone = p->node_cache[kept].slot[1].bone = UINT32_MAX;
        const float whole = 1.0f;
        anchor_at(p, rest + 3 * (size_t)v, heaviest_joint(st->rig, &v, &whole, 1), &p->node_anchor[kept]);
        p->nodes[kept++] = v;
    }
    p->node_count = kept;
    p->node_clusters = (kept + POSE__PUSH_CLUSTER - 1) / POSE__PUSH_CLUSTER;
    pose__free(a, k);
    const pose_status s = pose__quiet_build(&p->node_quiet, p->node_clusters, p->joint_count, a);
    if (s != POSE_OK)
        return s;
    pose__push_forget(p, nv);
    p->nodes_built = 1;
    return POSE_OK;
}
