/* SPDX-License-Identifier: Apache-2.0
 * One posed tet into the output grid (pose_volume_sample's slab pass),
 * compiled twice: volume_raster.c (generic) and volume_raster_avx2.c
 * (-mavx2, used when the CPU has it). Both do the same IEEE operations in
 * the same order (no -mfma), so they give the same bytes.
 *
 * In output index space a tet's barycentric coordinates are affine in
 * (i, j, k), and so is the preimage in the rest image's index space. Per
 * tet: the inverse map once (double). Per row (j, k): the span of i inside
 * the tet from the four coordinates' bounds, each itself affine in j (four
 * lanes of one multiply-add, no division, no inside test per voxel), and
 * the preimage of the span's first voxel; the rows a plane's section spans
 * come from the same bounds taken pairwise. Per voxel: queued with its
 * preimage (three multiply-adds) for the gather (volume_gather.c), which
 * samples the trilinear intensity and the nearest label, for the voxels no
 * tet covered before. Expects POSE__VR(name) to name the variant. */
#include <math.h>
#include <string.h>

#include "rt_vec.h" /* POSE__INLINE */
#include "volume_internal.h"

/* The preimages of a row's span: voxel ia + u maps to r + m u (from ia
 * whichever run of the span is sampled, so a voxel's value does not
 * depend on the runs). */
typedef struct span {
    float rx, ry, rz, mx, my, mz;
    int ia, ib, j, k;
    uint16_t block; /* the tet's block (the rest cover's owner while it is built) */
} span;

/* Four floats (SSE2 everywhere x86-64 and ARMv8 run): a run's preimages
 * four at a time. */
typedef float v4f __attribute__((vector_size(16)));
typedef uint32_t v4u __attribute__((vector_size(16)));

/* Queues voxels i0..i1 of output row `row`, four at a time: a run of up
 * to four, the common case, is one set of vector stores (the queue's slack
 * takes the surplus), not a loop whose length the branch predictor would
 * have to guess. Preimages r + m u with u = i - ia (small integers, exact
 * in float), whichever run of the span a voxel falls in. */
static POSE__INLINE void queue_run(const pose_volume_sampler *s, pose__vol_stage *st,
                                   const span *sp, int i0, int i1, size_t row)
{
    const v4f lane = {0.0f, 1.0f, 2.0f, 3.0f};
    const v4u lane_u = {0, 1, 2, 3};
    const int len = i1 - i0 + 1;
    for (int at = 0; at < len; at += 4) {
        const unsigned n = st->n;
        const v4f u = lane + (float)(i0 + at - sp->ia);
        const v4u idx = lane_u + (uint32_t)(row + (size_t)(i0 + at));
        const v4f x = sp->rx + sp->mx * u, y = sp->ry + sp->my * u, z = sp->rz + sp->mz * u;
        memcpy(st->at + n, &idx, sizeof idx);
        memcpy(st->x + n, &x, sizeof x);
        memcpy(st->y + n, &y, sizeof y);
        memcpy(st->z + n, &z, sizeof z);
        st->n = n + (unsigned)(len - at < 4 ? len - at : 4);
        if (st->n >= POSE__VOL_STAGE)
            pose__volume_gather(s, st);
    }
}

/* Voxels i0..i1 of output row (j, k) of a tet that lies where it rests
 * (pose__vol_box.identity): each is its own preimage, so it takes the rest
 * voxel's intensity and label as they are (what the gather would give at
 * an exact voxel centre, without the inverse map's rounding), background
 * where the output grid reaches past the rest image. */
static void copy_run(const pose_volume_sampler *s, const span *sp, int i0, int i1, size_t row)
{
    if (s->owner_building) { /* the rest pose, rasterized once at creation */
        for (int i = i0; i <= i1; i++)
            s->owner[row + (size_t)i] = sp->block;
        return;
    }
    const int j = sp->j, k = sp->k;
    const pose_volume_desc *r = &s->rest;
    const int nx = (int)r->grid.nx;
    const int last = (uint32_t)j < r->grid.ny && (uint32_t)k < r->grid.nz ? (i1 < nx ? i1 : nx - 1)
                                                                          : i0 - 1;
    const size_t src = ((size_t)k * r->grid.ny + (size_t)j) * (size_t)nx;
    float *oi = s->dst_intensity;
    uint16_t *ol = s->dst_labels;
    for (int i = i0; i <= i1; i++) {
        if (oi)
            oi[row + (size_t)i] = i <= last ? r->intensity[src + (size_t)i] : r->intensity_background;
        if (ol)
            ol[row + (size_t)i] = i <= last ? r->labels[src + (size_t)i] : r->label_background;
    }
}

/* Samples voxels i0..i1 of a row: queued for the gather, or copied when
 * the tet lies where it rests (identity, constant per tet). */
static POSE__INLINE void sample_run(const pose_volume_sampler *s, pose__vol_stage *st,
                                    const span *sp, int identity, int i0, int i1, size_t row)
{
    if (identity)
        copy_run(s, sp, i0, i1, row);
    else
        queue_run(s, st, sp, i0, i1, row);
}

/* The general case of cover_span: a span over several words of the row,
 * or one some of whose voxels an earlier tet covered (out of line: it
 * keeps the common case's loop small). */
static __attribute__((noinline)) void cover_words(const pose_volume_sampler *s,
                                                  pose__vol_stage *st, const span *sp, int identity,
                                                  uint64_t *w, size_t row)
{
    const int a = sp->ia >> 6, b = sp->ib >> 6;
    const uint64_t first = ~(uint64_t)0 << (sp->ia & 63), last = ~(uint64_t)0 >> (63 - (sp->ib & 63));
    for (int x = a; x <= b; x++) {
        const uint64_t m = (x == a ? first : ~(uint64_t)0) & (x == b ? last : ~(uint64_t)0);
        uint64_t open = m & ~w[x];
        w[x] |= m;
        while (open) {
            const int lo = __builtin_ctzll(open);
            const uint64_t after = ~(open >> lo);
            const int len = after ? __builtin_ctzll(after) : 64 - lo;
            sample_run(s, st, sp, identity, 64 * x + lo, 64 * x + lo + len - 1, row);
            open = lo + len < 64 ? open & (~(uint64_t)0 << (lo + len)) : 0;
        }
    }
}

/* Marks voxels ia..ib of a row covered (its words w) and samples, in runs,
 * those no tet rasterized before covered: a voxel inside two posed tets (a
 * centre on a face two tets share, or where the deformation folds) is
 * sampled once, by the first tet the slab visits (the later in index
 * order), whatever the slab split. */
static POSE__INLINE void cover_span(const pose_volume_sampler *s, pose__vol_stage *st,
                                    const span *sp, int identity, uint64_t *w, size_t row)
{
    const int a = sp->ia >> 6;
    const uint64_t m = (~(uint64_t)0 << (sp->ia & 63)) & (~(uint64_t)0 >> (63 - (sp->ib & 63)));
    if (a == sp->ib >> 6 && !(w[a] & m)) { /* the common case: one word, nothing covered yet */
        w[a] |= m;
        sample_run(s, st, sp, identity, sp->ia, sp->ib, row);
    } else {
        cover_words(s, st, sp, identity, w, row);
    }
}

/* ceil / floor of a value within the int range (callers clamp first). */
static inline int iceil(double x)
{
    int i = (int)x;
    return i + ((double)i < x);
}

static inline int ifloor(double x)
{
    int i = (int)x;
    return i - ((double)i > x);
}

static inline double det3(const double m[3][3])
{
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

static inline double maxd(double a, double b)
{
    return a > b ? a : b;
}

static inline double mind(double a, double b)
{
    return a < b ? a : b;
}

/* Four doubles, one per barycentric coordinate (or per pair of them):
 * the row bounds of a tet as a few vector operations instead of a dozen
 * scalars the compiler spills. One AVX register where the variant has
 * AVX, two SSE2/NEON registers otherwise (a 32-byte vector type there
 * would be lowered through memory). */
#ifdef __AVX__
typedef double v4d __attribute__((vector_size(32)));
static inline v4d v4_load(const double p[4])
{
    v4d v;
    memcpy(&v, p, sizeof v);
    return v;
}
static inline v4d v4_madd(v4d a, v4d b, double s) /* a + b s */
{
    return a + b * s;
}
static inline double v4_max(v4d v, v4d add) /* max over the lanes of v + add */
{
    v4d w = v + add;
    return maxd(maxd(w[0], w[1]), maxd(w[2], w[3]));
}
static inline double v4_min(v4d v, v4d add)
{
    v4d w = v + add;
    return mind(mind(w[0], w[1]), mind(w[2], w[3]));
}
static inline double v4_lane(v4d v, int c)
{
    return v[c];
}
#else
typedef double v2d __attribute__((vector_size(16)));
typedef struct v4d {
    v2d lo, hi;
} v4d;
static inline v4d v4_load(const double p[4])
{
    v4d v;
    memcpy(&v.lo, p, sizeof v.lo);
    memcpy(&v.hi, p + 2, sizeof v.hi);
    return v;
}
static inline v4d v4_madd(v4d a, v4d b, double s)
{
    return (v4d){a.lo + b.lo * s, a.hi + b.hi * s};
}
static inline double v4_max(v4d v, v4d add)
{
    v2d l = v.lo + add.lo, h = v.hi + add.hi;
    return maxd(maxd(l[0], l[1]), maxd(h[0], h[1]));
}
static inline double v4_min(v4d v, v4d add)
{
    v2d l = v.lo + add.lo, h = v.hi + add.hi;
    return mind(mind(l[0], l[1]), mind(h[0], h[1]));
}
static inline double v4_lane(v4d v, int c)
{
    return c < 2 ? v.lo[c] : v.hi[c - 2];
}
#endif

/* For each set of coordinates that bound i from below (bit c set: d_c > 0),
 * the pairs (below, above) whose bounds meet, which bound the rows of a
 * plane (at most 2 x 2 of them). */
static const struct {
    uint8_t n, pair[4][2];
} k_pairs[16] = {
    {0, {{0, 0}}},
    {3, {{0, 1}, {0, 2}, {0, 3}}},
    {3, {{1, 0}, {1, 2}, {1, 3}}},
    {4, {{0, 2}, {0, 3}, {1, 2}, {1, 3}}},
    {3, {{2, 0}, {2, 1}, {2, 3}}},
    {4, {{0, 1}, {0, 3}, {2, 1}, {2, 3}}},
    {4, {{1, 0}, {1, 3}, {2, 0}, {2, 3}}},
    {3, {{0, 3}, {1, 3}, {2, 3}}},
    {3, {{3, 0}, {3, 1}, {3, 2}}},
    {4, {{0, 1}, {0, 2}, {3, 1}, {3, 2}}},
    {4, {{1, 0}, {1, 2}, {3, 0}, {3, 2}}},
    {3, {{0, 2}, {1, 2}, {3, 2}}},
    {4, {{2, 0}, {2, 1}, {3, 0}, {3, 1}}},
    {3, {{0, 1}, {2, 1}, {3, 1}}},
    {3, {{1, 0}, {2, 0}, {3, 0}}},
    {0, {{0, 0}}},
};

void POSE__VR(pose__volume_raster_tet)(const pose_volume_sampler *s, size_t t,
                                       const pose__vol_box *box, int k0, int k1,
                                       pose__vol_stage *st)
{
    const uint32_t *tv = s->tets + 4 * t;
    const int flags = s->tet_flags[t];
    const float *q[4], *r[4];
    for (int c = 0; c < 4; c++) {
        q[c] = s->posed_index + 3 * (size_t)tv[c];
        r[c] = s->rest_index + 3 * (size_t)tv[c];
    }
    /* D = [q1-q0 q2-q0 q3-q0]; b = D^-1 (x - q0); rest = r0 + E b. */
    double D[3][3];
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++)
            D[a][c] = (double)q[c + 1][a] - q[0][a];
    const double det = det3(D);
    if (!(fabs(det) > 1e-12))
        return; /* flat posed tet: it covers no volume */
    /* A posed tet turned inside out (where the skinning folds tissue over
     * itself) would paint its mirrored preimage over the tissue it folds
     * onto: it is skipped, the unfolded tets there cover the space (so is
     * a flat rest tet). */
    const int rest_sign = flags & POSE__VOL_REST_POSITIVE ? 1 : flags & POSE__VOL_REST_NEGATIVE ? -1 : 0;
    if ((det > 0 ? rest_sign : -rest_sign) != s->orient)
        return;
    const double id = 1.0 / det;
    const double B[3][3] = {
        {(D[1][1] * D[2][2] - D[1][2] * D[2][1]) * id, (D[0][2] * D[2][1] - D[0][1] * D[2][2]) * id,
         (D[0][1] * D[1][2] - D[0][2] * D[1][1]) * id},
        {(D[1][2] * D[2][0] - D[1][0] * D[2][2]) * id, (D[0][0] * D[2][2] - D[0][2] * D[2][0]) * id,
         (D[0][2] * D[1][0] - D[0][0] * D[1][2]) * id},
        {(D[1][0] * D[2][1] - D[1][1] * D[2][0]) * id, (D[0][1] * D[2][0] - D[0][0] * D[2][1]) * id,
         (D[0][0] * D[1][1] - D[0][1] * D[1][0]) * id}};
    /* Barycentric c as g + d i + e j + f k (c = 1..3 from B, c = 0 the rest
     * of 1), then its bound on i in a row: b >= -eps is i >= (-eps - g - e j
     * - f k) / d for d > 0, i <= that for d < 0. A coordinate constant
     * along rows (|d| tiny) takes d = +1e-12, which turns it into a bound
     * that lets the whole row in when b >= -eps and none of it otherwise.
     * Bound c is ba + bj j + bk k; lo_add / hi_add (0 or -inf / +inf) make
     * it count only in the max (bounds from below) or only in the min
     * (from above), without a branch per row. */
    const double q0[3] = {q[0][0], q[0][1], q[0][2]};
    double g[4], d[4], e[4], f[4];
    g[0] = 1.0, d[0] = e[0] = f[0] = 0.0;
    for (int c = 1; c < 4; c++) {
        const double *b = B[c - 1];
        g[c] = -(b[0] * q0[0] + b[1] * q0[1] + b[2] * q0[2]);
        d[c] = b[0], e[c] = b[1], f[c] = b[2];
        g[0] -= g[c], d[0] -= d[c], e[0] -= e[c], f[0] -= f[c];
    }
    double ba[4], bj[4], bk[4], lo_add[4], hi_add[4];
    int below = 0;
    for (int c = 0; c < 4; c++) {
        const double dc = fabs(d[c]) > 1e-12 ? d[c] : 1e-12, rd = 1.0 / dc;
        ba[c] = (-POSE__VOL_EPS - g[c]) * rd;
        bj[c] = -e[c] * rd;
        bk[c] = -f[c] * rd;
        lo_add[c] = dc > 0 ? 0.0 : -INFINITY;
        hi_add[c] = dc > 0 ? INFINITY : 0.0;
        below |= (dc > 0) << c;
    }
    /* The rows of a plane the section spans: a row is not empty when every
     * bound from below is under every bound from above, v_a(j) <= v_h(j),
     * a bound on j affine in k for each such pair (a pair constant in j
     * as above). A hint (widened by 1e-3 rows): the row test decides.
     * Unused pair slots bound nothing. */
    double ja[4], jk[4], jlo_add[4], jhi_add[4];
    for (int p = 0; p < 4; p++) {
        const int used = p < k_pairs[below].n, a = k_pairs[below].pair[p][0],
                  h = k_pairs[below].pair[p][1];
        const double cj0 = bj[a] - bj[h], cj = fabs(cj0) > 1e-12 ? cj0 : -1e-12;
        ja[p] = used ? -(ba[a] - ba[h]) / cj : 0.0;
        jk[p] = used ? -(bk[a] - bk[h]) / cj : 0.0;
        jlo_add[p] = used && cj < 0 ? -1e-3 : -INFINITY;
        jhi_add[p] = used && cj > 0 ? 1e-3 : INFINITY;
    }
    /* rest = R + M (i, j, k), M = E B (the identity when the tet lies
     * where it rests: not used then). */
    const int identity = box->identity;
    double M[3][3], R[3];
    for (int a = 0; a < 3; a++) {
        const double E0 = (double)r[1][a] - r[0][a], E1 = (double)r[2][a] - r[0][a],
                     E2 = (double)r[3][a] - r[0][a];
        for (int c = 0; c < 3; c++)
            M[a][c] = E0 * B[0][c] + E1 * B[1][c] + E2 * B[2][c];
        R[a] = r[0][a] - (M[a][0] * q0[0] + M[a][1] * q0[1] + M[a][2] * q0[2]);
    }
    const double Rv[4] = {R[0], R[1], R[2], 0.0}, Mi[4] = {M[0][0], M[1][0], M[2][0], 0.0},
                 Mj[4] = {M[0][1], M[1][1], M[2][1], 0.0}, Mk[4] = {M[0][2], M[1][2], M[2][2], 0.0};
    const v4d ja_v = v4_load(ja), jk_v = v4_load(jk), jlo_v = v4_load(jlo_add),
              jhi_v = v4_load(jhi_add), ba_v = v4_load(ba), bj_v = v4_load(bj), bk_v = v4_load(bk),
              lo_v = v4_load(lo_add), hi_v = v4_load(hi_add), R_v = v4_load(Rv), Mi_v = v4_load(Mi),
              Mj_v = v4_load(Mj), Mk_v = v4_load(Mk);
    const size_t nx = s->out.nx, ny = s->out.ny;
    const double i0 = box->i0, i1 = box->i1;
    span sp = {.mx = (float)M[0][0], .my = (float)M[1][0], .mz = (float)M[2][0],
               .block = (uint16_t)(t >> s->block_shift)};
    for (int k = k0; k <= k1; k++) {
        const double kd = k;
        const v4d jv = v4_madd(ja_v, jk_v, kd);
        const double jlo = maxd(box->j0, v4_max(jv, jlo_v)), jhi = mind(box->j1, v4_min(jv, jhi_v));
        if (!(jlo <= jhi))
            continue;
        const int j0 = iceil(jlo), j1 = ifloor(jhi);
        /* The bounds and preimages of a row from the tet, k and j only,
         * whatever slab this plane falls in. */
        const v4d vk = v4_madd(ba_v, bk_v, kd), rk = v4_madd(R_v, Mk_v, kd);
        sp.k = k;
        for (int j = j0; j <= j1; j++) {
            const double jd = j;
            const v4d v = v4_madd(vk, bj_v, jd);
            const double lo = maxd(i0, v4_max(v, lo_v)), hi = mind(i1, v4_min(v, hi_v));
            if (!(lo <= hi))
                continue;
            sp.ia = iceil(lo), sp.ib = ifloor(hi);
            if (sp.ia > sp.ib)
                continue;
            if (!identity) {
                const v4d r0 = v4_madd(v4_madd(rk, Mj_v, jd), Mi_v, (double)sp.ia);
                sp.rx = (float)v4_lane(r0, 0), sp.ry = (float)v4_lane(r0, 1),
                sp.rz = (float)v4_lane(r0, 2);
            }
            sp.j = j;
            cover_span(s, st, &sp, identity, pose__vol_cover_row(s, (size_t)j, (size_t)k),
                       ((size_t)k * ny + (size_t)j) * nx);
        }
    }
}
