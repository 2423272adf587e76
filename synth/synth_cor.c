/* SPDX-License-Identifier: Apache-2.0 */
/* Centres of rotation (Le & Hodgins 2016), adapted to tets as in design §2:
 *   s(wp, ws) = sum_{i != j} wp_i wp_j ws_i ws_j exp(-(wp_i ws_j - ws_i wp_j)^2 / sigma^2)
 *   cor_p     = sum_t s(wp, wbar_t) V_t c_t / sum_t s(wp, wbar_t) V_t
 * s vanishes unless both weight vectors have two common non-zero bones, so
 * only "blend" vertices and tets (two or more non-zero bones) take part;
 * every other vertex gets its own rest position (the CoR method moves it
 * rigidly whatever its centre). EXACT evaluates every (vertex, blend tet)
 * pair; CLUSTERED groups blend tets whose mean weights agree after
 * quantization to 1/64 and evaluates each group once, with its
 * volume-weighted mean weights and centroid (an approximation). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "synth_internal.h"

#define MAX_SPARSE 32 /* mean of 4 vertices x up to 8 influences */
#define QUANT 64.0

typedef struct sparse {
    int n;
    uint16_t bone[MAX_SPARSE];
    double w[MAX_SPARSE];
} sparse;

/* A blend tet or a cluster of them. */
typedef struct blend {
    sparse w;       /* mean weights */
    double volume;
    double moment[3]; /* volume * centroid */
} blend;

static void sparse_add(sparse *s, uint16_t bone, double w)
{
    if (w <= 0.0)
        return;
    for (int i = 0; i < s->n; i++)
        if (s->bone[i] == bone) {
            s->w[i] += w;
            return;
        }
    if (s->n < MAX_SPARSE) {
        s->bone[s->n] = bone;
        s->w[s->n++] = w;
    }
}

static double sparse_get(const sparse *s, uint16_t bone)
{
    for (int i = 0; i < s->n; i++)
        if (s->bone[i] == bone)
            return s->w[i];
    return 0.0;
}

static double similarity(const sparse *p, const sparse *t, double inv_sigma2)
{
    double wt[POSE_SYNTH_MAX_K];
    int shared = 0;
    for (int i = 0; i < p->n; i++) {
        wt[i] = sparse_get(t, p->bone[i]);
        shared += wt[i] > 0.0;
    }
    if (shared < 2)
        return 0.0;
    double s = 0.0;
    for (int i = 0; i < p->n; i++)
        for (int j = 0; j < p->n; j++) {
            if (i == j || wt[i] <= 0.0 || wt[j] <= 0.0)
                continue;
            double d = p->w[i] * wt[j] - wt[i] * p->w[j];
            s += p->w[i] * p->w[j] * wt[i] * wt[j] * exp(-d * d * inv_sigma2);
        }
    return s;
}

static void vertex_sparse(const pose_rig_desc *d, size_t v, sparse *s)
{
    s->n = 0;
    for (unsigned k = 0; k < d->influences; k++)
        sparse_add(s, d->weight_joints[v * d->influences + k], d->weights[v * d->influences + k]);
}

/* Volume, centroid moment and mean weights of every tet with >= 2 bones. */
static blend *collect_blend_tets(const pose_rig_desc *d, size_t *count)
{
    blend *b = malloc((d->tet_count ? d->tet_count : 1) * sizeof *b);
    if (!b)
        return NULL;
    size_t n = 0;
    for (size_t t = 0; t < d->tet_count; t++) {
        const uint32_t *v = &d->tets[4 * t];
        blend *e = &b[n];
        e->w.n = 0;
        for (int k = 0; k < 4; k++)
            for (unsigned i = 0; i < d->influences; i++)
                sparse_add(&e->w, d->weight_joints[v[k] * d->influences + i],
                           0.25 * d->weights[v[k] * d->influences + i]);
        if (e->w.n < 2)
            continue;
        const float *p0 = &d->tet_positions[3 * v[0]];
        double a[3][3];
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < 3; i++)
                a[k][i] = (double)d->tet_positions[3 * v[k + 1] + i] - p0[i];
        double vol = fabs(a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                          a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                          a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])) / 6.0;
        e->volume = vol;
        for (int i = 0; i < 3; i++) {
            double c = 0.0;
            for (int k = 0; k < 4; k++)
                c += d->tet_positions[3 * v[k] + i];
            e->moment[i] = vol * c / 4.0;
        }
        n++;
    }
    *count = n;
    return b;
}

/* ------------------------------------------------------------- clusters */

typedef struct key {
    uint16_t bone[4];
    uint8_t q[4];
    uint32_t index;
} key;

static int cmp_key(const void *a, const void *b)
{
    const key *x = a, *y = b;
    int c = memcmp(x->bone, y->bone, sizeof x->bone);
    if (c)
        return c;
    c = memcmp(x->q, y->q, sizeof x->q);
    if (c)
        return c;
    return (x->index > y->index) - (x->index < y->index);
}

static key make_key(const sparse *w, uint32_t index)
{
    key k;
    memset(&k, 0, sizeof k);
    k.index = index;
    int idx[MAX_SPARSE];
    for (int i = 0; i < w->n; i++)
        idx[i] = i;
    for (int i = 0; i < w->n && i < 4; i++) /* four largest, then by bone */
        for (int j = i + 1; j < w->n; j++)
            if (w->w[idx[j]] > w->w[idx[i]]) {
                int t = idx[i];
                idx[i] = idx[j];
                idx[j] = t;
            }
    int m = w->n < 4 ? w->n : 4;
    for (int i = 0; i < m; i++)
        for (int j = i + 1; j < m; j++)
            if (w->bone[idx[j]] < w->bone[idx[i]]) {
                int t = idx[i];
                idx[i] = idx[j];
                idx[j] = t;
            }
    for (int i = 0; i < 4; i++) {
        k.bone[i] = i < m ? w->bone[idx[i]] : 0xFFFFu;
        k.q[i] = i < m ? (uint8_t)lround(w->w[idx[i]] * QUANT) : 0;
    }
    return k;
}

/* Merge blend tets with equal keys into volume-weighted clusters, in place. */
static size_t cluster(blend *b, size_t n)
{
    key *keys = malloc((n ? n : 1) * sizeof *keys);
    blend *out = malloc((n ? n : 1) * sizeof *out);
    if (!keys || !out) {
        free(keys);
        free(out);
        return 0;
    }
    for (size_t i = 0; i < n; i++)
        keys[i] = make_key(&b[i].w, (uint32_t)i);
    qsort(keys, n, sizeof *keys, cmp_key);
    size_t m = 0;
    for (size_t i = 0; i < n;) {
        size_t j = i;
        blend *c = &out[m++];
        memset(c, 0, sizeof *c);
        while (j < n && memcmp(keys[j].bone, keys[i].bone, sizeof keys[i].bone) == 0 &&
               memcmp(keys[j].q, keys[i].q, sizeof keys[i].q) == 0) {
            const blend *t = &b[keys[j].index];
            c->volume += t->volume;
            for (int a = 0; a < 3; a++)
                c->moment[a] += t->moment[a];
            for (int k = 0; k < t->w.n; k++)
                sparse_add(&c->w, t->w.bone[k], t->w.w[k] * t->volume);
            j++;
        }
        for (int k = 0; k < c->w.n; k++)
            c->w.w[k] = c->volume > 0.0 ? c->w.w[k] / c->volume : 0.0;
        i = j;
    }
    memcpy(b, out, m * sizeof *b);
    free(keys);
    free(out);
    return m;
}

pose_status pose_synth_compute_cor(const pose_rig_desc *d, float sigma, pose_synth_cor_mode mode,
                                   float *cor)
{
    return ps_compute_cor(d, sigma, mode, cor, NULL);
}

pose_status ps_compute_cor(const pose_rig_desc *d, float sigma, pose_synth_cor_mode mode,
                           float *cor, const pose_synth_rig *r)
{
    if (!d || !cor || !(sigma > 0.0f) || d->influences == 0 ||
        d->influences > POSE_SYNTH_MAX_K ||
        (mode != POSE_SYNTH_COR_EXACT && mode != POSE_SYNTH_COR_CLUSTERED))
        return POSE_ERR_INVALID_ARGUMENT;
    size_t nb;
    blend *b = collect_blend_tets(d, &nb);
    if (!b)
        return POSE_ERR_OUT_OF_MEMORY;
    if (mode == POSE_SYNTH_COR_CLUSTERED && nb) {
        nb = cluster(b, nb);
        if (!nb) {
            free(b);
            return POSE_ERR_OUT_OF_MEMORY;
        }
    }
    double inv_sigma2 = 1.0 / ((double)sigma * sigma);
    for (size_t v = 0; v < d->tet_vertex_count; v++) {
        if (v % 8192 == 0)
            ps_progress(r, "cor", (double)v / d->tet_vertex_count);
        sparse p;
        vertex_sparse(d, v, &p);
        memcpy(&cor[3 * v], &d->tet_positions[3 * v], 3 * sizeof(float));
        if (p.n < 2)
            continue;
        double num[3] = {0, 0, 0}, den = 0.0;
        for (size_t t = 0; t < nb; t++) {
            double s = similarity(&p, &b[t].w, inv_sigma2);
            if (s <= 0.0)
                continue;
            den += s * b[t].volume;
            for (int a = 0; a < 3; a++)
                num[a] += s * b[t].moment[a];
        }
        if (den > 0.0)
            for (int a = 0; a < 3; a++)
                cor[3 * v + a] = (float)(num[a] / den);
    }
    free(b);
    ps_progress(r, "cor", 1.0);
    return POSE_OK;
}
