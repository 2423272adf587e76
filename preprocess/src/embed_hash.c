/* SPDX-License-Identifier: Apache-2.0 */
#include "embed_hash.h"

#include "embed_geom.h"

#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

struct pp_tet_hash {
    const pp_tetmesh *mesh;
    double cell, inv_cell;
    size_t size;       /* buckets (a prime) */
    uint32_t *start;   /* size + 1 */
    uint32_t *items;   /* tet indices */
    int ring_max;      /* ring search limit before the brute-force fallback */
};

/* Only inside tests that must agree with exact containment: a point on a
 * shared face is inside both tets; either answer is exact. */
#define INSIDE_EPS 1e-9

/* Vertices this close to the mesh (metres) are on its boundary, not outside. */
#define ON_SURFACE 1e-6

/* fmin/fmax are library calls without -ffast-math; these are hot. */
#define MIN2(a, b) ((a) < (b) ? (a) : (b))
#define MAX2(a, b) ((a) > (b) ? (a) : (b))

static size_t next_prime(size_t n)
{
    if (n < 3)
        return 3;
    for (n |= 1;; n += 2) {
        int prime = 1;
        for (size_t d = 3; d * d <= n; d += 2)
            if (n % d == 0) {
                prime = 0;
                break;
            }
        if (prime)
            return n;
    }
}

static size_t hash_cell(const pp_tet_hash *h, long i, long j, long k)
{
    uint64_t x = ((uint64_t)i * 73856093u) ^ ((uint64_t)j * 19349663u) ^ ((uint64_t)k * 83492791u);
    return (size_t)(x % h->size);
}

static long cell_coord(const pp_tet_hash *h, double x)
{
    return (long)floor(x * h->inv_cell);
}

static void tet_box(const pp_tetmesh *m, size_t t, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++)
        lo[k] = DBL_MAX, hi[k] = -DBL_MAX;
    for (int c = 0; c < 4; c++) {
        const float *p = m->positions + 3 * (size_t)m->tets[4 * t + c];
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], p[k]);
            hi[k] = fmax(hi[k], p[k]);
        }
    }
}

int pp_tet_hash_build(const pp_tetmesh *m, double cell, pp_tet_hash **out, char *err,
                      size_t err_size)
{
    *out = NULL;
    if (!m || m->tet_count == 0 || m->tet_count > UINT32_MAX) {
        snprintf(err, err_size, "mapping: the tet mesh is empty");
        return POSE_ERR_INVALID_DATA;
    }
    pp_tet_hash *h = calloc(1, sizeof *h);
    if (!h) {
        snprintf(err, err_size, "mapping: out of memory");
        return POSE_ERR_OUT_OF_MEMORY;
    }
    h->mesh = m;
    if (!(cell > 0)) {
        double sum = 0;
        for (size_t t = 0; t < m->tet_count; t++) {
            double lo[3], hi[3];
            tet_box(m, t, lo, hi);
            sum += fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
        }
        cell = sum / (double)m->tet_count;
        if (!(cell > 0))
            cell = 1e-3;
    }
    h->cell = cell;
    h->inv_cell = 1.0 / cell;
    /* Entries: each tet in every cell its box overlaps (about 2-8 for a tet
     * the size of a cell). Count first, size the table to ~2x entries. */
    size_t entries = 0;
    for (size_t t = 0; t < m->tet_count; t++) {
        double lo[3], hi[3];
        tet_box(m, t, lo, hi);
        size_t c = 1;
        for (int k = 0; k < 3; k++)
            c *= (size_t)(cell_coord(h, hi[k]) - cell_coord(h, lo[k]) + 1);
        entries += c;
    }
    if (entries > UINT32_MAX) {
        free(h);
        snprintf(err, err_size, "mapping: %zu hash entries; the tets are far larger than the cell",
                 entries);
        return POSE_ERR_INVALID_DATA;
    }
    h->size = next_prime(2 * entries);
    h->start = calloc(h->size + 1, sizeof *h->start);
    h->items = malloc((entries ? entries : 1) * sizeof *h->items);
    if (!h->start || !h->items) {
        pp_tet_hash_free(h);
        snprintf(err, err_size, "mapping: out of memory for %zu hash entries", entries);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    for (int pass = 0; pass < 2; pass++) {
        for (size_t t = 0; t < m->tet_count; t++) {
            double lo[3], hi[3];
            tet_box(m, t, lo, hi);
            long c0[3], c1[3];
            for (int k = 0; k < 3; k++) {
                c0[k] = cell_coord(h, lo[k]);
                c1[k] = cell_coord(h, hi[k]);
            }
            for (long z = c0[2]; z <= c1[2]; z++)
                for (long y = c0[1]; y <= c1[1]; y++)
                    for (long x = c0[0]; x <= c1[0]; x++) {
                        size_t b = hash_cell(h, x, y, z);
                        if (pass == 0)
                            h->start[b + 1]++;
                        else
                            h->items[h->start[b]++] = (uint32_t)t;
                    }
        }
        if (pass == 0) {
            for (size_t b = 0; b < h->size; b++)
                h->start[b + 1] += h->start[b];
        } else {
            memmove(h->start + 1, h->start, h->size * sizeof *h->start);
            h->start[0] = 0;
        }
    }
    h->ring_max = 24;
    *out = h;
    return POSE_OK;
}

void pp_tet_hash_free(pp_tet_hash *h)
{
    if (!h)
        return;
    free(h->start);
    free(h->items);
    free(h);
}

void pp_tet_hash_stats(const pp_tet_hash *h, size_t *buckets, size_t *entries, double *cell)
{
    *buckets = h->size;
    *entries = h->start[h->size];
    *cell = h->cell;
}

static void corners(const pp_tetmesh *m, uint32_t t, double c[4][3])
{
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++)
            c[i][k] = m->positions[3 * (size_t)m->tets[4 * (size_t)t + i] + k];
}

/* The first candidate tet containing p, restricted to `label` when >= 0;
 * failing that, one within INSIDE_EPS (the most inside). */
static int find_inside(const pp_tet_hash *h, const double p[3], int label, uint32_t *tet,
                       double bary[4])
{
    const pp_tetmesh *m = h->mesh;
    size_t b = hash_cell(h, cell_coord(h, p[0]), cell_coord(h, p[1]), cell_coord(h, p[2]));
    double best = -INSIDE_EPS;
    int found = 0;
    for (uint32_t i = h->start[b]; i < h->start[b + 1]; i++) {
        uint32_t t = h->items[i];
        if (label >= 0 && m->labels[t] != label)
            continue;
        double c[4][3], w[4];
        corners(m, t, c);
        if (!pp_tet_barycentric(p, c[0], c[1], c[2], c[3], w))
            continue;
        double mn = MIN2(MIN2(w[0], w[1]), MIN2(w[2], w[3]));
        if (mn >= best) {
            best = mn;
            *tet = t;
            memcpy(bary, w, sizeof w);
            found = 1;
            if (mn >= 0)
                break; /* inside: exact; tets sharing a face would give the same point */
        }
    }
    return found;
}

/* Nearest tet by rings of hash cells around p, up to `rings`; returns the
 * squared distance (DBL_MAX when none found). */
static double find_nearest(const pp_tet_hash *h, const double p[3], int label, int rings,
                           uint32_t *tet)
{
    const pp_tetmesh *m = h->mesh;
    long c[3] = {cell_coord(h, p[0]), cell_coord(h, p[1]), cell_coord(h, p[2])};
    double best = DBL_MAX;
    for (int r = 0; r <= rings; r++) {
        for (long dz = -r; dz <= r; dz++)
            for (long dy = -r; dy <= r; dy++)
                for (long dx = -r; dx <= r; dx++) {
                    if (labs(dx) != r && labs(dy) != r && labs(dz) != r)
                        continue; /* only the shell of ring r */
                    /* Skip a cell that cannot hold anything closer. */
                    long cc[3] = {c[0] + dx, c[1] + dy, c[2] + dz};
                    double cell_d = 0;
                    for (int k = 0; k < 3; k++) {
                        double lo = (double)cc[k] * h->cell, hi = lo + h->cell;
                        double g = p[k] < lo ? lo - p[k] : p[k] > hi ? p[k] - hi : 0;
                        cell_d += g * g;
                    }
                    if (cell_d >= best)
                        continue;
                    size_t b = hash_cell(h, cc[0], cc[1], cc[2]);
                    for (uint32_t i = h->start[b]; i < h->start[b + 1]; i++) {
                        uint32_t t = h->items[i];
                        if (label >= 0 && m->labels[t] != label)
                            continue;
                        double q[4][3];
                        corners(m, t, q);
                        /* The box distance bounds the tet distance from below
                         * and costs a tenth of the exact test. */
                        double box = 0;
                        for (int k = 0; k < 3; k++) {
                            double lo = MIN2(MIN2(q[0][k], q[1][k]), MIN2(q[2][k], q[3][k]));
                            double hi = MAX2(MAX2(q[0][k], q[1][k]), MAX2(q[2][k], q[3][k]));
                            double g = p[k] < lo ? lo - p[k] : p[k] > hi ? p[k] - hi : 0;
                            box += g * g;
                        }
                        if (box >= best)
                            continue;
                        double d = pp_point_tet_dist2(p, q[0], q[1], q[2], q[3]);
                        if (d < best) {
                            best = d;
                            *tet = t;
                        }
                    }
                }
        /* Unseen tets lie only in rings > r, at least r cells away. */
        double reach = (double)r * h->cell;
        if (best <= reach * reach)
            break;
    }
    return best;
}

static double nearest_brute(const pp_tetmesh *m, const double p[3], uint32_t *tet)
{
    double best = DBL_MAX;
    for (size_t t = 0; t < m->tet_count; t++) {
        double q[4][3];
        corners(m, (uint32_t)t, q);
        double d = pp_point_tet_dist2(p, q[0], q[1], q[2], q[3]);
        if (d < best) {
            best = d;
            *tet = (uint32_t)t;
        }
    }
    return best;
}

typedef struct embed_job {
    const pp_tet_hash *h;
    const float *pts;
    size_t end;
    atomic_size_t *next; /* shared: the next chunk to take */
    int label;
    int label_rings;
    uint32_t *tet;
    float *bary;
    pp_embed_report rep;
} embed_job;

static void embed_one(embed_job *job, size_t i)
{
    const pp_tet_hash *h = job->h;
    const pp_tetmesh *m = h->mesh;
    double p[3] = {job->pts[3 * i], job->pts[3 * i + 1], job->pts[3 * i + 2]};
    uint32_t t = 0;
    double w[4];
    int inside = 0;
    if (job->label >= 0) {
        inside = find_inside(h, p, job->label, &t, w);
        if (!inside) {
            double d = find_nearest(h, p, job->label, job->label_rings, &t);
            double reach = job->label_rings * h->cell;
            if (d <= reach * reach) {
                double q[4][3];
                corners(m, t, q);
                pp_tet_barycentric(p, q[0], q[1], q[2], q[3], w);
                job->tet[i] = t;
                for (int k = 0; k < 4; k++)
                    job->bary[4 * i + k] = (float)w[k];
                return; /* close to its own bone: not "outside the mesh" */
            }
            job->rep.label_fallback++;
        }
    }
    if (!inside)
        inside = find_inside(h, p, -1, &t, w);
    if (!inside) {
        double d = find_nearest(h, p, -1, h->ring_max, &t);
        if (d == DBL_MAX)
            d = nearest_brute(m, p, &t);
        double q[4][3];
        corners(m, t, q);
        pp_tet_barycentric(p, q[0], q[1], q[2], q[3], w);
        if (d > ON_SURFACE * ON_SURFACE) { /* not just rounding on the boundary */
            job->rep.outside++;
            job->rep.max_distance = fmax(job->rep.max_distance, sqrt(d));
        }
    }
    job->tet[i] = t;
    for (int k = 0; k < 4; k++)
        job->bary[4 * i + k] = (float)w[k];
}

/* Points outside the mesh cost far more than inside ones and come in runs
 * (a whole skin region), so threads take small chunks in turn. */
enum { EMBED_CHUNK = 512 };

static void *embed_run(void *arg)
{
    embed_job *job = arg;
    for (;;) {
        size_t begin = atomic_fetch_add(job->next, EMBED_CHUNK);
        if (begin >= job->end)
            break;
        size_t end = begin + EMBED_CHUNK < job->end ? begin + EMBED_CHUNK : job->end;
        for (size_t i = begin; i < end; i++)
            embed_one(job, i);
    }
    return NULL;
}

int pp_embed_points(const pp_tet_hash *h, const float *pts, size_t n, int prefer_label,
                    double label_reach, int threads, uint32_t *tet, float *bary,
                    pp_embed_report *rep)
{
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    if (threads < 1)
        threads = 1;
    if ((size_t)threads > n / 1024 + 1)
        threads = (int)(n / 1024 + 1);
    int rings = label_reach > 0 ? (int)ceil(label_reach / h->cell) : 2;
    embed_job jobs[64];
    pthread_t tid[64];
    if (threads > 64)
        threads = 64;
    int started = 0, rc = POSE_OK;
    atomic_size_t next = 0;
    for (int i = 0; i < threads; i++)
        jobs[i] = (embed_job){h, pts, n, &next, prefer_label, rings, tet, bary, {0}};
    for (int i = 1; i < threads; i++) {
        if (pthread_create(&tid[i], NULL, embed_run, &jobs[i]) != 0) {
            /* Run what could not be started on this thread. */
            for (int k = i; k < threads; k++)
                embed_run(&jobs[k]);
            break;
        }
        started = i;
    }
    embed_run(&jobs[0]);
    for (int i = 1; i <= started; i++)
        pthread_join(tid[i], NULL);
    for (int i = 0; i < threads; i++) {
        rep->outside += jobs[i].rep.outside;
        rep->label_fallback += jobs[i].rep.label_fallback;
        rep->max_distance = fmax(rep->max_distance, jobs[i].rep.max_distance);
    }
    rep->vertices += n;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    rep->seconds += (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    return rc;
}

void pp_embed_points_naive(const pp_tetmesh *m, const float *pts, size_t n, uint32_t *tet,
                           float *bary)
{
    for (size_t i = 0; i < n; i++) {
        double p[3] = {pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]}, best = -DBL_MAX;
        uint32_t bt = 0;
        double bw[4] = {1, 0, 0, 0};
        for (size_t t = 0; t < m->tet_count; t++) {
            double q[4][3], w[4];
            corners(m, (uint32_t)t, q);
            if (!pp_tet_barycentric(p, q[0], q[1], q[2], q[3], w))
                continue;
            double mn = fmin(fmin(w[0], w[1]), fmin(w[2], w[3]));
            if (mn > best) {
                best = mn;
                bt = (uint32_t)t;
                memcpy(bw, w, sizeof w);
            }
        }
        tet[i] = bt;
        for (int k = 0; k < 4; k++)
            bary[4 * i + k] = (float)bw[k];
    }
}
