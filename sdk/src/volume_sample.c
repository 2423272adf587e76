/* SPDX-License-Identifier: Apache-2.0
 * pose/volume.h: posing a volumetric image through the posed tet mesh.
 *
 * Per call: (1) every posed tet vertex into the output grid's index space
 * (parts over vertices); (2) every posed tet's box of output voxel centres
 * and whether it lies where it rests (parts over tets); (3) per z-slab of
 * the output (one slab per part): every tet in index order whose box
 * meets the slab is rasterized (volume_raster_body.h), setting the covered
 * bits of its voxels, except those the rest cover copies
 * (volume_rest_cover.c); (4) the voxels left uncovered get the background,
 * or their neighbours' values in a mesh crack. */
#include "pose/volume.h"

#include <math.h>
#include <string.h>

#include "error.h"
#include "rt_kernels.h"
#include "rt_thread.h"
#include "volume_internal.h"

#define VOL_MAX_VOXELS ((uint64_t)1 << 31)
#define VOL_MAX_THREADS 256u

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

static void build_rest_cover(pose_volume_sampler *s);

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
    s->boxes = pose__alloc(&a, ti.tet_count ? ti.tet_count * sizeof *s->boxes : 1, POSE__ALIGN);
    s->tet_flags = pose__alloc(&a, ti.tet_count ? ti.tet_count : 1, POSE__ALIGN);
    s->cover_words = (og->nx + 63) / 64;
    s->covered = pose__alloc(&a, s->cover_words * og->ny * og->nz * sizeof *s->covered, POSE__ALIGN);
    s->stages = pose__alloc(&a, n * sizeof *s->stages, POSE__ALIGN);
    s->use_avx2 = pose__kernels_use_avx2();
    if (!s->rest_index || !s->posed_index || !s->pool || !s->boxes || !s->tet_flags ||
        !s->covered || !s->stages) {
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
    if (pose__vol_rest_cover_wanted(&rest->grid, og)) {
        void *arrays = pose__alloc(&a, pose__vol_rest_cover_bytes(og), POSE__ALIGN);
        if (!arrays) {
            pose_volume_sampler_free(s);
            return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a volume sampler");
        }
        pose__vol_rest_cover_init(s, arrays);
    }
    for (size_t v = 0; v < ti.vertex_count; v++) {
        const float *p = ti.rest_positions + 3 * v;
        for (int r = 0; r < 3; r++)
            s->rest_index[3 * v + r] = (float)(rest_inv[r][0] * p[0] + rest_inv[r][1] * p[1] +
                                               rest_inv[r][2] * p[2] + rest_inv[r][3]);
    }
    for (size_t t = 0; t < ti.tet_count; t++) {
        const float *r[4];
        for (int c = 0; c < 4; c++)
            r[c] = s->rest_index + 3 * (size_t)ti.tets[4 * t + c];
        s->tet_flags[t] = (uint8_t)pose__volume_rest_flags(r);
    }
    if (s->owner)
        build_rest_cover(s);
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
    pose__free(&a, s->boxes);
    pose__free(&a, s->tet_flags);
    pose__free(&a, s->covered);
    pose__free(&a, s->stages);
    pose__free(&a, s->owned_words);
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
     * (bounded by the output size); the covered bits cleared, set and read;
     * posed and index vertices, tets, their boxes written and read. */
    /* with a rest cover, its owners are read once more */
    return 2 * nv * per + 3 * nv / 8 + (s->owner ? nv * sizeof *s->owner : 0) +
           3 * s->vertex_count * sizeof(float) * 3 +
           s->tet_count * (4 * sizeof(uint32_t) + 2 * sizeof(pose__vol_box));
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

/* The index range [lo, hi] of voxel centres within [vmin, vmax] (widened
 * by the barycentric tolerance) on an axis of n voxels; lo > hi if none.
 * Clamped before converting: posed coordinates may lie far outside the
 * int range. Returns 0 when the range is empty or a coordinate is NaN (a
 * state gone bad covers nothing). */
static inline int axis_range(float vmin, float vmax, int n, int32_t *lo, int32_t *hi)
{
    float a = vmin - 1e-4f, b = vmax + 1e-4f;
    if (!(a <= b)) /* NaN */
        return 0;
    a = a > -1.0f ? a : -1.0f;
    b = b < (float)n ? b : (float)n;
    if (!(a <= b))
        return 0;
    int ia = (int)a, ib = (int)b;
    ia += (float)ia < a;
    ib -= (float)ib > b;
    *lo = ia > 0 ? ia : 0;
    *hi = ib < n - 1 ? ib : n - 1;
    return *lo <= *hi;
}

static inline float min4f(float a, float b, float c, float d)
{
    a = b < a ? b : a;
    c = d < c ? d : c;
    return c < a ? c : a;
}

static inline float max4f(float a, float b, float c, float d)
{
    a = b > a ? b : a;
    c = d > c ? d : c;
    return c > a ? c : a;
}

/* Pass 2: the box of output voxel centres of every posed tet, and whether
 * it lies where it rests (parts of whole blocks: then whether the blocks
 * of the rest cover are still). */
static void box_task(void *ctx, unsigned part, unsigned parts)
{
    pose_volume_sampler *s = ctx;
    const size_t blocks = (s->tet_count + ((size_t)1 << s->block_shift) - 1) >> s->block_shift;
    const size_t block0 = pose__part_begin(blocks, part, parts);
    const size_t block1 = pose__part_begin(blocks, part + 1, parts);
    const size_t b = block0 << s->block_shift < s->tet_count ? block0 << s->block_shift : s->tet_count;
    const size_t e = block1 << s->block_shift < s->tet_count ? block1 << s->block_shift : s->tet_count;
    const int nx = (int)s->out.nx, ny = (int)s->out.ny, nz = (int)s->out.nz;
    const float *P = s->posed_index, *R = s->rest_index;
    for (size_t t = b; t < e; t++) {
        const uint32_t *tv = s->tets + 4 * t;
        const float *q0 = P + 3 * (size_t)tv[0], *q1 = P + 3 * (size_t)tv[1],
                    *q2 = P + 3 * (size_t)tv[2], *q3 = P + 3 * (size_t)tv[3];
        pose__vol_box *bx = &s->boxes[t];
        bx->identity = !memcmp(q0, R + 3 * (size_t)tv[0], 3 * sizeof *q0) &&
                       !memcmp(q1, R + 3 * (size_t)tv[1], 3 * sizeof *q1) &&
                       !memcmp(q2, R + 3 * (size_t)tv[2], 3 * sizeof *q2) &&
                       !memcmp(q3, R + 3 * (size_t)tv[3], 3 * sizeof *q3);
        if (!axis_range(min4f(q0[2], q1[2], q2[2], q3[2]), max4f(q0[2], q1[2], q2[2], q3[2]), nz,
                        &bx->k0, &bx->k1) ||
            !axis_range(min4f(q0[1], q1[1], q2[1], q3[1]), max4f(q0[1], q1[1], q2[1], q3[1]), ny,
                        &bx->j0, &bx->j1) ||
            !axis_range(min4f(q0[0], q1[0], q2[0], q3[0]), max4f(q0[0], q1[0], q2[0], q3[0]), nx,
                        &bx->i0, &bx->i1))
            bx->k0 = INT32_MAX, bx->k1 = INT32_MIN;
    }
    if (s->owner)
        pose__vol_rest_cover_blocks(s, block0, block1);
}

/* Pass 3: one z-slab per part: every tet whose box meets the slab, in
 * reverse index order; a voxel already covered keeps its value (see
 * volume_raster_body.h), so a voxel inside two posed tets takes the later
 * one and is sampled once. With a rest cover, the tets of still blocks
 * are not rasterized: their voxels are copied after the others, where no
 * moved tet took them (volume_rest_cover.c). */
static void slab_task(void *ctx, unsigned part, unsigned parts)
{
    pose_volume_sampler *s = ctx;
    const int z0 = (int)pose__part_begin(s->out.nz, part, parts);
    const int z1 = (int)pose__part_begin(s->out.nz, part + 1, parts) - 1;
    if (z0 > z1)
        return;
    const int copy_still = s->owner && !s->owner_building;
    const size_t plane = s->cover_words * s->out.ny;
    memset(pose__vol_cover_row(s, 0, (size_t)z0), 0, (size_t)(z1 - z0 + 1) * plane * sizeof(uint64_t));
    const pose__vol_box *bx = s->boxes;
    const uint8_t *still = s->block_still;
    const unsigned shift = s->block_shift;
    pose__vol_stage *st = &s->stages[part];
    st->n = 0;
    void (*raster)(const pose_volume_sampler *, size_t, const pose__vol_box *, int, int,
                   pose__vol_stage *) = pose__volume_raster_tet_generic;
#ifdef POSE__HAVE_AVX2_VOLUME
    if (s->use_avx2)
        raster = pose__volume_raster_tet_avx2;
#endif
    for (size_t t = s->tet_count; t-- > 0;) {
        if (bx[t].k1 < z0 || bx[t].k0 > z1 || (copy_still && still[t >> shift]))
            continue;
        raster(s, t, &bx[t], bx[t].k0 > z0 ? bx[t].k0 : z0, bx[t].k1 < z1 ? bx[t].k1 : z1, st);
    }
    pose__volume_gather(s, st);
    if (copy_still)
        pose__vol_rest_cover_copy(s, (size_t)z0, (size_t)z1 + 1);
}

static inline int covered_at(const pose_volume_sampler *s, size_t i, size_t j, size_t k)
{
    return (int)(pose__vol_cover_row(s, j, k)[i >> 6] >> (i & 63)) & 1;
}

/* Pass 4, the voxels no tet covered. One whose six neighbours all are
 * covered sits in a crack of the mesh (a centre on a sliver or a
 * coarsening seam that float rounding left out of every tet), not outside
 * the body: it takes its neighbours' mean intensity and its -x neighbour's
 * label. The others are background. Whole words of covered bits are
 * skipped at once, and a full word with none set is background throughout
 * (each of its voxels has an uncovered neighbour in the row). Reads only
 * covered voxels, which this pass never writes: any thread count gives the
 * same bytes. */
static void fill_task(void *ctx, unsigned part, unsigned parts)
{
    pose_volume_sampler *s = ctx;
    const size_t nx = s->out.nx, ny = s->out.ny, nz = s->out.nz, sy = nx, sz = nx * ny;
    const size_t z0 = pose__part_begin(nz, part, parts), z1 = pose__part_begin(nz, part + 1, parts);
    float *di = s->dst_intensity;
    uint16_t *dl = s->dst_labels;
    const float bi = s->rest.intensity_background;
    const uint16_t bl = s->rest.label_background;
    for (size_t k = z0; k < z1; k++)
        for (size_t j = 0; j < ny; j++) {
            const uint64_t *w = pose__vol_cover_row(s, j, k);
            const size_t row = k * sz + j * sy;
            const int inner = k > 0 && k + 1 < nz && j > 0 && j + 1 < ny;
            for (size_t x = 0; x < s->cover_words; x++) {
                const size_t i0 = 64 * x, n = nx - i0 < 64 ? nx - i0 : 64;
                const uint64_t all = n == 64 ? ~(uint64_t)0 : ((uint64_t)1 << n) - 1;
                uint64_t open = ~w[x] & all;
                if (open == all && n == 64) {
                    if (di)
                        for (size_t v = row + i0; v < row + i0 + 64; v++)
                            di[v] = bi;
                    if (dl)
                        for (size_t v = row + i0; v < row + i0 + 64; v++)
                            dl[v] = bl;
                    continue;
                }
                for (; open; open &= open - 1) {
                    const size_t i = i0 + (size_t)__builtin_ctzll(open), v = row + i;
                    if (inner && i > 0 && i + 1 < nx && covered_at(s, i - 1, j, k) &&
                        covered_at(s, i + 1, j, k) && covered_at(s, i, j - 1, k) &&
                        covered_at(s, i, j + 1, k) && covered_at(s, i, j, k - 1) &&
                        covered_at(s, i, j, k + 1)) {
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
}

/* The rest cover's owners: the rest pose through the box and slab passes,
 * every tet lying where it rests (creation, once). */
static void build_rest_cover(pose_volume_sampler *s)
{
    memcpy(s->posed_index, s->rest_index, 3 * s->vertex_count * sizeof(float));
    s->owner_building = 1;
    pose__pool_run(s->pool, box_task, s);
    pose__pool_run(s->pool, slab_task, s);
    s->owner_building = 0;
    pose__vol_rest_cover_rows(s);
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
    pose__pool_run(s->pool, box_task, s);
    pose__pool_run(s->pool, slab_task, s);
    pose__pool_run(s->pool, fill_task, s);
    s->posed = NULL;
    s->dst_intensity = NULL;
    s->dst_labels = NULL;
    return POSE_OK;
}
