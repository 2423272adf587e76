/* SPDX-License-Identifier: Apache-2.0 */
#include "cor_fast.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* A tet's mean weights have at most 4 K distinct joints. */
#define MAX_SUPPORT (4 * PP_MAX_INFLUENCES)

typedef struct sparse_w {
    int n;
    uint16_t j[MAX_SUPPORT]; /* ascending */
    double w[MAX_SUPPORT];
} sparse_w;

static void vertex_weights(const pp_weights *w, size_t v, sparse_w *out)
{
    out->n = 0;
    for (unsigned k = 0; k < w->influences; k++) {
        float x = w->weights[v * w->influences + k];
        if (!(x > 0))
            continue;
        uint16_t j = w->joints[v * w->influences + k];
        int i = out->n++;
        while (i > 0 && out->j[i - 1] > j) {
            out->j[i] = out->j[i - 1];
            out->w[i] = out->w[i - 1];
            i--;
        }
        out->j[i] = j;
        out->w[i] = x;
    }
}

static void tet_mean_weights(const pp_tetmesh *m, const pp_weights *w, size_t t, sparse_w *out)
{
    out->n = 0;
    for (int c = 0; c < 4; c++) {
        size_t v = m->tets[4 * t + c];
        for (unsigned k = 0; k < w->influences; k++) {
            float x = w->weights[v * w->influences + k];
            if (!(x > 0))
                continue;
            uint16_t j = w->joints[v * w->influences + k];
            int i = 0;
            while (i < out->n && out->j[i] < j)
                i++;
            if (i < out->n && out->j[i] == j) {
                out->w[i] += 0.25 * x;
                continue;
            }
            memmove(out->j + i + 1, out->j + i, (size_t)(out->n - i) * sizeof out->j[0]);
            memmove(out->w + i + 1, out->w + i, (size_t)(out->n - i) * sizeof out->w[0]);
            out->j[i] = j;
            out->w[i] = 0.25 * x;
            out->n++;
        }
    }
}

/* s(a, b): over unordered joint pairs shared by both, times two (the
 * formula sums ordered pairs i != j and each term is symmetric). */
static double similarity(const uint16_t *aj, const double *aw, int an, const uint16_t *bj,
                         const double *bw, int bn, double inv_sigma2)
{
    double ca[MAX_SUPPORT], cb[MAX_SUPPORT];
    int n = 0;
    for (int x = 0, y = 0; x < an && y < bn;) {
        if (aj[x] < bj[y])
            x++;
        else if (aj[x] > bj[y])
            y++;
        else {
            ca[n] = aw[x++];
            cb[n++] = bw[y++];
        }
    }
    double s = 0;
    for (int i = 0; i < n; i++)
        for (int k = i + 1; k < n; k++) {
            double d = ca[i] * cb[k] - cb[i] * ca[k];
            s += ca[i] * ca[k] * cb[i] * cb[k] * exp(-d * d * inv_sigma2);
        }
    return 2 * s;
}

static double tet_volume_centroid(const pp_tetmesh *m, size_t t, double c[3])
{
    const float *p[4];
    for (int i = 0; i < 4; i++)
        p[i] = m->positions + 3 * (size_t)m->tets[4 * t + i];
    double a[3], b[3], d[3];
    for (int k = 0; k < 3; k++) {
        a[k] = (double)p[1][k] - p[0][k];
        b[k] = (double)p[2][k] - p[0][k];
        d[k] = (double)p[3][k] - p[0][k];
        c[k] = 0.25 * ((double)p[0][k] + p[1][k] + p[2][k] + p[3][k]);
    }
    double det = a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) +
                 a[2] * (b[0] * d[1] - b[1] * d[0]);
    return fabs(det) / 6.0;
}

int pp_cor_naive_vertices(const pp_tetmesh *m, const pp_weights *w, double sigma,
                          const uint32_t *vertices, size_t count, float *cor)
{
    double inv = 1.0 / (sigma * sigma);
    sparse_w *tw = malloc((m->tet_count ? m->tet_count : 1) * sizeof *tw);
    if (!tw)
        return POSE_ERR_OUT_OF_MEMORY;
    for (size_t t = 0; t < m->tet_count; t++)
        tet_mean_weights(m, w, t, &tw[t]);
    for (size_t i = 0; i < count; i++) {
        size_t v = vertices ? vertices[i] : i;
        sparse_w wp;
        vertex_weights(w, v, &wp);
        double num[3] = {0}, den = 0;
        if (wp.n >= 2)
            for (size_t t = 0; t < m->tet_count; t++) {
                double s = similarity(wp.j, wp.w, wp.n, tw[t].j, tw[t].w, tw[t].n, inv);
                if (s == 0)
                    continue;
                double c[3], vol = tet_volume_centroid(m, t, c);
                for (int k = 0; k < 3; k++)
                    num[k] += s * vol * c[k];
                den += s * vol;
            }
        for (int k = 0; k < 3; k++)
            cor[3 * i + k] = den > 0 ? (float)(num[k] / den) : m->positions[3 * v + k];
    }
    free(tw);
    return POSE_OK;
}

int pp_cor_naive(const pp_tetmesh *m, const pp_weights *w, double sigma, float *cor)
{
    return pp_cor_naive_vertices(m, w, sigma, NULL, m->vertex_count, cor);
}

/* ---- pair bins ----------------------------------------------------- */

/* Raw sums while binning, turned into evaluation form by finish_bins. */
typedef struct bin_acc {
    uint64_t key;
    double v, vc[3], vb[2], vcb[2][3];
} bin_acc;

/* Evaluation form: mean weights of the pair's two joints, Σ V, Σ V c and
 * the first moments Σ V c (b_k - mean_k). */
typedef struct bin {
    double b[2], v, vc[3], m[2][3];
} bin;

#define MAX_JOINTS 1024u
#define Q_BITS 20

typedef struct bin_table {
    uint64_t *keys; /* open addressing, key + 1 (0 = empty) */
    uint32_t *slot; /* bin index per occupied key */
    size_t cap;
    bin_acc *acc;
    size_t count, acc_cap;
} bin_table;

static uint64_t mix64(uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdull;
    x ^= x >> 33;
    x *= 0xc4ceb3f99c6b32e3ull;
    return x ^ (x >> 33);
}

static int table_grow(bin_table *t)
{
    size_t cap = t->cap ? 2 * t->cap : 1u << 16;
    uint64_t *keys = calloc(cap, sizeof *keys);
    uint32_t *slot = malloc(cap * sizeof *slot);
    if (!keys || !slot) {
        free(keys), free(slot);
        return -1;
    }
    for (size_t i = 0; i < t->cap; i++)
        if (t->keys[i]) {
            size_t h = mix64(t->keys[i]) & (cap - 1);
            while (keys[h])
                h = (h + 1) & (cap - 1);
            keys[h] = t->keys[i];
            slot[h] = t->slot[i];
        }
    free(t->keys);
    free(t->slot);
    t->keys = keys;
    t->slot = slot;
    t->cap = cap;
    return 0;
}

/* The accumulator for key (created zeroed), or NULL when out of memory. */
static bin_acc *table_get(bin_table *t, uint64_t key)
{
    if (2 * (t->count + 1) > t->cap && table_grow(t) < 0)
        return NULL;
    size_t h = mix64(key + 1) & (t->cap - 1);
    while (t->keys[h]) {
        if (t->keys[h] == key + 1)
            return &t->acc[t->slot[h]];
        h = (h + 1) & (t->cap - 1);
    }
    if (t->count == t->acc_cap) {
        size_t c = t->acc_cap ? 2 * t->acc_cap : 1u << 14;
        bin_acc *a = realloc(t->acc, c * sizeof *a);
        if (!a)
            return NULL;
        t->acc = a;
        t->acc_cap = c;
    }
    t->keys[h] = key + 1;
    t->slot[h] = (uint32_t)t->count;
    bin_acc *a = &t->acc[t->count++];
    memset(a, 0, sizeof *a);
    a->key = key;
    return a;
}

static int cmp_acc(const void *x, const void *y)
{
    uint64_t a = ((const bin_acc *)x)->key, b = ((const bin_acc *)y)->key;
    return a < b ? -1 : a > b;
}

/* Per (pair, vertex-weight cell) results: num[3], den, and their
 * derivatives along a_i and a_j (num_i[3], den_i, num_j[3], den_j). */
enum { CELL_RESULT = 12 };

typedef struct cor_ctx {
    const uint32_t *pair_start; /* bins of pair p: [pair_start[p], pair_start[p + 1]) */
    const bin *bins;
    const bin_acc *cells;       /* key (pair in the top bits), Σ a_i, Σ a_j, count in v */
    double *result;             /* CELL_RESULT per cell */
    double inv_sigma2;
} cor_ctx;

typedef struct cor_job {
    const cor_ctx *ctx;
    size_t begin, end;
    size_t evaluations;
} cor_job;

/* Evaluate each cell's pair sums at its mean (a_i, a_j), with the
 * derivatives a vertex needs to correct for its own offset from the mean.
 * The pair term is a_i a_j g(a, b) with g = b_i b_j exp(-d²/σ²); the cell
 * sums g only and each vertex multiplies by its own a_i a_j, because a
 * vertex with a tiny weight is far (relatively) from its cell's mean and a
 * linear correction of the product would overshoot. */
static void *cor_run(void *arg)
{
    cor_job *job = arg;
    const cor_ctx *c = job->ctx;
    const double k2 = 2 * c->inv_sigma2;
    for (size_t k = job->begin; k < job->end; k++) {
        const bin_acc *cell = &c->cells[k];
        const double ai = cell->vb[0] / cell->v, aj = cell->vb[1] / cell->v;
        uint64_t p = cell->key >> 40;
        const bin *b = c->bins + c->pair_start[p], *e = c->bins + c->pair_start[p + 1];
        double r[CELL_RESULT] = {0};
        job->evaluations += (size_t)(e - b);
        for (; b < e; b++) {
            const double bi = b->b[0], bj = b->b[1], bb = bi * bj;
            const double d = ai * bj - bi * aj;
            const double x = exp(-d * d * c->inv_sigma2);
            const double g = bb * x;
            /* ∂g/∂b (first-order bin moments) and ∂g/∂a (vertex offsets). */
            const double gi = x * (bj + k2 * bb * aj * d), gj = x * (bi - k2 * bb * ai * d);
            const double fi = -k2 * g * d * bj, fj = k2 * g * d * bi;
            for (int q = 0; q < 3; q++) {
                r[q] += g * b->vc[q] + gi * b->m[0][q] + gj * b->m[1][q];
                r[4 + q] += fi * b->vc[q];
                r[8 + q] += fj * b->vc[q];
            }
            r[3] += g * b->v;
            r[7] += fi * b->v;
            r[11] += fj * b->v;
        }
        memcpy(c->result + CELL_RESULT * k, r, sizeof r);
    }
    return NULL;
}

static int run_jobs(cor_ctx *ctx, size_t count, int threads, size_t *evaluations)
{
    if (threads > 64)
        threads = 64;
    if ((size_t)threads > count / 16 + 1)
        threads = (int)(count / 16 + 1);
    cor_job jobs[64];
    pthread_t tid[64];
    int started = 0;
    for (int i = 0; i < threads; i++)
        jobs[i] = (cor_job){ctx, count * (size_t)i / (size_t)threads,
                            count * (size_t)(i + 1) / (size_t)threads, 0};
    for (int i = 1; i < threads; i++) {
        if (pthread_create(&tid[i], NULL, cor_run, &jobs[i]) != 0) {
            for (int q = i; q < threads; q++)
                cor_run(&jobs[q]);
            break;
        }
        started = i;
    }
    cor_run(&jobs[0]);
    for (int i = 1; i <= started; i++)
        pthread_join(tid[i], NULL);
    for (int i = 0; i < threads; i++)
        *evaluations += jobs[i].evaluations;
    return 0;
}

/* Key of a vertex's cell for one pair: quantized (a_i, a_j), or in exact
 * mode the vertex itself (so the cell mean is the vertex's own weights). */
static uint64_t cell_key(uint32_t pair, double ai, double aj, double inv_step, size_t v)
{
    if (inv_step == 0)
        return ((uint64_t)pair << 40) | (uint64_t)v;
    uint64_t qi = (uint64_t)(ai * inv_step), qj = (uint64_t)(aj * inv_step);
    return ((uint64_t)pair << 40) | (qi << Q_BITS) | qj;
}

int pp_cor_compute(const pp_tetmesh *m, const pp_weights *w, const pp_cor_options *opt,
                   float *cor, pp_cor_report *rep_out, char *err, size_t err_size)
{
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    pp_cor_report rep;
    memset(&rep, 0, sizeof rep);
    double sigma = opt && opt->sigma > 0 ? opt->sigma : 0.1;
    double step = opt && opt->tolerance != 0 ? opt->tolerance : 1.0 / 128;
    int exact = step < 0;
    double inv_step = exact ? 0 : 1.0 / step;
    double cstep = opt && opt->cell_tolerance > 0 ? opt->cell_tolerance : step;
    double inv_cell = exact ? 0 : 1.0 / cstep;
    int threads = opt && opt->threads > 1 ? opt->threads : 1;
    size_t n = m->vertex_count, nt = m->tet_count;
    if (w->vertex_count != n) {
        snprintf(err, err_size, "cor: weights for %zu vertices, mesh has %zu", w->vertex_count, n);
        return POSE_ERR_INVALID_ARGUMENT;
    }
    if (!exact && !(inv_step >= 1 && inv_step < (double)(1u << Q_BITS) && inv_cell >= 1 &&
                    inv_cell < (double)(1u << Q_BITS))) {
        snprintf(err, err_size, "cor: bin step %g out of range (%g..1)", step,
                 1.0 / (1u << Q_BITS));
        return POSE_ERR_INVALID_ARGUMENT;
    }
    uint32_t joints = 0;
    for (size_t i = 0; i < n * w->influences; i++)
        joints = w->joints[i] + 1u > joints ? w->joints[i] + 1u : joints;
    if (joints > MAX_JOINTS) {
        snprintf(err, err_size, "cor: %u joints; at most %u", joints, MAX_JOINTS);
        return POSE_ERR_INVALID_ARGUMENT;
    }
    int rc = POSE_OK;
    bin_table tab = {0};
    int32_t *pair_id = malloc((size_t)joints * joints * sizeof *pair_id + 1);
    uint32_t *pair_start = NULL;
    bin *bins = NULL;
    double *result = NULL;
    if (!pair_id)
        goto oom;
    for (size_t i = 0; i < (size_t)joints * joints; i++)
        pair_id[i] = -1;

    /* 1. File every (tet, joint pair) into its bin. Exact mode keys by the
     *    (tet, pair) itself so no two tets merge. */
    uint32_t npairs = 0;
    size_t entry = 0;
    for (size_t t = 0; t < nt; t++) {
        sparse_w s;
        tet_mean_weights(m, w, t, &s);
        if (s.n < 2)
            continue;
        rep.tets_used++;
        double c[3], vol = tet_volume_centroid(m, t, c);
        for (int x = 0; x < s.n; x++)
            for (int y = x + 1; y < s.n; y++) {
                int32_t *pid = &pair_id[(size_t)s.j[x] * joints + s.j[y]];
                if (*pid < 0)
                    *pid = (int32_t)npairs++;
                uint64_t key;
                if (exact) {
                    key = ((uint64_t)*pid << 40) | (uint64_t)entry++;
                } else {
                    uint64_t qi = (uint64_t)(s.w[x] * inv_step), qj = (uint64_t)(s.w[y] * inv_step);
                    key = ((uint64_t)*pid << 40) | (qi << Q_BITS) | qj;
                }
                bin_acc *a = table_get(&tab, key);
                if (!a)
                    goto oom;
                a->v += vol;
                for (int q = 0; q < 3; q++) {
                    a->vc[q] += vol * c[q];
                    a->vcb[0][q] += vol * c[q] * s.w[x];
                    a->vcb[1][q] += vol * c[q] * s.w[y];
                }
                a->vb[0] += vol * s.w[x];
                a->vb[1] += vol * s.w[y];
            }
    }
    rep.pairs = npairs;
    rep.bins = tab.count;

    /* 2. Pair-major order; mean weights and centred moments per bin. The
     *    pair id occupies the key's top bits, so a sort groups the pairs. */
    qsort(tab.acc, tab.count, sizeof *tab.acc, cmp_acc);
    pair_start = calloc((size_t)npairs + 1, sizeof *pair_start);
    bins = malloc((tab.count ? tab.count : 1) * sizeof *bins);
    if (!pair_start || !bins)
        goto oom;
    for (size_t i = 0; i < tab.count; i++) {
        const bin_acc *a = &tab.acc[i];
        bin *b = &bins[i];
        pair_start[(a->key >> 40) + 1]++;
        double inv = a->v > 0 ? 1.0 / a->v : 0;
        b->v = a->v;
        for (int k = 0; k < 2; k++)
            b->b[k] = a->vb[k] * inv;
        for (int q = 0; q < 3; q++) {
            b->vc[q] = a->vc[q];
            for (int k = 0; k < 2; k++)
                b->m[k][q] = a->vcb[k][q] - b->b[k] * a->vc[q];
        }
    }
    for (uint32_t p = 0; p < npairs; p++)
        pair_start[p + 1] += pair_start[p];
    free(tab.acc);
    free(tab.keys);
    free(tab.slot);
    memset(&tab, 0, sizeof tab); /* reused for the vertex cells */

    /* 3. Vertex cells: per pair, vertices with nearby (a_i, a_j) share one
     *    evaluation at their mean, corrected to first order per vertex; the
     *    number of cells saturates while the vertex count grows. */
    for (size_t v = 0; v < n; v++) {
        sparse_w s;
        vertex_weights(w, v, &s);
        if (s.n < 2)
            continue;
        rep.vertices_with_cor++;
        for (int x = 0; x < s.n; x++)
            for (int y = x + 1; y < s.n; y++) {
                int32_t p = pair_id[(size_t)s.j[x] * joints + s.j[y]];
                if (p < 0)
                    continue;
                bin_acc *a = table_get(&tab, cell_key((uint32_t)p, s.w[x], s.w[y], inv_cell, v));
                if (!a)
                    goto oom;
                a->vb[0] += s.w[x];
                a->vb[1] += s.w[y];
                a->v += 1;
            }
    }
    rep.cells = tab.count;
    result = malloc((tab.count ? tab.count : 1) * CELL_RESULT * sizeof *result);
    if (!result)
        goto oom;
    cor_ctx ctx = {pair_start, bins, tab.acc, result, 1.0 / (sigma * sigma)};
    run_jobs(&ctx, tab.count, threads, &rep.evaluations);

    /* 4. Each vertex sums its pairs' cells. */
    for (size_t v = 0; v < n; v++) {
        sparse_w s;
        vertex_weights(w, v, &s);
        double num[3] = {0}, den = 0;
        for (int x = 0; x < s.n; x++)
            for (int y = x + 1; y < s.n; y++) {
                int32_t p = pair_id[(size_t)s.j[x] * joints + s.j[y]];
                if (p < 0)
                    continue;
                const bin_acc *a = table_get(&tab, cell_key((uint32_t)p, s.w[x], s.w[y], inv_cell, v));
                const double *r = result + CELL_RESULT * (size_t)(a - tab.acc);
                double di = s.w[x] - a->vb[0] / a->v, dj = s.w[y] - a->vb[1] / a->v;
                double aa = s.w[x] * s.w[y];
                for (int q = 0; q < 3; q++)
                    num[q] += aa * (r[q] + di * r[4 + q] + dj * r[8 + q]);
                den += aa * (r[3] + di * r[7] + dj * r[11]);
            }
        for (int q = 0; q < 3; q++)
            cor[3 * v + q] = s.n >= 2 && den > 0 ? (float)(num[q] / den) : m->positions[3 * v + q];
    }
    goto done;
oom:
    snprintf(err, err_size, "cor: out of memory");
    rc = POSE_ERR_OUT_OF_MEMORY;
done:
    free(tab.keys);
    free(tab.slot);
    free(tab.acc);
    free(pair_id);
    free(pair_start);
    free(bins);
    free(result);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    rep.seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (rep_out)
        *rep_out = rep;
    return rc;
}
