/* SPDX-License-Identifier: Apache-2.0
 * pose/volume.h: posing a volumetric image through the posed tet mesh.
 *
 * Per call: (1) every posed tet vertex into the output grid's index space
 * (parts over vertices); (2) per z-slab of the output (one slab per part):
 * for every tet in index order whose z range meets the slab, scan its
 * voxels row by row, marking them covered; (3) the voxels left uncovered
 * get the background, or their neighbours' values in a mesh crack. In output index space the
 * barycentric coordinates are affine in i along a row, so each row's span
 * inside the tet is an interval found from the four coordinates (no
 * per-voxel inside test), and the preimage in the rest image's index space
 * is affine too (r = r0 + M (x - q0)): one add per voxel. */
#include "pose/volume.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "rt_pool.h"
#include "rt_thread.h"

#define VOL_MAX_VOXELS ((uint64_t)1 << 31)
#define VOL_MAX_THREADS 256u
/* Barycentric tolerance: voxel centres on a face shared by two tets (grid-
 * aligned meshes) belong to both rather than to neither. */
#define VOL_EPS 1e-4

struct pose_volume_sampler {
    const pose_rig *rig;
    pose_allocator allocator;
    pose_volume_desc rest;
    pose_volume_grid out;
    double out_inv[3][4];   /* model -> output index */
    int orient;             /* sign of det(rest index <- model) * det(output index <- model) */
    size_t vertex_count, tet_count;
    const uint32_t *tets;
    float *rest_index;      /* 3 * V: rest vertices in the rest image's index space */
    float *posed_index;     /* 3 * V: posed vertices in the output index space (per call) */
    uint8_t *covered;       /* per output voxel: inside a posed tet (this call) */
    pose__pool *pool;
    /* the call in flight */
    const float *posed;
    float *dst_intensity;
    uint16_t *dst_labels;
};

static int invert_affine(const float a[3][4], double inv[3][4])
{
    double m[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            if (!isfinite(a[r][c]))
                return -1;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            m[r][c] = a[r][c];
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                 m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (!(fabs(det) > 1e-30) || !isfinite(det))
        return -1;
    double c[3][3] = {{m[1][1] * m[2][2] - m[1][2] * m[2][1], m[0][2] * m[2][1] - m[0][1] * m[2][2],
                       m[0][1] * m[1][2] - m[0][2] * m[1][1]},
                      {m[1][2] * m[2][0] - m[1][0] * m[2][2], m[0][0] * m[2][2] - m[0][2] * m[2][0],
                       m[0][2] * m[1][0] - m[0][0] * m[1][2]},
                      {m[1][0] * m[2][1] - m[1][1] * m[2][0], m[0][1] * m[2][0] - m[0][0] * m[2][1],
                       m[0][0] * m[1][1] - m[0][1] * m[1][0]}};
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++)
            inv[r][k] = c[r][k] / det;
        inv[r][3] = -(inv[r][0] * a[0][3] + inv[r][1] * a[1][3] + inv[r][2] * a[2][3]);
    }
    return 0;
}

static pose_status check_grid(const pose_volume_grid *g, const char *what, double inv[3][4])
{
    uint64_t n = (uint64_t)g->nx * g->ny * g->nz;
    if (g->nx == 0 || g->ny == 0 || g->nz == 0 || n > VOL_MAX_VOXELS)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_volume_sampler_create: %s grid %u x %u x %u (1 .. 2^31 voxels)",
                          what, g->nx, g->ny, g->nz);
    if (invert_affine(g->affine, inv) != 0)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_volume_sampler_create: the %s grid's affine is singular or not "
                          "finite",
                          what);
    return POSE_OK;
}

static size_t voxels_of(const pose_volume_grid *g)
{
    return (size_t)g->nx * g->ny * g->nz;
}

pose_status pose_volume_sampler_create(const pose_rig *rig, const pose_volume_desc *rest,
                                       const pose_volume_grid *out_grid, int threads,
                                       const pose_allocator *allocator, pose_volume_sampler **out)
{
    pose__clear_error();
    if (out)
        *out = NULL;
    if (!rig || !rest || !out || threads < 0)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_volume_sampler_create: %s",
                          threads < 0 ? "threads < 0" : "rig, rest and out are required");
    if (allocator && !pose__allocator_valid(allocator))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_volume_sampler_create: allocator needs both alloc and free");
    if (!rest->intensity && !rest->labels)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_volume_sampler_create: the rest image has neither intensities nor "
                          "labels");
    double rest_inv[3][4], out_inv[3][4];
    pose_status st = check_grid(&rest->grid, "rest", rest_inv);
    if (st != POSE_OK)
        return st;
    const pose_volume_grid *og = out_grid ? out_grid : &rest->grid;
    st = check_grid(og, "output", out_inv);
    if (st != POSE_OK)
        return st;
    pose_tet_info ti;
    st = pose_rig_tet_info(rig, &ti);
    if (st != POSE_OK)
        return st;
    unsigned n = threads > 0 ? (unsigned)threads : 0;
    if (n == 0)
        n = pose__cpu_count();
    if (n > VOL_MAX_THREADS)
        n = VOL_MAX_THREADS;

    pose_allocator a = pose__allocator_resolve(allocator);
    pose_volume_sampler *s = pose__alloc(&a, sizeof *s, POSE__ALIGN);
    if (!s)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a volume sampler");
    memset(s, 0, sizeof *s);
    s->rig = rig;
    s->allocator = a;
    s->rest = *rest;
    s->out = *og;
    memcpy(s->out_inv, out_inv, sizeof out_inv);
    double dr = rest_inv[0][0] * (rest_inv[1][1] * rest_inv[2][2] - rest_inv[1][2] * rest_inv[2][1]) -
                rest_inv[0][1] * (rest_inv[1][0] * rest_inv[2][2] - rest_inv[1][2] * rest_inv[2][0]) +
                rest_inv[0][2] * (rest_inv[1][0] * rest_inv[2][1] - rest_inv[1][1] * rest_inv[2][0]);
    double dout = out_inv[0][0] * (out_inv[1][1] * out_inv[2][2] - out_inv[1][2] * out_inv[2][1]) -
                  out_inv[0][1] * (out_inv[1][0] * out_inv[2][2] - out_inv[1][2] * out_inv[2][0]) +
                  out_inv[0][2] * (out_inv[1][0] * out_inv[2][1] - out_inv[1][1] * out_inv[2][0]);
    s->orient = dr * dout > 0 ? 1 : -1;
    s->vertex_count = ti.vertex_count;
    s->tet_count = ti.tet_count;
    s->tets = ti.tets;
    size_t vb = 3 * ti.vertex_count * sizeof(float);
    s->rest_index = pose__alloc(&a, vb ? vb : 1, POSE__ALIGN);
    s->posed_index = pose__alloc(&a, vb ? vb : 1, POSE__ALIGN);
    s->pool = pose__alloc(&a, pose__pool_size(n), POSE__ALIGN);
    s->covered = pose__alloc(&a, voxels_of(og), POSE__ALIGN);
    if (!s->rest_index || !s->posed_index || !s->pool || !s->covered) {
        pose__free(&a, s->pool);
        s->pool = NULL;
        pose_volume_sampler_free(s);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a volume sampler");
    }
    if (pose__pool_init(s->pool, n) != 0) {
        pose__free(&a, s->pool);
        s->pool = NULL;
        pose_volume_sampler_free(s);
        return pose__fail(POSE_ERR_THREAD, "could not start %u worker threads", n - 1);
    }
    for (size_t v = 0; v < ti.vertex_count; v++) {
        const float *p = ti.rest_positions + 3 * v;
        for (int r = 0; r < 3; r++)
            s->rest_index[3 * v + r] = (float)(rest_inv[r][0] * p[0] + rest_inv[r][1] * p[1] +
                                               rest_inv[r][2] * p[2] + rest_inv[r][3]);
    }
    *out = s;
    return POSE_OK;
}

void pose_volume_sampler_free(pose_volume_sampler *s)
{
    if (!s)
        return;
    pose_allocator a = s->allocator;
    if (s->pool) {
        pose__pool_destroy(s->pool);
        pose__free(&a, s->pool);
    }
    pose__free(&a, s->rest_index);
    pose__free(&a, s->posed_index);
    pose__free(&a, s->covered);
    pose__free(&a, s);
}

const pose_volume_grid *pose_volume_sampler_grid(const pose_volume_sampler *s)
{
    return s ? &s->out : NULL;
}

size_t pose_volume_sample_bytes(const pose_volume_sampler *s, int intensity, int labels)
{
    if (!s)
        return 0;
    size_t nv = voxels_of(&s->out);
    size_t per = (intensity ? sizeof(float) : 0) + (labels ? sizeof(uint16_t) : 0);
    /* outputs written; rest samples read about once each where the body is
     * (bounded by the output size); posed and index vertices, tets. */
    return 2 * nv * per + 3 * nv + 3 * s->vertex_count * sizeof(float) * 3 +
           s->tet_count * 4 * sizeof(uint32_t);
}

/* Pass 1: posed tet vertices -> output index space. */
static void to_index_task(void *ctx, unsigned part, unsigned parts)
{
    pose_volume_sampler *s = ctx;
    size_t b = pose__part_begin(s->vertex_count, part, parts);
    size_t e = pose__part_begin(s->vertex_count, part + 1, parts);
    const double(*m)[4] = s->out_inv;
    for (size_t v = b; v < e; v++) {
        const float *p = s->posed + 3 * v;
        float *q = s->posed_index + 3 * v;
        for (int r = 0; r < 3; r++)
            q[r] = (float)(m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3]);
    }
}

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
    /* Beyond the image (a tet reaching past the field of view): no data. */
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

/* sample_rest for a preimage known to lie in [0, n - 1) on every axis
 * (the tet's four rest vertices do): no clamps, the nearest voxel from the
 * trilinear cell. */
static inline void sample_rest_inside(const pose_volume_desc *rest, size_t sy, size_t sz,
                                      float x, float y, float z, float *dst_i, uint16_t *dst_l,
                                      size_t at)
{
    int i = (int)x, j = (int)y, k = (int)z;
    float fx = x - (float)i, fy = y - (float)j, fz = z - (float)k;
    size_t base = (size_t)k * sz + (size_t)j * sy + (size_t)i;
    if (dst_l)
        dst_l[at] = rest->labels[base + (fx >= 0.5f) + (fy >= 0.5f ? sy : 0) + (fz >= 0.5f ? sz : 0)];
    if (!dst_i)
        return;
    const float *p = rest->intensity + base;
    float c00 = p[0] + fx * (p[1] - p[0]);
    float c10 = p[sy] + fx * (p[sy + 1] - p[sy]);
    float c01 = p[sz] + fx * (p[sz + 1] - p[sz]);
    float c11 = p[sz + sy] + fx * (p[sz + sy + 1] - p[sz + sy]);
    float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
    dst_i[at] = c0 + fz * (c1 - c0);
}

static inline float minf4(float a, float b, float c, float d)
{
    float x = a < b ? a : b, y = c < d ? c : d;
    return x < y ? x : y;
}

static inline float maxf4(float a, float b, float c, float d)
{
    float x = a > b ? a : b, y = c > d ? c : d;
    return x > y ? x : y;
}

/* ceil / floor of a value well inside the int range. */
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

/* One barycentric coordinate along a row: b(i) = c + d i >= -eps narrows
 * [lo, hi]; rd = 1 / d (0 when d is 0). */
static inline void clip_span(double c, double d, double rd, double *lo, double *hi)
{
    if (d > 1e-12) {
        double v = (-VOL_EPS - c) * rd;
        *lo = v > *lo ? v : *lo;
    } else if (d < -1e-12) {
        double v = (-VOL_EPS - c) * rd;
        *hi = v < *hi ? v : *hi;
    } else if (c < -VOL_EPS) {
        *hi = -1e30;
    }
}

static void raster_tet(const pose_volume_sampler *s, size_t t, int z0, int z1)
{
    const uint32_t *tv = s->tets + 4 * t;
    const float *q[4], *r[4];
    for (int c = 0; c < 4; c++)
        q[c] = s->posed_index + 3 * (size_t)tv[c];
    float zmin = minf4(q[0][2], q[1][2], q[2][2], q[3][2]);
    float zmax = maxf4(q[0][2], q[1][2], q[2][2], q[3][2]);
    int k0 = iceil(zmin - 1e-4f), k1 = ifloor(zmax + 1e-4f);
    if (k0 < z0)
        k0 = z0;
    if (k1 > z1 - 1)
        k1 = z1 - 1;
    if (k0 > k1)
        return;
    const int nx = (int)s->out.nx, ny = (int)s->out.ny;
    float xmin = minf4(q[0][0], q[1][0], q[2][0], q[3][0]);
    float xmax = maxf4(q[0][0], q[1][0], q[2][0], q[3][0]);
    int i0 = iceil(xmin - 1e-4f), i1 = ifloor(xmax + 1e-4f);
    if (i0 < 0)
        i0 = 0;
    if (i1 > nx - 1)
        i1 = nx - 1;
    if (i0 > i1)
        return;
    /* Most small tets hold no voxel centre: the y extent says so before the
     * matrices are set up. */
    const float ymin = minf4(q[0][1], q[1][1], q[2][1], q[3][1]);
    const float ymax = maxf4(q[0][1], q[1][1], q[2][1], q[3][1]);
    if (iceil(ymin - 1e-4f) > ifloor(ymax + 1e-4f) || ymax < -1e-4f || ymin > (float)(ny - 1) + 1e-4f)
        return;
    for (int c = 0; c < 4; c++)
        r[c] = s->rest_index + 3 * (size_t)tv[c];
    /* D = [q1-q0 q2-q0 q3-q0]; b = D^-1 (x - q0); rest = r0 + E b. */
    double D[3][3], E[3][3];
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++) {
            D[a][c] = (double)q[c + 1][a] - q[0][a];
            E[a][c] = (double)r[c + 1][a] - r[0][a];
        }
    double det = D[0][0] * (D[1][1] * D[2][2] - D[1][2] * D[2][1]) -
                 D[0][1] * (D[1][0] * D[2][2] - D[1][2] * D[2][0]) +
                 D[0][2] * (D[1][0] * D[2][1] - D[1][1] * D[2][0]);
    if (!(fabs(det) > 1e-12))
        return; /* flat posed tet: it covers no volume */
    /* A posed tet turned inside out (where the skinning folds tissue over
     * itself) would paint its mirrored preimage over the tissue it folds
     * onto: it is skipped, the unfolded tets there cover the space. */
    double dete = E[0][0] * (E[1][1] * E[2][2] - E[1][2] * E[2][1]) -
                  E[0][1] * (E[1][0] * E[2][2] - E[1][2] * E[2][0]) +
                  E[0][2] * (E[1][0] * E[2][1] - E[1][1] * E[2][0]);
    if ((det * dete > 0 ? 1 : -1) != s->orient)
        return;
    double B[3][3] = {{D[1][1] * D[2][2] - D[1][2] * D[2][1], D[0][2] * D[2][1] - D[0][1] * D[2][2],
                       D[0][1] * D[1][2] - D[0][2] * D[1][1]},
                      {D[1][2] * D[2][0] - D[1][0] * D[2][2], D[0][0] * D[2][2] - D[0][2] * D[2][0],
                       D[0][2] * D[1][0] - D[0][0] * D[1][2]},
                      {D[1][0] * D[2][1] - D[1][1] * D[2][0], D[0][1] * D[2][0] - D[0][0] * D[2][1],
                       D[0][0] * D[1][1] - D[0][1] * D[1][0]}};
    const double inv_det = 1.0 / det;
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++)
            B[a][c] *= inv_det;
    double M[3][3];
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++)
            M[a][c] = E[a][0] * B[0][c] + E[a][1] * B[1][c] + E[a][2] * B[2][c];
    const pose_volume_desc *rest = &s->rest;
    /* Fast path when the whole rest tet lies inside the image's cells. */
    int inside = 1;
    const float lim[3] = {(float)rest->grid.nx - 1.001f, (float)rest->grid.ny - 1.001f,
                          (float)rest->grid.nz - 1.001f};
    for (int c = 0; c < 4; c++)
        for (int a = 0; a < 3; a++)
            inside &= r[c][a] >= 0.001f && r[c][a] <= lim[a];
    const size_t rsy = rest->grid.nx, rsz = (size_t)rest->grid.nx * rest->grid.ny;
    float *dst_i = s->dst_intensity;
    uint16_t *dst_l = s->dst_labels;
    /* Barycentric coordinates change along i by the first column of B. */
    const double d1 = B[0][0], d2 = B[1][0], d3 = B[2][0], d0 = -(d1 + d2 + d3);
    const double rd1 = fabs(d1) > 1e-12 ? 1.0 / d1 : 0.0, rd2 = fabs(d2) > 1e-12 ? 1.0 / d2 : 0.0,
                 rd3 = fabs(d3) > 1e-12 ? 1.0 / d3 : 0.0, rd0 = fabs(d0) > 1e-12 ? 1.0 / d0 : 0.0;
    const float mx = (float)M[0][0], my = (float)M[1][0], mz = (float)M[2][0];
    /* The six edges, for each plane's y range. */
    static const int edge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    for (int k = k0; k <= k1; k++) {
        /* y extent of the tet's section by the plane z = k. */
        double ylo = 1e30, yhi = -1e30;
        for (int e = 0; e < 6; e++) {
            const float *a = q[edge[e][0]], *b = q[edge[e][1]];
            double za = a[2] - (double)k, zb = b[2] - (double)k;
            if ((za > 1e-4 && zb > 1e-4) || (za < -1e-4 && zb < -1e-4))
                continue;
            double y;
            if (fabs(za - zb) < 1e-12) {
                y = a[1] < b[1] ? a[1] : b[1];
                ylo = y < ylo ? y : ylo;
                y = a[1] > b[1] ? a[1] : b[1];
                yhi = y > yhi ? y : yhi;
                continue;
            }
            double u = za / (za - zb);
            u = u < 0 ? 0 : u > 1 ? 1 : u;
            y = a[1] + u * ((double)b[1] - a[1]);
            ylo = y < ylo ? y : ylo;
            yhi = y > yhi ? y : yhi;
        }
        int j0 = iceil(ylo - 1e-3), j1 = ifloor(yhi + 1e-3);
        if (j0 < 0)
            j0 = 0;
        if (j1 > ny - 1)
            j1 = ny - 1;
        for (int j = j0; j <= j1; j++) {
            double x0[3] = {-(double)q[0][0], j - (double)q[0][1], k - (double)q[0][2]};
            double b1 = B[0][0] * x0[0] + B[0][1] * x0[1] + B[0][2] * x0[2];
            double b2 = B[1][0] * x0[0] + B[1][1] * x0[1] + B[1][2] * x0[2];
            double b3 = B[2][0] * x0[0] + B[2][1] * x0[1] + B[2][2] * x0[2];
            double lo = i0, hi = i1;
            clip_span(b1, d1, rd1, &lo, &hi);
            clip_span(b2, d2, rd2, &lo, &hi);
            clip_span(b3, d3, rd3, &lo, &hi);
            clip_span(1.0 - b1 - b2 - b3, d0, rd0, &lo, &hi);
            if (!(lo <= hi))
                continue;
            int ia = iceil(lo), ib = ifloor(hi);
            if (ia > ib)
                continue;
            /* The preimage at i = ia, then one add per voxel. */
            double xa[3] = {ia - (double)q[0][0], x0[1], x0[2]};
            float rx = (float)(r[0][0] + M[0][0] * xa[0] + M[0][1] * xa[1] + M[0][2] * xa[2]);
            float ry = (float)(r[0][1] + M[1][0] * xa[0] + M[1][1] * xa[1] + M[1][2] * xa[2]);
            float rz = (float)(r[0][2] + M[2][0] * xa[0] + M[2][1] * xa[1] + M[2][2] * xa[2]);
            size_t row = ((size_t)k * (size_t)ny + (size_t)j) * (size_t)nx;
            memset(s->covered + row + ia, 1, (size_t)(ib - ia + 1));
            if (inside && dst_i && dst_l) {
                /* The common case, both outputs: everything in registers. */
                const float *img = rest->intensity;
                const uint16_t *lb = rest->labels;
                float *oi = dst_i + row;
                uint16_t *ol = dst_l + row;
                for (int i = ia; i <= ib; i++) {
                    const float u = (float)(i - ia);
                    const float x = rx + mx * u, y = ry + my * u, z = rz + mz * u;
                    int xi = (int)x, yi = (int)y, zi = (int)z;
                    float fx = x - (float)xi, fy = y - (float)yi, fz = z - (float)zi;
                    size_t base = (size_t)zi * rsz + (size_t)yi * rsy + (size_t)xi;
                    ol[i] = lb[base + (fx >= 0.5f) + (fy >= 0.5f ? rsy : 0) + (fz >= 0.5f ? rsz : 0)];
                    const float *p = img + base;
                    float c00 = p[0] + fx * (p[1] - p[0]);
                    float c10 = p[rsy] + fx * (p[rsy + 1] - p[rsy]);
                    float c01 = p[rsz] + fx * (p[rsz + 1] - p[rsz]);
                    float c11 = p[rsz + rsy] + fx * (p[rsz + rsy + 1] - p[rsz + rsy]);
                    float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
                    oi[i] = c0 + fz * (c1 - c0);
                }
            } else if (inside)
                for (int i = ia; i <= ib; i++) {
                    float u = (float)(i - ia);
                    sample_rest_inside(rest, rsy, rsz, rx + mx * u, ry + my * u, rz + mz * u,
                                       dst_i, dst_l, row + (size_t)i);
                }
            else
                for (int i = ia; i <= ib; i++) {
                    float u = (float)(i - ia);
                    sample_rest(rest, rx + mx * u, ry + my * u, rz + mz * u, dst_i, dst_l,
                                row + (size_t)i);
                }
        }
    }
}

/* Pass 2: one z-slab per part: every tet meeting the slab, in index order. */
static void slab_task(void *ctx, unsigned part, unsigned parts)
{
    pose_volume_sampler *s = ctx;
    int z0 = (int)pose__part_begin(s->out.nz, part, parts);
    int z1 = (int)pose__part_begin(s->out.nz, part + 1, parts);
    if (z0 >= z1)
        return;
    size_t plane = (size_t)s->out.nx * s->out.ny;
    memset(s->covered + (size_t)z0 * plane, 0, (size_t)(z1 - z0) * plane);
    for (size_t t = 0; t < s->tet_count; t++)
        raster_tet(s, t, z0, z1);
}

/* Pass 3, the voxels no tet covered. One whose six neighbours all are
 * covered sits in a crack of the mesh (a centre on a sliver or a
 * coarsening seam that float rounding left out of every tet), not outside
 * the body: it takes its neighbours' mean intensity and its -x neighbour's
 * label. The others are background. Reads only covered voxels, which this
 * pass never writes: any thread count gives the same bytes. */
static void fill_task(void *ctx, unsigned part, unsigned parts)
{
    pose_volume_sampler *s = ctx;
    const size_t nx = s->out.nx, ny = s->out.ny, nz = s->out.nz, sy = nx, sz = nx * ny;
    const size_t z0 = pose__part_begin(nz, part, parts), z1 = pose__part_begin(nz, part + 1, parts);
    const uint8_t *c = s->covered;
    float *di = s->dst_intensity;
    uint16_t *dl = s->dst_labels;
    const float bi = s->rest.intensity_background;
    const uint16_t bl = s->rest.label_background;
    for (size_t k = z0; k < z1; k++)
        for (size_t j = 0; j < ny; j++) {
            const size_t row = k * sz + j * sy;
            const int inner = k > 0 && k + 1 < nz && j > 0 && j + 1 < ny;
            for (size_t i = 0; i < nx; i++) {
                size_t v = row + i;
                if (c[v])
                    continue;
                if (inner && i > 0 && i + 1 < nx && c[v - 1] && c[v + 1] && c[v - sy] &&
                    c[v + sy] && c[v - sz] && c[v + sz]) {
                    if (di)
                        di[v] = (di[v - 1] + di[v + 1] + di[v - sy] + di[v + sy] + di[v - sz] +
                                 di[v + sz]) / 6.0f;
                    if (dl)
                        dl[v] = dl[v - 1];
                    continue;
                }
                if (di)
                    di[v] = bi;
                if (dl)
                    dl[v] = bl;
            }
        }
}

pose_status pose_volume_sample(pose_volume_sampler *s, const pose_state *state,
                               float *out_intensity, uint16_t *out_labels)
{
    pose__clear_error();
    if (!s || !state)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_volume_sample: sampler and state are "
                                                     "required");
    if (pose_state_rig(state) != s->rig)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_volume_sample: the state comes from another rig than the "
                          "sampler's");
    if ((out_intensity && !s->rest.intensity) || (out_labels && !s->rest.labels))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_volume_sample: %s asked for but the rest image has none",
                          out_intensity && !s->rest.intensity ? "intensities" : "labels");
    size_t n = 0;
    const float *posed = pose_tet_positions(state, &n);
    if (!posed || n != s->vertex_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_volume_sample: the state has %zu tet vertices, the rig %zu", n,
                          s->vertex_count);
    s->posed = posed;
    s->dst_intensity = out_intensity;
    s->dst_labels = out_labels;
    pose__pool_run(s->pool, to_index_task, s);
    pose__pool_run(s->pool, slab_task, s);
    pose__pool_run(s->pool, fill_task, s);
    s->posed = NULL;
    s->dst_intensity = NULL;
    s->dst_labels = NULL;
    return POSE_OK;
}
