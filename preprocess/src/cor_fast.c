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

int pp_cor_naive(const pp_tetmesh *m, const pp_weights *w, double sigma, float *cor)
{
    double inv = 1.0 / (sigma * sigma);
    sparse_w *tw = malloc(m->tet_count * sizeof *tw);
    if (!tw)
        return POSE_ERR_OUT_OF_MEMORY;
    for (size_t t = 0; t < m->tet_count; t++)
        tet_mean_weights(m, w, t, &tw[t]);
    for (size_t v = 0; v < m->vertex_count; v++) {
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
            cor[3 * v + k] = den > 0 ? (float)(num[k] / den) : m->positions[3 * v + k];
    }
    free(tw);
    return POSE_OK;
}

/* ---- clustering ---------------------------------------------------- */

/* Clusters in structure-of-arrays form with variable-length joint lists
 * (a few joints each), so millions of them stay compact. */
typedef struct clusters {
    size_t count;
    uint32_t *off;   /* count + 1 into joints/weights */
    uint16_t *joints;
    double *weights; /* volume-weighted mean */
    double *vol;     /* Σ V */
    double *vc;      /* Σ V c, 3 per cluster */
} clusters;

typedef struct keyed {
    uint64_t hash;
    uint32_t item;   /* tet or vertex */
    uint32_t off;    /* into the key pool */
    uint8_t n;
} keyed;

typedef struct key_pool {
    uint16_t *j;
    int32_t *q;
} key_pool;

/* qsort has no context argument in C11: the pool travels thread-locally. */
static _Thread_local const key_pool *g_sort_pool;

static int cmp_keyed(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->hash != y->hash)
        return x->hash < y->hash ? -1 : 1;
    if (x->n != y->n)
        return x->n < y->n ? -1 : 1;
    int c = memcmp(g_sort_pool->j + x->off, g_sort_pool->j + y->off, x->n * sizeof(uint16_t));
    if (c)
        return c;
    c = memcmp(g_sort_pool->q + x->off, g_sort_pool->q + y->off, x->n * sizeof(int32_t));
    if (c)
        return c;
    return x->item < y->item ? -1 : x->item > y->item;
}

static int same_key(const key_pool *p, const keyed *x, const keyed *y)
{
    return x->hash == y->hash && x->n == y->n &&
           !memcmp(p->j + x->off, p->j + y->off, x->n * sizeof(uint16_t)) &&
           !memcmp(p->q + x->off, p->q + y->off, x->n * sizeof(int32_t));
}

static void make_key(const sparse_w *s, double inv_tol, key_pool *pool, keyed *k, uint32_t item,
                     uint32_t off)
{
    uint64_t h = 1469598103934665603ull;
    for (int i = 0; i < s->n; i++) {
        int32_t q = inv_tol > 0 ? (int32_t)lrint(s->w[i] * inv_tol) : (int32_t)item;
        pool->j[off + i] = s->j[i];
        pool->q[off + i] = q;
        h = (h ^ s->j[i]) * 1099511628211ull;
        h = (h ^ (uint32_t)q) * 1099511628211ull;
    }
    *k = (keyed){h, item, off, (uint8_t)s->n};
}

typedef struct pair_entry {
    uint32_t pair; /* i * joints + j, i < j */
    uint32_t cluster;
} pair_entry;

static int cmp_pair(const void *a, const void *b)
{
    const pair_entry *x = a, *y = b;
    if (x->pair != y->pair)
        return x->pair < y->pair ? -1 : 1;
    return x->cluster < y->cluster ? -1 : x->cluster > y->cluster;
}

typedef struct cor_ctx {
    const pp_tetmesh *mesh;
    const pp_weights *w;
    const clusters *cl;
    const pair_entry *pairs;
    size_t pair_count;
    uint32_t joints;
    double inv_sigma2;
    const uint32_t *eval_vertex; /* representative vertex per evaluation */
    double *eval_cor;            /* 3 per evaluation */
    size_t eval_count;
} cor_ctx;

typedef struct cor_job {
    const cor_ctx *ctx;
    size_t begin, end;
    uint32_t *stamp; /* per thread, one per cluster: visit each cluster once per vertex */
} cor_job;

static size_t lower_pair(const pair_entry *p, size_t n, uint32_t key)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (p[mid].pair < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

static void *cor_run(void *arg)
{
    cor_job *job = arg;
    const cor_ctx *c = job->ctx;
    uint32_t *stamp = job->stamp;
    for (size_t e = job->begin; e < job->end; e++) {
        uint32_t v = c->eval_vertex[e];
        sparse_w wp;
        vertex_weights(c->w, v, &wp);
        double num[3] = {0}, den = 0;
        uint32_t mark = (uint32_t)(e - job->begin) + 1;
        for (int a = 0; a < wp.n; a++)
            for (int b = a + 1; b < wp.n; b++) {
                uint32_t key = (uint32_t)wp.j[a] * c->joints + wp.j[b];
                for (size_t i = lower_pair(c->pairs, c->pair_count, key);
                     i < c->pair_count && c->pairs[i].pair == key; i++) {
                    uint32_t k = c->pairs[i].cluster;
                    if (stamp[k] == mark)
                        continue; /* shares another pair with this vertex: done */
                    stamp[k] = mark;
                    uint32_t o = c->cl->off[k], n = c->cl->off[k + 1] - o;
                    double s = similarity(wp.j, wp.w, wp.n, c->cl->joints + o, c->cl->weights + o,
                                          (int)n, c->inv_sigma2);
                    den += s * c->cl->vol[k];
                    for (int q = 0; q < 3; q++)
                        num[q] += s * c->cl->vc[3 * (size_t)k + q];
                }
            }
        for (int q = 0; q < 3; q++)
            c->eval_cor[3 * e + q] =
                den > 0 ? num[q] / den : (double)c->mesh->positions[3 * (size_t)v + q];
    }
    return NULL;
}

static void clusters_free(clusters *c)
{
    free(c->off);
    free(c->joints);
    free(c->weights);
    free(c->vol);
    free(c->vc);
    memset(c, 0, sizeof *c);
}

int pp_cor_compute(const pp_tetmesh *m, const pp_weights *w, const pp_cor_options *opt,
                   float *cor, pp_cor_report *rep_out, char *err, size_t err_size)
{
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    pp_cor_report rep;
    memset(&rep, 0, sizeof rep);
    double sigma = opt && opt->sigma > 0 ? opt->sigma : 0.1;
    double tol = opt && opt->tolerance != 0 ? opt->tolerance : 1e-4;
    double inv_tol = tol > 0 ? 1.0 / tol : 0;
    int threads = opt && opt->threads > 1 ? opt->threads : 1;
    size_t n = m->vertex_count, nt = m->tet_count;
    uint32_t joints = 0;
    for (size_t i = 0; i < n * w->influences; i++)
        joints = w->joints[i] + 1u > joints ? w->joints[i] + 1u : joints;
    if (w->vertex_count != n || n > UINT32_MAX || nt > UINT32_MAX) {
        snprintf(err, err_size, "cor: weights for %zu vertices, mesh has %zu", w->vertex_count, n);
        return POSE_ERR_INVALID_ARGUMENT;
    }
    int rc = POSE_OK;
    clusters cl = {0};
    keyed *keys = NULL, *vkeys = NULL;
    key_pool pool = {0}, vpool = {0};
    pair_entry *pairs = NULL;
    uint32_t *eval_vertex = NULL, *vertex_eval = NULL, *stamps = NULL;
    double *eval_cor = NULL;
    size_t maxs = 4 * (size_t)w->influences;

    /* 1. Tets with >= 2 joints, keyed by joint set and quantized weights. */
    keys = malloc((nt ? nt : 1) * sizeof *keys);
    pool.j = malloc((nt * maxs + 1) * sizeof *pool.j);
    pool.q = malloc((nt * maxs + 1) * sizeof *pool.q);
    if (!keys || !pool.j || !pool.q)
        goto oom;
    size_t used = 0, poff = 0;
    for (size_t t = 0; t < nt; t++) {
        sparse_w s;
        tet_mean_weights(m, w, t, &s);
        if (s.n < 2)
            continue;
        make_key(&s, inv_tol, &pool, &keys[used++], (uint32_t)t, (uint32_t)poff);
        poff += (size_t)s.n;
    }
    rep.tets_used = used;
    g_sort_pool = &pool;
    qsort(keys, used, sizeof *keys, cmp_keyed);
    size_t ncl = 0;
    for (size_t i = 0; i < used; i++)
        ncl += i == 0 || !same_key(&pool, &keys[i - 1], &keys[i]);
    cl.count = ncl;
    cl.off = malloc((ncl + 1) * sizeof *cl.off);
    cl.joints = malloc((poff + 1) * sizeof *cl.joints);
    cl.weights = calloc(poff + 1, sizeof *cl.weights);
    cl.vol = calloc(ncl + 1, sizeof *cl.vol);
    cl.vc = calloc(3 * ncl + 1, sizeof *cl.vc);
    if (!cl.off || !cl.joints || !cl.weights || !cl.vol || !cl.vc)
        goto oom;
    size_t k = (size_t)-1, coff = 0;
    for (size_t i = 0; i < used; i++) {
        if (i == 0 || !same_key(&pool, &keys[i - 1], &keys[i])) {
            k++;
            cl.off[k] = (uint32_t)coff;
            memcpy(cl.joints + coff, pool.j + keys[i].off, keys[i].n * sizeof *cl.joints);
            coff += keys[i].n;
        }
        sparse_w s;
        tet_mean_weights(m, w, keys[i].item, &s);
        double c[3], vol = tet_volume_centroid(m, keys[i].item, c);
        cl.vol[k] += vol;
        for (int q = 0; q < 3; q++)
            cl.vc[3 * k + q] += vol * c[q];
        for (int q = 0; q < s.n; q++)
            cl.weights[cl.off[k] + (size_t)q] += vol * s.w[q];
    }
    cl.off[ncl] = (uint32_t)coff;
    for (size_t c = 0; c < ncl; c++)
        for (uint32_t q = cl.off[c]; q < cl.off[c + 1]; q++)
            cl.weights[q] = cl.vol[c] > 0 ? cl.weights[q] / cl.vol[c] : 0;
    rep.clusters = ncl;
    free(keys);
    keys = NULL;
    free(pool.j);
    free(pool.q);
    pool.j = NULL;
    pool.q = NULL;

    /* 2. Joint-pair lists of clusters. */
    size_t npairs = 0;
    for (size_t c = 0; c < ncl; c++) {
        size_t s = cl.off[c + 1] - cl.off[c];
        npairs += s * (s - 1) / 2;
    }
    pairs = malloc((npairs ? npairs : 1) * sizeof *pairs);
    if (!pairs)
        goto oom;
    size_t pi = 0;
    for (size_t c = 0; c < ncl; c++)
        for (uint32_t a = cl.off[c]; a < cl.off[c + 1]; a++)
            for (uint32_t b = a + 1; b < cl.off[c + 1]; b++)
                pairs[pi++] = (pair_entry){(uint32_t)cl.joints[a] * joints + cl.joints[b],
                                           (uint32_t)c};
    qsort(pairs, npairs, sizeof *pairs, cmp_pair);

    /* 3. Vertices with >= 2 joints; equal quantized weights share one evaluation. */
    vkeys = malloc((n ? n : 1) * sizeof *vkeys);
    vpool.j = malloc((n * w->influences + 1) * sizeof *vpool.j);
    vpool.q = malloc((n * w->influences + 1) * sizeof *vpool.q);
    vertex_eval = malloc((n ? n : 1) * sizeof *vertex_eval);
    if (!vkeys || !vpool.j || !vpool.q || !vertex_eval)
        goto oom;
    size_t nv = 0;
    poff = 0;
    for (size_t v = 0; v < n; v++) {
        sparse_w s;
        vertex_weights(w, v, &s);
        vertex_eval[v] = UINT32_MAX;
        if (s.n < 2)
            continue;
        make_key(&s, inv_tol, &vpool, &vkeys[nv++], (uint32_t)v, (uint32_t)poff);
        poff += (size_t)s.n;
    }
    rep.vertices_with_cor = nv;
    g_sort_pool = &vpool;
    qsort(vkeys, nv, sizeof *vkeys, cmp_keyed);
    size_t ne = 0;
    for (size_t i = 0; i < nv; i++)
        ne += i == 0 || !same_key(&vpool, &vkeys[i - 1], &vkeys[i]);
    eval_vertex = malloc((ne ? ne : 1) * sizeof *eval_vertex);
    eval_cor = malloc((3 * ne + 1) * sizeof *eval_cor);
    if (!eval_vertex || !eval_cor)
        goto oom;
    size_t e = (size_t)-1;
    for (size_t i = 0; i < nv; i++) {
        if (i == 0 || !same_key(&vpool, &vkeys[i - 1], &vkeys[i]))
            eval_vertex[++e] = vkeys[i].item;
        vertex_eval[vkeys[i].item] = (uint32_t)e;
    }
    rep.evaluations = ne;

    /* 4. Evaluate, split by ranges across threads. */
    cor_ctx ctx = {m, w, &cl, pairs, npairs, joints, 1.0 / (sigma * sigma), eval_vertex, eval_cor,
                   ne};
    if (threads > 64)
        threads = 64;
    if ((size_t)threads > ne / 64 + 1)
        threads = (int)(ne / 64 + 1);
    cor_job jobs[64];
    pthread_t tid[64];
    int started = 0;
    stamps = calloc((size_t)threads * (ncl ? ncl : 1), sizeof *stamps);
    if (!stamps)
        goto oom;
    for (int i = 0; i < threads; i++)
        jobs[i] = (cor_job){&ctx, ne * (size_t)i / (size_t)threads,
                            ne * (size_t)(i + 1) / (size_t)threads,
                            stamps + (size_t)i * (ncl ? ncl : 1)};
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
    for (size_t v = 0; v < n; v++)
        for (int q = 0; q < 3; q++)
            cor[3 * v + q] = vertex_eval[v] == UINT32_MAX
                                 ? m->positions[3 * v + q]
                                 : (float)eval_cor[3 * (size_t)vertex_eval[v] + q];
    goto done;
oom:
    snprintf(err, err_size, "cor: out of memory");
    rc = POSE_ERR_OUT_OF_MEMORY;
done:
    free(keys);
    free(pool.j);
    free(pool.q);
    free(vkeys);
    free(vpool.j);
    free(vpool.q);
    free(pairs);
    free(eval_vertex);
    free(vertex_eval);
    free(eval_cor);
    free(stamps);
    clusters_free(&cl);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    rep.seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (rep_out)
        *rep_out = rep;
    return rc;
}
