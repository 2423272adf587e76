/* SPDX-License-Identifier: Apache-2.0
 * One posed tet into the output grid (pose_volume_sample's slab pass).
 *
 * In output index space a tet's barycentric coordinates are affine in
 * (i, j, k), and so is the preimage in the rest image's index space. Per
 * tet: the inverse map once (double). Per row (j, k): the span of i inside
 * the tet from the four coordinates' bounds, each itself affine in j (one
 * multiply-add per coordinate, no division, no inside test per voxel), and
 * the preimage of the span's first voxel; the rows a plane's section spans
 * come from the same bounds taken pairwise. Per voxel: three
 * multiply-adds to the preimage, then the trilinear intensity and the
 * nearest label, for the voxels no tet covered before. */
#include <math.h>

#include "rt_vec.h" /* POSE__INLINE */
#include "volume_internal.h"

static inline float clampf(float v, float lo, float hi)
{
    return v < lo ? lo : v > hi ? hi : v; /* NaN -> hi: still inside the image */
}

/* One voxel of the output from the rest image at index-space point (x, y, z):
 * intensity trilinear, label of the nearest voxel; a point more than half a
 * voxel outside the image gets the background (the scan has no data
 * there), within that margin coordinates are clamped to the image. */
static inline void sample_rest(const pose_volume_desc *rest, float x, float y, float z,
                               float *dst_i, uint16_t *dst_l, size_t at)
{
    const int nx = (int)rest->grid.nx, ny = (int)rest->grid.ny, nz = (int)rest->grid.nz;
    if (x < -0.5f || y < -0.5f || z < -0.5f || x > (float)nx - 0.5f || y > (float)ny - 0.5f ||
        z > (float)nz - 0.5f) {
        if (dst_l)
            dst_l[at] = rest->label_background;
        if (dst_i)
            dst_i[at] = rest->intensity_background;
        return;
    }
    x = clampf(x, 0.0f, (float)(nx - 1));
    y = clampf(y, 0.0f, (float)(ny - 1));
    z = clampf(z, 0.0f, (float)(nz - 1));
    if (dst_l) {
        int li = (int)(x + 0.5f), lj = (int)(y + 0.5f), lk = (int)(z + 0.5f);
        dst_l[at] = rest->labels[((size_t)lk * (size_t)ny + (size_t)lj) * (size_t)nx + (size_t)li];
    }
    if (!dst_i)
        return;
    int i = (int)x, j = (int)y, k = (int)z;
    i -= i > nx - 2 && i > 0;
    j -= j > ny - 2 && j > 0;
    k -= k > nz - 2 && k > 0;
    float fx = x - (float)i, fy = y - (float)j, fz = z - (float)k;
    const size_t sx = nx > 1 ? 1 : 0, sy = ny > 1 ? (size_t)nx : 0,
                 sz = nz > 1 ? (size_t)nx * (size_t)ny : 0;
    const float *p = rest->intensity + ((size_t)k * (size_t)ny + (size_t)j) * (size_t)nx + (size_t)i;
    float c00 = p[0] + fx * (p[sx] - p[0]);
    float c10 = p[sy] + fx * (p[sy + sx] - p[sy]);
    float c01 = p[sz] + fx * (p[sz + sx] - p[sz]);
    float c11 = p[sz + sy] + fx * (p[sz + sy + sx] - p[sz + sy]);
    float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
    dst_i[at] = c0 + fz * (c1 - c0);
}

/* The preimages of a row's span: voxel ia + u maps to r + m u (from ia
 * whichever run of the span is sampled, so a voxel's value does not
 * depend on the runs). */
typedef struct span {
    float rx, ry, rz, mx, my, mz;
    int ia, ib;
} span;

/* A run of a span whose preimages lie in [0, n - 1) on every axis (the
 * tet's four rest vertices do): no clamps, the nearest voxel from the
 * trilinear cell; either output may be absent. */
static POSE__INLINE void row_inside(const pose_volume_desc *rest, const span *sp, int i0, int i1,
                                    float *oi, uint16_t *ol)
{
    const size_t sy = rest->grid.nx, sz = (size_t)rest->grid.nx * rest->grid.ny;
    const float *img = rest->intensity;
    const uint16_t *lb = rest->labels;
    const float rx = sp->rx, ry = sp->ry, rz = sp->rz, mx = sp->mx, my = sp->my, mz = sp->mz;
    for (int i = i0; i <= i1; i++) {
        const float u = (float)(i - sp->ia);
        const float x = rx + mx * u, y = ry + my * u, z = rz + mz * u;
        const int xi = (int)x, yi = (int)y, zi = (int)z;
        const float fx = x - (float)xi, fy = y - (float)yi, fz = z - (float)zi;
        const size_t base = (size_t)zi * sz + (size_t)yi * sy + (size_t)xi;
        if (ol)
            ol[i] = lb[base + (fx >= 0.5f) + (fy >= 0.5f ? sy : 0) + (fz >= 0.5f ? sz : 0)];
        if (!oi)
            continue;
        const float *p = img + base;
        const float c00 = p[0] + fx * (p[1] - p[0]);
        const float c10 = p[sy] + fx * (p[sy + 1] - p[sy]);
        const float c01 = p[sz] + fx * (p[sz + 1] - p[sz]);
        const float c11 = p[sz + sy] + fx * (p[sz + sy + 1] - p[sz + sy]);
        const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
        oi[i] = c0 + fz * (c1 - c0);
    }
}

/* A span whose preimage may leave the image: clamps and background. */
static inline void row_clamped(const pose_volume_desc *rest, const span *sp, int i0, int i1, float *oi,
                               uint16_t *ol)
{
    for (int i = i0; i <= i1; i++) {
        const float u = (float)(i - sp->ia);
        sample_rest(rest, sp->rx + sp->mx * u, sp->ry + sp->my * u, sp->rz + sp->mz * u, oi, ol,
                    (size_t)i);
    }
}

static inline void sample_run(const pose_volume_desc *rest, const span *sp, int inside, int i0,
                              int i1, float *oi, uint16_t *ol)
{
    if (inside && oi && ol) /* the common case: both outputs, a loop of its own */
        row_inside(rest, sp, i0, i1, oi, ol);
    else if (inside)
        row_inside(rest, sp, i0, i1, oi, ol);
    else
        row_clamped(rest, sp, i0, i1, oi, ol);
}

/* Marks voxels ia..ib of a row covered (its words w) and samples, in runs,
 * those no tet rasterized before covered: a voxel inside two posed tets (a
 * centre on a face two tets share, or where the deformation folds) is
 * sampled once, by the first tet the slab visits (the later in index
 * order), whatever the slab split. */
static inline void cover_span(const pose_volume_desc *rest, const span *sp, int inside, uint64_t *w,
                              float *oi, uint16_t *ol)
{
    const int a = sp->ia >> 6, b = sp->ib >> 6;
    const uint64_t first = ~(uint64_t)0 << (sp->ia & 63), last = ~(uint64_t)0 >> (63 - (sp->ib & 63));
    if (a == b && !(w[a] & first & last)) { /* the common case: one word, nothing covered yet */
        w[a] |= first & last;
        sample_run(rest, sp, inside, sp->ia, sp->ib, oi, ol);
        return;
    }
    for (int x = a; x <= b; x++) {
        const uint64_t m = (x == a ? first : ~(uint64_t)0) & (x == b ? last : ~(uint64_t)0);
        uint64_t open = m & ~w[x];
        w[x] |= m;
        while (open) {
            const int lo = __builtin_ctzll(open);
            const uint64_t after = ~(open >> lo);
            const int len = after ? __builtin_ctzll(after) : 64 - lo;
            sample_run(rest, sp, inside, 64 * x + lo, 64 * x + lo + len - 1, oi, ol);
            open = lo + len < 64 ? open & (~(uint64_t)0 << (lo + len)) : 0;
        }
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

int pose__volume_rest_flags(const pose_volume_grid *g, const float *r[4])
{
    double E[3][3];
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++)
            E[a][c] = (double)r[c + 1][a] - r[0][a];
    const double det = det3(E);
    int flags = det > 0 ? POSE__VOL_REST_POSITIVE : det < 0 ? POSE__VOL_REST_NEGATIVE : 0;
    const float lim[3] = {(float)g->nx - 1.001f, (float)g->ny - 1.001f, (float)g->nz - 1.001f};
    int inside = 1;
    for (int c = 0; c < 4; c++)
        for (int a = 0; a < 3; a++)
            inside &= r[c][a] >= 0.001f && r[c][a] <= lim[a];
    return flags | (inside ? POSE__VOL_REST_INSIDE : 0);
}

void pose__volume_raster_tet(const pose_volume_sampler *s, size_t t, const pose__vol_box *box,
                             int k0, int k1)
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
     * Bound c is v_c = ba + bj j + bk k; lo_add / hi_add (0 or -inf / +inf)
     * make it count only in the max (bounds from below) or only in the min
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
    for (int c = 0; c < 4; c++) {
        const double dc = fabs(d[c]) > 1e-12 ? d[c] : 1e-12, rd = 1.0 / dc;
        ba[c] = (-POSE__VOL_EPS - g[c]) * rd;
        bj[c] = -e[c] * rd;
        bk[c] = -f[c] * rd;
        lo_add[c] = dc > 0 ? 0.0 : -INFINITY;
        hi_add[c] = dc > 0 ? INFINITY : 0.0;
    }
    /* The rows of a plane the section spans: a row is not empty when every
     * bound from below is under every bound from above, v_a(j) <= v_h(j),
     * a bound on j affine in k for each such pair (a pair constant in j
     * as above); same trick for pairs that are not such a pair. A hint
     * (widened by 1e-3 rows): the row test decides. */
    double ja[4], jk[4], jlo_add[4], jhi_add[4];
    int pairs = 0;
    for (int a = 0; a < 4; a++)
        for (int h = 0; h < 4; h++)
            if (lo_add[a] == 0.0 && hi_add[h] == 0.0) {
                const double cj0 = bj[a] - bj[h], cj = fabs(cj0) > 1e-12 ? cj0 : -1e-12;
                ja[pairs] = -(ba[a] - ba[h]) / cj;
                jk[pairs] = -(bk[a] - bk[h]) / cj;
                jlo_add[pairs] = cj < 0 ? -1e-3 : -INFINITY;
                jhi_add[pairs] = cj < 0 ? INFINITY : 1e-3;
                pairs++;
            }
    for (; pairs < 4; pairs++) /* at most 2 x 2 pairs; the others bound nothing */
        ja[pairs] = jk[pairs] = 0.0, jlo_add[pairs] = -INFINITY, jhi_add[pairs] = INFINITY;
    /* rest = R + M (i, j, k), M = E B. */
    double M[3][3], R[3];
    for (int a = 0; a < 3; a++) {
        const double E0 = (double)r[1][a] - r[0][a], E1 = (double)r[2][a] - r[0][a],
                     E2 = (double)r[3][a] - r[0][a];
        for (int c = 0; c < 3; c++)
            M[a][c] = E0 * B[0][c] + E1 * B[1][c] + E2 * B[2][c];
        R[a] = r[0][a] - (M[a][0] * q0[0] + M[a][1] * q0[1] + M[a][2] * q0[2]);
    }
    const int inside = flags & POSE__VOL_REST_INSIDE;
    const size_t nx = s->out.nx, ny = s->out.ny;
    float *const di = s->dst_intensity;
    uint16_t *const dl = s->dst_labels;
    const double i0 = box->i0, i1 = box->i1;
    span sp = {.mx = (float)M[0][0], .my = (float)M[1][0], .mz = (float)M[2][0]};
    for (int k = k0; k <= k1; k++) {
        double jlo = box->j0, jhi = box->j1;
        for (int p = 0; p < 4; p++) {
            const double v = ja[p] + jk[p] * k;
            jlo = maxd(jlo, v + jlo_add[p]);
            jhi = mind(jhi, v + jhi_add[p]);
        }
        if (!(jlo <= jhi))
            continue;
        const int j0 = iceil(jlo), j1 = ifloor(jhi);
        /* Values at row j0, then one add per row: they depend on the tet, k
         * and j only, whatever slab this plane falls in. */
        double v0 = ba[0] + bj[0] * j0 + bk[0] * k, v1 = ba[1] + bj[1] * j0 + bk[1] * k,
               v2 = ba[2] + bj[2] * j0 + bk[2] * k, v3 = ba[3] + bj[3] * j0 + bk[3] * k;
        double rx = R[0] + M[0][1] * j0 + M[0][2] * k, ry = R[1] + M[1][1] * j0 + M[1][2] * k,
               rz = R[2] + M[2][1] * j0 + M[2][2] * k;
        for (int j = j0; j <= j1; j++) {
            const double lo = maxd(maxd(maxd(i0, v0 + lo_add[0]), v1 + lo_add[1]),
                                   maxd(v2 + lo_add[2], v3 + lo_add[3]));
            const double hi = mind(mind(mind(i1, v0 + hi_add[0]), v1 + hi_add[1]),
                                   mind(v2 + hi_add[2], v3 + hi_add[3]));
            if (lo <= hi) {
                sp.ia = iceil(lo), sp.ib = ifloor(hi);
                if (sp.ia <= sp.ib) {
                    sp.rx = (float)(rx + M[0][0] * sp.ia);
                    sp.ry = (float)(ry + M[1][0] * sp.ia);
                    sp.rz = (float)(rz + M[2][0] * sp.ia);
                    const size_t row = ((size_t)k * ny + (size_t)j) * nx;
                    cover_span(&s->rest, &sp, inside, pose__vol_cover_row(s, (size_t)j, (size_t)k),
                               di ? di + row : NULL, dl ? dl + row : NULL);
                }
            }
            v0 += bj[0], v1 += bj[1], v2 += bj[2], v3 += bj[3];
            rx += M[0][1], ry += M[1][1], rz += M[2][1];
        }
    }
}
