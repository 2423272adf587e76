/* SPDX-License-Identifier: Apache-2.0 */
/* Backward Euler dynamics of the co-rotational FEM (fem_dynamics.h). */
#include "fem_dynamics.h"

#include <math.h>
#include <string.h>

#include "rt_thread.h"

static size_t align64(size_t n)
{
    return (n + 63u) & ~(size_t)63u;
}

/* ------------------------------------------------------------ topology */

static int is_dynamic(const pose__fem_mesh *m, size_t v)
{
    return m->corner_offset[v + 1] > m->corner_offset[v] && m->mass[v] > 0.0f;
}

/* Union-find with the smaller index as root: a set's root is its first
 * vertex, so numbering roots in vertex order numbers islands in order. */
static uint32_t find(uint32_t *p, uint32_t a)
{
    while (p[a] != a) {
        p[a] = p[p[a]];
        a = p[a];
    }
    return a;
}

static void unite(uint32_t *p, uint32_t a, uint32_t b)
{
    a = find(p, a);
    b = find(p, b);
    if (a < b)
        p[b] = a;
    else if (b < a)
        p[a] = b;
}

/* Segments of chunk k: runs of one island's vertices (kinematic vertices
 * inside a run do not end it). Writes them when first/isl are given. */
static size_t chunk_segments(const pose__fem_mesh *m, const uint32_t *island, size_t k,
                             uint32_t *first, uint32_t *isl)
{
    size_t b = k * POSE__FEM_CHUNK, e = b + POSE__FEM_CHUNK, n = 0;
    if (e > m->vertex_count)
        e = m->vertex_count;
    uint32_t cur = POSE__FEM_KINEMATIC;
    for (size_t v = b; v < e; v++) {
        if (island[v] == POSE__FEM_KINEMATIC || island[v] == cur)
            continue;
        cur = island[v];
        if (first) {
            first[n] = (uint32_t)v;
            isl[n] = cur;
        }
        n++;
    }
    return n;
}

static void islands_of(const pose__fem_mesh *m, const pose__fem_links *links, uint32_t *p,
                       size_t *island_count, size_t *segment_count)
{
    const size_t nv = m->vertex_count;
    for (size_t v = 0; v < nv; v++)
        p[v] = (uint32_t)v;
    for (size_t t = 0; t < m->tet_count; t++) {
        const uint32_t *tv = m->tets[t].v;
        for (int c = 1; c < 4; c++)
            unite(p, tv[0], tv[c]);
    }
    /* The skin's volume term couples every vertex of the tets it lies in. */
    const pose__fem_surface *s = &m->surface;
    uint32_t anchor = POSE__FEM_KINEMATIC;
    for (size_t i = 0; i < s->vertex_count; i++) {
        const uint32_t *tv = s->tets + 4 * (size_t)s->tet[i];
        for (int c = 0; c < 4; c++) {
            if (!is_dynamic(m, tv[c]))
                continue;
            if (anchor == POSE__FEM_KINEMATIC)
                anchor = tv[c];
            unite(p, anchor, tv[c]);
        }
    }
    /* A soft-soft coupling joins its ends (fem_links.h). */
    for (size_t i = 0; links && i < links->count; i++)
        for (int c = 0; c < 4; c++)
            if (links->weight[4 * i + c] != 0.0f)
                unite(p, links->node[i], links->corner[4 * i + c]);
    for (size_t v = 0; v < nv; v++)
        p[v] = find(p, (uint32_t)v);
    /* p[v] <= v: a root is numbered before its set's other vertices read it */
    uint32_t islands = 0;
    for (size_t v = 0; v < nv; v++) {
        if (!is_dynamic(m, v))
            p[v] = POSE__FEM_KINEMATIC;
        else if (p[v] == v)
            p[v] = islands++;
        else
            p[v] = p[p[v]];
    }
    size_t segs = 0;
    for (size_t k = 0; k < m->chunk_count; k++)
        segs += chunk_segments(m, p, k, NULL, NULL);
    *island_count = islands;
    *segment_count = segs;
}

void pose__fem_dyn_islands(const pose__fem_mesh *m, uint32_t *p, size_t *island_count,
                           size_t *segment_count)
{
    islands_of(m, NULL, p, island_count, segment_count);
}

typedef struct layout {
    size_t island, tet_island, seg_offset, seg_first, seg_island, x, v, bone_prev, stiff, tets,
        rot, f, kv, blk, flag, twist_count, twist, corner, energy, group_sum, group_island, seg_sum,
        isl, alpha, beta, size;
} layout;

static layout layout_of(const pose__fem_mesh *m, size_t islands, size_t segs)
{
    const size_t nv = m->vertex_count, ni = islands > 0 ? islands : 1;
    const size_t nb = pose__fem_dyn_blocks(m), rows = 12 * POSE__FEM_LANES * sizeof(float);
    layout l;
    size_t off = 0;
#define TAKE(field, bytes) (l.field = off, off += align64(bytes))
    TAKE(island, nv * sizeof(uint32_t));
    TAKE(tet_island, nb * POSE__FEM_LANES * sizeof(uint32_t));
    TAKE(seg_offset, (m->chunk_count + 1) * sizeof(uint32_t));
    TAKE(seg_first, segs * sizeof(uint32_t));
    TAKE(seg_island, segs * sizeof(uint32_t));
    TAKE(x, 3 * nv * sizeof(float) + 16); /* slack: the 8-wide gathers (rt_vec.h) */
    TAKE(v, 3 * nv * sizeof(float) + 16);
    TAKE(bone_prev, 3 * nv * sizeof(float));
    TAKE(stiff, nv * sizeof(float));
    TAKE(tets, nb * sizeof(pose__fem_dyn_tets));
    TAKE(rot, nb * sizeof(pose__fem_dyn_rot));
    TAKE(f, nb * rows);
    TAKE(kv, nb * rows);
    TAKE(blk, 2 * nb * rows);
    TAKE(flag, nb * POSE__FEM_LANES * sizeof(uint32_t));
    TAKE(twist_count, pose__fem_dyn_groups(m) * sizeof(uint32_t));
    TAKE(twist,
         pose__fem_dyn_groups(m) * POSE__FEM_GROUP * POSE__FEM_LANES * sizeof(pose__fem_twist));
    TAKE(corner, m->corner_offset[nv] * sizeof(uint32_t));
    TAKE(energy, nb * POSE__FEM_LANES * sizeof(float));
    TAKE(group_sum, pose__fem_dyn_groups(m) * sizeof(double));
    TAKE(group_island, pose__fem_dyn_groups(m) * sizeof(uint32_t));
    TAKE(seg_sum, POSE__FEM_SUMS * segs * sizeof(double));
    TAKE(isl, ni * sizeof(pose__fem_island));
    TAKE(alpha, ni * sizeof(float));
    TAKE(beta, ni * sizeof(float));
#undef TAKE
    l.size = off;
    return l;
}

size_t pose__fem_dyn_size(const pose__fem_mesh *m, size_t islands, size_t segs)
{
    return layout_of(m, islands, segs).size;
}

/* The per-island layout from `island` (pose__fem_dyn_islands' numbering,
 * d->island_count islands and d->segment_count segments): each vertex's,
 * tet's and group's island, the chunks' segments, the islands' mass scale. */
static void topology(const pose__fem_mesh *m, const uint32_t *island, pose__fem_dyn *d)
{
    memcpy(d->island, island, m->vertex_count * sizeof(uint32_t));
    for (size_t t = 0; t < m->tet_count; t++) {
        const uint32_t i = island[m->tets[t].v[0]];
        d->tet_island[t] = i == POSE__FEM_KINEMATIC ? 0 : i; /* massless: never stepped */
    }
    for (size_t g = 0; g < pose__fem_dyn_groups(m); g++) {
        const size_t b0 = g * POSE__FEM_GROUP * POSE__FEM_LANES;
        size_t e0 = b0 + POSE__FEM_GROUP * POSE__FEM_LANES;
        e0 = e0 < m->tet_count ? e0 : m->tet_count;
        d->group_island[g] = d->tet_island[b0];
        for (size_t t = b0; t < e0; t++)
            if (d->tet_island[t] != d->group_island[g])
                d->group_island[g] = POSE__FEM_KINEMATIC; /* mixed */
    }
    size_t n = 0;
    for (size_t k = 0; k < m->chunk_count; k++) {
        d->seg_offset[k] = (uint32_t)n;
        n += chunk_segments(m, island, k, d->seg_first + n, d->seg_island + n);
    }
    d->seg_offset[m->chunk_count] = (uint32_t)n;
    memset(d->isl, 0, d->island_count * sizeof(pose__fem_island));
    for (size_t v = 0; v < m->vertex_count; v++)
        if (island[v] != POSE__FEM_KINEMATIC)
            d->isl[island[v]].mm += 3e-4 * (double)m->mass[v];
}

void pose__fem_dyn_init(const pose__fem_mesh *m, const uint32_t *island, size_t islands,
                        size_t segs, void *memory, pose__fem_dyn *d)
{
    layout l = layout_of(m, islands, segs);
    unsigned char *b = memory;
    memset(b, 0, l.size);
    *d = (pose__fem_dyn){
        .island_count = islands,
        .segment_count = segs,
        .island = (uint32_t *)(b + l.island),
        .tet_island = (uint32_t *)(b + l.tet_island),
        .seg_offset = (uint32_t *)(b + l.seg_offset),
        .seg_first = (uint32_t *)(b + l.seg_first),
        .seg_island = (uint32_t *)(b + l.seg_island),
        .x = (float *)(b + l.x),
        .v = (float *)(b + l.v),
        .bone_prev = (float *)(b + l.bone_prev),
        .stiff = (float *)(b + l.stiff),
        .tets = (pose__fem_dyn_tets *)(b + l.tets),
        .rot = (pose__fem_dyn_rot *)(b + l.rot),
        .f = (float *)(b + l.f),
        .kv = (float *)(b + l.kv),
        .blk = (float *)(b + l.blk),
        .flag = (uint32_t *)(b + l.flag),
        .twist_count = (uint32_t *)(b + l.twist_count),
        .twist = (pose__fem_twist *)(b + l.twist),
        .corner = (uint32_t *)(b + l.corner),
        .energy = (float *)(b + l.energy),
        .group_sum = (double *)(b + l.group_sum),
        .group_island = (uint32_t *)(b + l.group_island),
        .seg_sum = (double *)(b + l.seg_sum),
        .isl = (pose__fem_island *)(b + l.isl),
        .alpha = (float *)(b + l.alpha),
        .beta = (float *)(b + l.beta),
    };
    pose__fem_dyn_tets_build(m, d->tets, d->rot);
    for (size_t k = 0; k < m->corner_offset[m->vertex_count]; k++)
        d->corner[k] = (uint32_t)pose__fem_dyn_corner(m->corners[k], 12);
    topology(m, island, d);
    /* Each vertex's stiffness at rest (the trace / 3 of its 3x3 block,
     * invariant under rotation): what the bone springs are scaled by. */
    for (size_t t = 0; t < m->tet_count; t++) {
        const pose__fem_tet *tt = &m->tets[t];
        for (int c = 0; c < 4; c++) {
            float g[3];
            for (int a = 0; a < 3; a++)
                g[a] = c == 0 ? -(tt->b[a] + tt->b[3 + a] + tt->b[6 + a]) : tt->b[3 * (c - 1) + a];
            const double gg = (double)g[0] * g[0] + (double)g[1] * g[1] + (double)g[2] * g[2];
            d->stiff[tt->v[c]] +=
                (float)(tt->vmu * gg + ((double)tt->vkappa + tt->vmu / 3.0) * gg / 3.0);
        }
    }
}

void pose__fem_dyn_link(const pose__fem_mesh *m, const pose__fem_links *links, uint32_t *scratch,
                        pose__fem_dyn *d)
{
    size_t ni, ns; /* at most the block's: linking only merges islands and their runs */
    islands_of(m, links, scratch, &ni, &ns);
    d->island_count = ni;
    d->segment_count = ns;
    topology(m, scratch, d);
}

void pose__fem_dyn_reset(const pose__fem_mesh *m, pose__fem_dyn *d, const float *bones)
{
    const size_t n = 3 * m->vertex_count;
    memcpy(d->x, bones, n * sizeof(float));
    memcpy(d->bone_prev, bones, n * sizeof(float));
    memset(d->v, 0, n * sizeof(float));
    pose__fem_dyn_rot_reset(m, d->rot);
}

/* ------------------------------------------------------------ passes */

enum { PASS_ROTATE, PASS_RESIDUAL, PASS_PRODUCT, PASS_UPDATE, PASS_INTEGRATE };

typedef struct step_ctx {
    const pose__fem_mesh *mesh;
    pose__fem_work *w;
    pose__fem_dyn *d;
    const pose__fem_dyn_params *prm;
    const float *bones;
    int pass;
    float mscale;    /**< 1 + dt alpha: A's mass factor */
    float kscale;    /**< dt beta + dt^2: A's stiffness factor */
    float vol_force; /**< the volume term's force factor at x */
} step_ctx;

/* Sum of vertex v's corner values in a 12-row output (fem_dyn_tets.h), in
 * the mesh's fixed corner order: even and odd corners apart, then added
 * (two chains of dependent adds instead of one: the vertex passes wait on
 * them, not on the loads). */
static inline void gather(const pose__fem_mesh *m, const uint32_t *off, const float *rows,
                          size_t v, float out[3])
{
    float s[2][3] = {{0, 0, 0}, {0, 0, 0}};
    uint32_t k = m->corner_offset[v];
    const uint32_t e = m->corner_offset[v + 1];
    for (; k + 1 < e; k += 2)
        for (int h = 0; h < 2; h++) {
            const float *f = rows + off[k + (uint32_t)h];
            s[h][0] += f[0];
            s[h][1] += f[POSE__FEM_LANES];
            s[h][2] += f[2 * POSE__FEM_LANES];
        }
    if (k < e) {
        const float *f = rows + off[k];
        s[0][0] += f[0];
        s[0][1] += f[POSE__FEM_LANES];
        s[0][2] += f[2 * POSE__FEM_LANES];
    }
    out[0] = s[0][0] + s[1][0];
    out[1] = s[0][1] + s[1][1];
    out[2] = s[0][2] + s[1][2];
}

/* Vertex v's 3x3 stiffness block (xx xy xz yy yz zz) from the corners'
 * (corner k's 24-row offset from its 12-row one: same block and lane). */
static inline void vertex_block(const pose__fem_mesh *m, const uint32_t *off, const float *blk,
                                size_t v, double k[6])
{
    for (int e = 0; e < 6; e++)
        k[e] = 0.0;
    for (uint32_t i = m->corner_offset[v]; i < m->corner_offset[v + 1]; i++) {
        const float *b = blk + 2 * (size_t)off[i] - (off[i] & (POSE__FEM_LANES - 1));
        for (int e = 0; e < 6; e++)
            k[e] += b[e * POSE__FEM_LANES];
    }
}

/* Zero-length spring stiffness of a bone node (held vertices are the ones
 * whose Jacobi weight the mesh left at zero), or of a coupled vertex (its
 * target in `bones` too), else 0. */
static inline float spring_of(const step_ctx *c, size_t v)
{
    return c->mesh->inv_diag[v] == 0.0f ? c->prm->coupling * c->d->stiff[v]
           : c->prm->spring             ? c->prm->spring[v]
                                        : 0.0f;
}

/* Vertex v's resting contacts' stiffness S (pose__fem_dyn_contact), or
 * NULL. */
static inline const float *contact_of(const step_ctx *c, size_t v)
{
    return c->prm->contact && c->prm->contact->on[v] ? c->prm->contact->stiff + 6 * v : NULL;
}

/* A vertex's dot product in double (the passes sum them in double). */
static inline double dot3(const float *a, const float *b)
{
    return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
}

/* kscale u^T S u of a vertex's resting contacts (cs NULL: none): their
 * part of u^T D u. */
static inline double contact_energy(const step_ctx *c, const float *cs, const float *u)
{
    if (!cs)
        return 0.0;
    float su[3];
    pose__fem_apply_block(cs, u, su);
    return (double)c->kscale * dot3(su, u);
}

/* The warm start's residual r = b - A v, b = M v + dt f, with f every
 * force at x but the damping (the spring pulls toward the bone where it is
 * at the end of the step, its damping acts on the velocity relative to the
 * bone's); the preconditioner P (inverse blocks of A); u = P r; p = s = 0.
 * Sums: r.u, r.r, b^T P b, u.(D u), g.u. */
static void residual_vertex(const step_ctx *c, size_t v, float vp, double sum[POSE__FEM_SUMS])
{
    const pose__fem_mesh *m = c->mesh;
    pose__fem_work *w = c->w;
    const pose__fem_dyn *d = c->d;
    const pose__fem_dyn_params *prm = c->prm;
    const float dt = prm->dt, mass = m->mass[v], ks = spring_of(c, v);
    float *r = w->r + 3 * v, *u = w->z + 3 * v, *pre = w->pre + 6 * v;
    const float *vel = d->v + 3 * v, *gv = w->gvol + 3 * v, *x = d->x + 3 * v;
    const float *bo = c->bones + 3 * v, *bp = d->bone_prev + 3 * v;
    /* the soft-soft couplings (fem_links.h; zero where none reaches):
     * their force -K_l x and K_l v, formed before the pass, and diagonal */
    const pose__fem_links *l = prm->links;
    const float kl = l ? l->diag[v] : 0.0f;
    float f[3], kv[3], bv[3], pb[3];
    gather(m, d->corner, d->f, v, f);
    gather(m, d->corner, d->kv, v, kv);
    /* resting contacts: their force and their share of A v */
    const float *cs = contact_of(c, v), *cg = cs ? prm->contact->force + 3 * v : NULL;
    float sv[3] = {0, 0, 0};
    if (cs)
        pose__fem_apply_block(cs, vel, sv);
    for (int a = 0; a < 3; a++) {
        float fa = f[a] + c->vol_force * gv[a] + mass * prm->gravity[a] + ks * (bo[a] - x[a]) +
                   prm->beta * ks * (bo[a] - bp[a]) / dt + (cg ? cg[a] : 0.0f);
        float ka = kv[a] + ks * vel[a] + sv[a];
        if (l) {
            fa -= l->out[3 * v + (size_t)a];
            ka += l->out2[3 * v + (size_t)a];
        }
        bv[a] = mass * vel[a] + dt * fa;
        r[a] = dt * fa - (c->mscale - 1.0f) * mass * vel[a] - c->kscale * ka - vp * gv[a];
        w->p[3 * v + a] = w->ap[3 * v + a] = 0.0f;
    }
    double k[6];
    vertex_block(m, d->corner, d->blk, v, k);
    for (int e6 = 0; cs && e6 < 6; e6++)
        k[e6] += cs[e6];
    for (int e6 = 0; e6 < 6; e6++)
        k[e6] *= c->kscale;
    const double diag = (double)c->mscale * mass + (double)c->kscale * (ks + kl);
    k[0] += diag;
    k[3] += diag;
    k[5] += diag;
    if (pose__fem_invert_block(k, pre) < 0) {
        pre[0] = pre[3] = pre[5] = (float)(1.0 / diag);
        pre[1] = pre[2] = pre[4] = 0.0f;
    }
    pose__fem_apply_block(pre, bv, pb);
    pose__fem_apply_block(pre, r, u);
    const float dd = c->mscale * mass + c->kscale * ks;
    sum[0] += dot3(r, u);
    sum[1] += dot3(r, r);
    sum[2] += dot3(bv, pb);
    sum[3] += dd * dot3(u, u) + contact_energy(c, cs, u);
    sum[4] += dot3(gv, u);
}

/* One Chronopoulos-Gear CG iteration at a vertex: w = A u (the gathered
 * K u with the couplings' K_l u, the diagonal D = mscale M + kscale K_s, the volume term's rank one
 * vp g), p = u + beta p, s = w + beta s (= A p), v += alpha p,
 * r -= alpha s, u = P r. Sums: r.u, r.r, -, u.(D u), g.u. */
static void update_vertex(const step_ctx *c, size_t v, float alpha, float beta, float vp,
                          double sum[POSE__FEM_SUMS])
{
    const pose__fem_mesh *m = c->mesh;
    pose__fem_work *w = c->w;
    const float mass = m->mass[v], ks = spring_of(c, v), dd = c->mscale * mass + c->kscale * ks;
    float *r = w->r + 3 * v, *u = w->z + 3 * v, *p = w->p + 3 * v, *sv = w->ap + 3 * v;
    float *vel = c->d->v + 3 * v;
    const float *gv = w->gvol + 3 * v;
    const float *cs = contact_of(c, v);
    /* K_l u, formed between the product and this pass (fem_links.h) */
    const float *lu = c->prm->links ? c->prm->links->out + 3 * v : NULL;
    float f[3], su[3] = {0, 0, 0};
    gather(m, c->d->corner, c->d->f, v, f);
    if (cs)
        pose__fem_apply_block(cs, u, su);
    for (int a = 0; a < 3; a++) {
        if (lu)
            f[a] += lu[a];
        const float wa = c->mscale * mass * u[a] + c->kscale * (f[a] + ks * u[a] + su[a]) + vp * gv[a];
        p[a] = u[a] + beta * p[a];
        sv[a] = wa + beta * sv[a];
        vel[a] += alpha * p[a];
        r[a] -= alpha * sv[a];
    }
    pose__fem_apply_block(w->pre + 6 * v, r, u);
    sum[0] += dot3(r, u);
    sum[1] += dot3(r, r);
    sum[3] += dd * dot3(u, u) + contact_energy(c, cs, u);
    sum[4] += dot3(gv, u);
}

/* A vertex pass over segment s (vertices [seg_first[s], e) of its island). */
static void segment_pass(step_ctx *c, size_t s, size_t e)
{
    pose__fem_dyn *d = c->d;
    const uint32_t i = d->seg_island[s];
    const pose__fem_island *is = &d->isl[i];
    const float alpha = d->alpha[i], beta = d->beta[i];
    /* the volume term's product scale: kscale kappa_g (g . u) */
    const float vp = (float)(c->kscale * c->mesh->surface.stiffness * is->gu);
    double sum[POSE__FEM_SUMS] = {0};
    if (c->pass == PASS_RESIDUAL || is->active)
        for (size_t v = d->seg_first[s]; v < e; v++) {
            if (d->island[v] != i)
                continue;
            if (c->pass == PASS_RESIDUAL)
                residual_vertex(c, v, vp, sum);
            else
                update_vertex(c, v, alpha, beta, vp, sum);
        }
    memcpy(d->seg_sum + POSE__FEM_SUMS * s, sum, sizeof sum);
}

/* x += dt v for the simulated vertices; the others move with their bone.
 * Kinetic energy summed per chunk (work->partial). */
static void integrate_chunk(step_ctx *c, size_t k)
{
    const pose__fem_mesh *m = c->mesh;
    pose__fem_dyn *d = c->d;
    const float dt = c->prm->dt;
    size_t b = k * POSE__FEM_CHUNK, e = b + POSE__FEM_CHUNK;
    if (e > m->vertex_count)
        e = m->vertex_count;
    double ke = 0.0;
    for (size_t v = b; v < e; v++) {
        float *x = d->x + 3 * v, *vel = d->v + 3 * v, *bp = d->bone_prev + 3 * v;
        const float *bo = c->bones + 3 * v;
        if (d->island[v] == POSE__FEM_KINEMATIC) {
            for (int a = 0; a < 3; a++) {
                vel[a] = (bo[a] - x[a]) / dt;
                x[a] = bo[a];
            }
        } else {
            for (int a = 0; a < 3; a++) {
                x[a] += dt * vel[a];
                ke += 0.5 * m->mass[v] * (double)vel[a] * vel[a];
            }
        }
        bp[0] = bo[0];
        bp[1] = bo[1];
        bp[2] = bo[2];
    }
    c->w->partial[4 * k] = ke;
}

/* K u for group g's tets, and when they are one island's, the sum of
 * their u^T K u in tet order. */
static void product_group(const pose__fem_mesh *m, pose__fem_work *w, pose__fem_dyn *d, size_t g)
{
    const size_t nb = pose__fem_dyn_blocks(m), b = g * POSE__FEM_GROUP;
    const size_t e = b + POSE__FEM_GROUP < nb ? b + POSE__FEM_GROUP : nb;
    pose__fem_dyn_product(d->tets, d->rot, w->z, d->f, d->energy, b, e);
    pose__fem_dyn_twist_product(d->tets, d->rot, d->twist + g * POSE__FEM_GROUP * POSE__FEM_LANES,
                                d->twist_count[g], w->z, d->f, d->energy);
    if (d->group_island[g] == POSE__FEM_KINEMATIC)
        return;
    double sum = 0.0;
    for (size_t t = b * POSE__FEM_LANES; t < e * POSE__FEM_LANES; t++)
        sum += d->energy[t]; /* padding lanes add +0 */
    d->group_sum[g] = sum;
}

/* Most rotation extraction steps per tet and step (fem_solve.c's count:
 * warm-started, most tets converge in a few; the rest go on next step). */
#define FEM_POLAR_STEPS 8

/* The skin volume term at x: its gradient (work->gvol), force factor and
 * g . v per island for the warm start's product (serial code, one order:
 * one item of the rotate pass, running beside the tets). */
static void volume_item(step_ctx *c)
{
    const pose__fem_mesh *m = c->mesh;
    pose__fem_dyn *d = c->d;
    c->vol_force = (float)pose__fem_volume_gradient(m, c->w, d->x);
    for (size_t i = 0; i < d->island_count; i++)
        d->isl[i].gu = 0.0;
    if (m->surface.vertex_count == 0)
        return;
    for (size_t v = 0; v < m->vertex_count; v++) {
        const float *g = c->w->gvol + 3 * v, *vel = d->v + 3 * v;
        if (d->island[v] != POSE__FEM_KINEMATIC)
            d->isl[d->island[v]].gu +=
                (double)g[0] * vel[0] + (double)g[1] * vel[1] + (double)g[2] * vel[2];
    }
}

/* Items of a pass: tet passes take groups of POSE__FEM_GROUP blocks (the
 * rotate pass the volume term first), vertex passes chunks. */
static size_t pass_items(const step_ctx *c)
{
    const size_t ng = pose__fem_dyn_groups(c->mesh);
    return c->pass == PASS_ROTATE ? 1 + ng : c->pass == PASS_PRODUCT ? ng : c->mesh->chunk_count;
}

static void pass_item(void *ctx, size_t item)
{
    step_ctx *c = ctx;
    const pose__fem_mesh *m = c->mesh;
    pose__fem_dyn *d = c->d;
    if (c->pass == PASS_ROTATE) { /* with K v: the warm start's product */
        if (item == 0) {
            volume_item(c);
            return;
        }
        const size_t g = item - 1, nb = pose__fem_dyn_blocks(m), b = g * POSE__FEM_GROUP;
        const size_t e = b + POSE__FEM_GROUP < nb ? b + POSE__FEM_GROUP : nb;
        pose__fem_dyn_rotate(d->tets, d->rot, d->x, c->prm->joint_q, d->v, FEM_POLAR_STEPS,
                             POSE__FEM_TWIST, d->f, d->kv, d->blk, d->flag, b, e);
        d->twist_count[g] = (uint32_t)pose__fem_dyn_twist_build(
            d->tets, d->rot, d->flag, d->x, d->v, d->kv, d->blk, b, e,
            d->twist + g * POSE__FEM_GROUP * POSE__FEM_LANES);
        return;
    }
    if (c->pass == PASS_PRODUCT) {
        product_group(m, c->w, d, item);
        return;
    }
    if (c->pass == PASS_INTEGRATE) {
        integrate_chunk(c, item);
        return;
    }
    size_t chunk_end = (item + 1) * POSE__FEM_CHUNK;
    if (chunk_end > m->vertex_count)
        chunk_end = m->vertex_count;
    for (uint32_t s = d->seg_offset[item]; s < d->seg_offset[item + 1]; s++)
        segment_pass(c, s, s + 1 < d->seg_offset[item + 1] ? d->seg_first[s + 1] : chunk_end);
}

/* Below this many tets the caller works alone (as pose__fem_solve). */
#define FEM_SERIAL_TETS 4096u

/* One pass; the vertex passes' sums land in each island's sum[], added
 * segment after segment (the same order for any thread count). */
static void run(step_ctx *c, pose__pool *pool, int pass)
{
    c->pass = pass;
    const size_t n = pass_items(c);
    if (pool && pose__pool_threads(pool) > 1 && c->mesh->tet_count >= FEM_SERIAL_TETS)
        pose__pool_run_items(pool, pass_item, c, n);
    else
        for (size_t i = 0; i < n; i++)
            pass_item(c, i);
    pose__fem_dyn *d = c->d;
    if (pass == PASS_PRODUCT) { /* the tets' u^T K u per island, group after group */
        for (size_t i = 0; i < d->island_count; i++)
            d->isl[i].tet = 0.0;
        for (size_t g = 0; g < pose__fem_dyn_groups(c->mesh); g++) {
            if (d->group_island[g] != POSE__FEM_KINEMATIC) {
                d->isl[d->group_island[g]].tet += d->group_sum[g];
                continue;
            }
            const size_t b = g * POSE__FEM_GROUP * POSE__FEM_LANES;
            const size_t e = b + POSE__FEM_GROUP * POSE__FEM_LANES;
            for (size_t t = b; t < e && t < c->mesh->tet_count; t++)
                d->isl[d->tet_island[t]].tet += d->energy[t];
        }
        return;
    }
    if (pass != PASS_RESIDUAL && pass != PASS_UPDATE)
        return;
    for (size_t i = 0; i < d->island_count; i++)
        memset(d->isl[i].sum, 0, sizeof d->isl[i].sum);
    for (size_t s = 0; s < d->segment_count; s++) {
        double *sum = d->isl[d->seg_island[s]].sum;
        for (int k = 0; k < POSE__FEM_SUMS; k++)
            sum[k] += d->seg_sum[POSE__FEM_SUMS * s + k];
    }
}

/* The soft-soft couplings' K_l u for the update pass and each island's
 * u^T K_l u (vertex after vertex: one order for any thread count), while u
 * holds still between the product and the update. */
static void links_product(step_ctx *c)
{
    const pose__fem_links *l = c->prm->links;
    pose__fem_dyn *d = c->d;
    for (size_t i = 0; i < d->island_count; i++)
        d->isl[i].link = 0.0;
    if (!l)
        return;
    pose__fem_links_product(l, c->w->z, NULL, 0.0f, l->out);
    for (size_t i = 0; i < l->touched_count; i++) {
        const size_t v = l->touched[i];
        if (d->island[v] != POSE__FEM_KINEMATIC) /* massless: never stepped */
            d->isl[d->island[v]].link += dot3(c->w->z + 3 * v, l->out + 3 * v);
    }
}

static double now(void)
{
    return 1e-9 * (double)pose__now_ns();
}

void pose__fem_dyn_step(const pose__fem_mesh *m, pose__fem_work *w, pose__fem_dyn *d,
                        pose__pool *pool, const pose__fem_dyn_params *prm, const float *bones,
                        pose__fem_dyn_stats *stats)
{
    pose__fem_dyn_stats st = {0};
    const double dt = prm->dt;
    step_ctx c = {.mesh = m, .w = w, .d = d, .prm = prm, .bones = bones,
                  .mscale = (float)(1.0 + dt * prm->alpha),
                  .kscale = (float)(dt * prm->beta + dt * dt)};
    const double t0 = now();
    const size_t ni = d->island_count;
    const double kg = c.kscale * m->surface.stiffness; /* the volume term's product factor */
    for (size_t i = 0; i < (ni > 0 ? ni : 1); i++)
        d->beta[i] = d->alpha[i] = 0.0f;
    for (size_t i = 0; i < ni; i++) {
        d->isl[i].active = 0;
        d->isl[i].iterations = 0;
    }
    /* Assembly: rotations, elastic forces at x and K v in one pass over the
     * tets (the skin's volume term as one more item), then per vertex the right-hand side, the preconditioner (blocks
     * of A) and the residual of the warm start v. */
    run(&c, pool, PASS_ROTATE); /* with the volume term beside the tets */
    if (prm->links) { /* K_l x and K_l v for the residual pass (fem_links.h: one thread) */
        pose__fem_links_product(prm->links, d->x, NULL, 0.0f, prm->links->out);
        pose__fem_links_product(prm->links, d->v, NULL, 0.0f, prm->links->out2);
    }
    run(&c, pool, PASS_RESIDUAL);
    const double tol2 = (double)prm->tolerance * prm->tolerance;
    int any = 0;
    for (size_t i = 0; i < ni; i++) {
        pose__fem_island *is = &d->isl[i];
        is->rz = is->sum[0];
        is->rr = is->sum[1];
        is->bb = is->sum[2];
        is->dm = is->sum[3];
        is->gu = is->sum[4];
        /* In the preconditioner's norm (P about A^-1: r^T P r measures
         * the velocity error by its energy, b^T P b about twice the kinetic
         * energy of the momentum b), relative to b's, but never below the
         * island's kinetic energy at 1e-2 rig units per second: at rest b
         * is rounding noise, not a scale. Unlike |r| <= tol |b|, light
         * vertices' errors count by their own mass. */
        is->stop = tol2 * (is->bb > is->mm ? is->bb : is->mm);
        is->active = is->rz > is->stop;
        any |= is->active;
    }
    const double t1 = now();
    st.seconds_assembly = t1 - t0;

    /* CG per island, Chronopoulos-Gear's form: one product A u per
     * iteration (u = P r), whose u^T A u the tets sum as they form it, so
     * the step length is known before the one vertex pass that updates
     * p, A p, v, r and u (two passes and one reduction per iteration
     * where plain CG takes three and two). */
    for (int it = 0; it < prm->cg_iterations && any; it++) {
        run(&c, pool, PASS_PRODUCT);
        links_product(&c);
        for (size_t i = 0; i < ni; i++) {
            pose__fem_island *is = &d->isl[i];
            if (!is->active)
                continue;
            const double uau = c.kscale * (is->tet + is->link) + is->dm + kg * is->gu * is->gu;
            const double den = is->iterations == 0 ? uau : uau - d->beta[i] * is->rz / is->alpha;
            if (!(den > 0.0)) {
                is->active = 0;
                continue;
            }
            is->alpha = is->rz / den;
            d->alpha[i] = (float)is->alpha;
        }
        run(&c, pool, PASS_UPDATE);
        any = 0;
        for (size_t i = 0; i < ni; i++) {
            pose__fem_island *is = &d->isl[i];
            if (!is->active)
                continue;
            const double rz = is->sum[0];
            is->rr = is->sum[1];
            is->dm = is->sum[3];
            is->gu = is->sum[4];
            is->iterations++;
            d->beta[i] = (float)(rz / is->rz);
            is->rz = rz;
            is->active = rz > is->stop;
            any |= is->active;
        }
    }
    double t2 = now();
    st.seconds_cg = t2 - t1;
    if (prm->constrain) {
        prm->constrain(prm->constrain_ctx);
        const double t3 = now();
        st.seconds_constrain = t3 - t2;
        t2 = t3;
    }
    run(&c, pool, PASS_INTEGRATE);
    for (size_t k = 0; k < m->chunk_count; k++)
        st.kinetic_energy += w->partial[4 * k];
    for (size_t i = 0; i < ni; i++) {
        const pose__fem_island *is = &d->isl[i];
        if (is->iterations > st.cg_iterations)
            st.cg_iterations = is->iterations;
        const double scale = is->bb > is->mm ? is->bb : is->mm;
        const double res = scale > 0.0 ? sqrt(is->rz / scale) : 0.0;
        if (res > st.residual)
            st.residual = res;
    }
    st.seconds_assembly += now() - t2;
    if (stats)
        *stats = st;
}

double pose__fem_dyn_bytes(const pose__fem_mesh *m, double cg_iterations)
{
    const double nt = (double)m->tet_count, nv = (double)m->vertex_count;
    /* per tet: rotate (block constants 96: 60, the skeletal mask 4 and a
     * skeletal tet's joints and weights 32; quaternion r+w 32, matrix 36,
     * x and v at 4 corners 96, forces, K v and blocks 192, the twist flag
     * written and read 8), and the residual pass's gathers of its 4
     * corners (index 4 + forces 12 + K v 12 + block 24 each); per vertex:
     * the forces and residual passes (~112 each) and the integration (80).
     * The few flagged tets' twists (fem_dyn_twist.h) are left out. */
    const double assembly = nt * (96.0 + 32.0 + 36.0 + 96.0 + 192.0 + 8.0 + 4.0 * 52.0) +
                            nv * (112.0 + 112.0 + 80.0);
    /* per iteration: product (block constants 60, rotation 36, u at 4
     * corners 48, products 48, energy 4), the gather of its corners
     * (4 x (offset 4 + 12)), and the one vertex pass (reads u p s v r 60,
     * preconditioner 24, volume gradient 12, mass, weight, stiffness,
     * island and corner range 20; writes u p s v r 60) */
    const double iteration = nt * (196.0 + 64.0) + nv * 176.0;
    return assembly + cg_iterations * iteration;
}
