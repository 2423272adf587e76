/* SPDX-License-Identifier: Apache-2.0 */
#include "weights_fem.h"

#include "weights_matrix.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Fixed joint per vertex from the bone tets: -1 free, else the joint. A
 * vertex in tets of two bones takes the one with more incident tets. */
static int fixed_joints(const pp_tetmesh *m, size_t joint_count, int32_t *fixed, size_t *conflicts,
                        size_t *empty_joints, char *err, size_t err_size)
{
    size_t n = m->vertex_count;
    for (size_t v = 0; v < n; v++)
        fixed[v] = -1;
    uint8_t *seen = calloc(joint_count ? joint_count : 1, 1);
    if (!seen)
        return pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "weights: out of memory");
    size_t nconf = 0;
    for (size_t t = 0; t < m->tet_count; t++) {
        unsigned lab = m->labels[t];
        if (lab == 0)
            continue;
        if (lab > joint_count) {
            free(seen);
            return pp_fail(err, err_size, POSE_ERR_INVALID_DATA,
                        "weights: tet %zu has label %u but there are %zu joints", t, lab, joint_count);
        }
        seen[lab - 1] = 1;
        for (int k = 0; k < 4; k++) {
            uint32_t v = m->tets[4 * t + k];
            if (fixed[v] == -1)
                fixed[v] = (int32_t)(lab - 1);
            else if (fixed[v] >= 0 && fixed[v] != (int32_t)(lab - 1)) {
                fixed[v] = -2; /* settled below */
                nconf++;
            }
        }
    }
    size_t empty = 0;
    for (size_t j = 0; j < joint_count; j++)
        empty += !seen[j];
    free(seen);
    if (empty == joint_count)
        return pp_fail(err, err_size, POSE_ERR_INVALID_DATA,
                    "weights: no tet is labelled as bone; nothing to bind the skin to");
    *empty_joints = empty;
    *conflicts = 0;
    if (nconf == 0)
        return POSE_OK;
    /* Majority vote over incident bone tets, only for the conflicted vertices. */
    int32_t *slot = malloc(n * sizeof *slot);
    size_t nc = 0;
    if (!slot)
        return pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "weights: out of memory");
    for (size_t v = 0; v < n; v++)
        slot[v] = fixed[v] == -2 ? (int32_t)nc++ : -1;
    uint32_t *votes = calloc(nc * joint_count, sizeof *votes);
    if (!votes) {
        free(slot);
        return pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "weights: out of memory");
    }
    for (size_t t = 0; t < m->tet_count; t++)
        if (m->labels[t])
            for (int k = 0; k < 4; k++) {
                int32_t s = slot[m->tets[4 * t + k]];
                if (s >= 0)
                    votes[(size_t)s * joint_count + m->labels[t] - 1]++;
            }
    for (size_t v = 0; v < n; v++)
        if (slot[v] >= 0) {
            const uint32_t *vv = votes + (size_t)slot[v] * joint_count;
            size_t best = 0;
            for (size_t j = 1; j < joint_count; j++)
                if (vv[j] > vv[best])
                    best = j;
            fixed[v] = (int32_t)best;
        }
    *conflicts = nc;
    free(votes);
    free(slot);
    return POSE_OK;
}

static uint32_t uf_find(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

/* Pin each connected free region that touches no bone vertex to the joint
 * of the bone vertex nearest to it. */
static int pin_floating(const pp_tetmesh *m, int32_t *fixed, size_t *regions, size_t *vertices)
{
    size_t n = m->vertex_count;
    uint32_t *parent = malloc(n * sizeof *parent);
    uint8_t *anchored = calloc(n, 1);
    if (!parent || !anchored) {
        free(parent), free(anchored);
        return -1;
    }
    for (size_t v = 0; v < n; v++)
        parent[v] = (uint32_t)v;
    for (size_t t = 0; t < m->tet_count; t++) {
        const uint32_t *tv = m->tets + 4 * t;
        int has_fixed = 0;
        uint32_t first = UINT32_MAX;
        for (int k = 0; k < 4; k++) {
            if (fixed[tv[k]] >= 0) {
                has_fixed = 1;
                continue;
            }
            if (first == UINT32_MAX) {
                first = uf_find(parent, tv[k]);
                continue;
            }
            uint32_t r = uf_find(parent, tv[k]);
            if (r != first) {
                parent[r] = first;
                anchored[first] |= anchored[r];
            }
        }
        if (has_fixed && first != UINT32_MAX)
            anchored[uf_find(parent, first)] = 1;
    }
    *regions = *vertices = 0;
    int32_t *pin = malloc(n * sizeof *pin);
    if (!pin) {
        free(parent), free(anchored);
        return -1;
    }
    for (size_t v = 0; v < n; v++)
        pin[v] = -1;
    for (size_t v = 0; v < n; v++) {
        if (fixed[v] >= 0)
            continue;
        uint32_t r = uf_find(parent, (uint32_t)v);
        if (anchored[r])
            continue;
        if (pin[r] < 0) { /* first vertex of a new island: nearest bone vertex */
            const float *p = m->positions + 3 * v;
            double best = DBL_MAX;
            int32_t joint = 0;
            for (size_t u = 0; u < n; u++) {
                if (fixed[u] < 0)
                    continue;
                const float *q = m->positions + 3 * u;
                double d = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                           (p[2] - q[2]) * (p[2] - q[2]);
                if (d < best)
                    best = d, joint = fixed[u];
            }
            pin[r] = joint;
            (*regions)++;
        }
        (*vertices)++;
    }
    for (size_t v = 0; v < n; v++)
        if (fixed[v] < 0) {
            uint32_t r = uf_find(parent, (uint32_t)v);
            if (!anchored[r])
                fixed[v] = pin[r];
        }
    free(pin);
    free(parent);
    free(anchored);
    return 0;
}

/* Insert (w, j) into a descending top-K list; returns the value pushed out
 * (or w itself when it did not make the list), -inf when nothing dropped. */
static double topk_insert(float *w, uint16_t *jj, unsigned k, double value, unsigned joint)
{
    if (value <= w[k - 1]) {
        return value;
    }
    double dropped = w[k - 1];
    unsigned i = k - 1;
    while (i > 0 && w[i - 1] < value) {
        w[i] = w[i - 1];
        jj[i] = jj[i - 1];
        i--;
    }
    w[i] = (float)value;
    jj[i] = (uint16_t)joint;
    return dropped;
}

int pp_weights_compute(const pp_tetmesh *mesh, size_t joint_count, const pp_weight_options *opt,
                       pp_weights *out, pp_weight_report *rep_out, char *err, size_t err_size)
{
    pp_weight_report rep;
    memset(&rep, 0, sizeof rep);
    memset(out, 0, sizeof *out);
    unsigned K = opt && opt->influences ? opt->influences : 4;
    if (K > PP_MAX_INFLUENCES)
        return pp_fail(err, err_size, POSE_ERR_INVALID_ARGUMENT, "weights: K = %u; at most %d", K,
                    PP_MAX_INFLUENCES);
    if (joint_count == 0 || joint_count > UINT16_MAX)
        return pp_fail(err, err_size, POSE_ERR_INVALID_ARGUMENT, "weights: %zu joints", joint_count);
    if (K > joint_count)
        K = (unsigned)joint_count;
    size_t n = mesh->vertex_count;
    if (n == 0 || mesh->tet_count == 0 || n > INT32_MAX)
        return pp_fail(err, err_size, POSE_ERR_INVALID_DATA, "weights: the tet mesh is empty");
    double t0 = pp_now_s();
    int32_t *fixed = malloc(n * sizeof *fixed), *free_index = malloc(n * sizeof *free_index);
    int rc = POSE_OK;
    cholmod_common cc;
    cholmod_start(&cc);
    pp_laplacian lap = {0};
    cholmod_factor *L = NULL;
    cholmod_dense *B = NULL;
    double *sum = NULL;
    out->influences = K;
    out->vertex_count = n;
    out->joints = calloc(n * K, sizeof *out->joints);
    out->weights = malloc(n * K * sizeof *out->weights);
    if (!fixed || !free_index || !out->joints || !out->weights) {
        rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "weights: out of memory");
        goto done;
    }
    rc = fixed_joints(mesh, joint_count, fixed, &rep.conflict_vertices, &rep.empty_joints, err,
                      err_size);
    if (rc < 0)
        goto done;
    if (pin_floating(mesh, fixed, &rep.floating_regions, &rep.floating_vertices) < 0) {
        rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "weights: out of memory");
        goto done;
    }
    size_t nf = 0;
    for (size_t v = 0; v < n; v++)
        free_index[v] = fixed[v] < 0 ? (int32_t)nf++ : -1;
    rep.free_vertices = nf;
    rep.fixed_vertices = n - nf;
    for (size_t i = 0; i < n * K; i++)
        out->weights[i] = -INFINITY;
    rep.min_weight = 1.0;
    rep.max_weight = 0.0;
    rep.max_dropped = 0.0;
    for (size_t v = 0; v < n; v++)
        if (fixed[v] >= 0)
            topk_insert(out->weights + v * K, out->joints + v * K, K, 1.0, (unsigned)fixed[v]);
    if (nf > 0) {
        if (pp_laplacian_assemble(mesh, free_index, nf, fixed, !(opt && opt->plain_fem), &lap,
                                  &cc) < 0) {
            rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "weights: out of memory assembling");
            goto done;
        }
        rep.clipped_entries = lap.clipped;
        double t1 = pp_now_s();
        rep.seconds_assemble = t1 - t0;
        cc.supernodal = CHOLMOD_AUTO;
        L = cholmod_analyze(lap.A, &cc);
        if (L)
            cholmod_factorize(lap.A, L, &cc);
        if (!L || cc.status != CHOLMOD_OK || L->minor < L->n) {
            rc = pp_fail(err, err_size, POSE_ERR_INVALID_DATA,
                      "weights: Cholesky factorization failed (CHOLMOD status %d, minor %zu of %zu): "
                      "the mesh has degenerate tets",
                      cc.status, L ? (size_t)L->minor : 0, nf);
            goto done;
        }
        rep.supernodal = L->is_super;
        rep.factor_nnz = (size_t)cc.lnz;
        double t2 = pp_now_s();
        rep.seconds_factor = t2 - t1;
        unsigned block = opt && opt->block ? opt->block : (unsigned)joint_count;
        if (block > joint_count)
            block = (unsigned)joint_count;
        sum = calloc(nf, sizeof *sum);
        B = cholmod_allocate_dense(nf, block, nf, CHOLMOD_REAL, &cc);
        if (!sum || !B) {
            rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "weights: out of memory for %u "
                      "right-hand sides", block);
            goto done;
        }
        size_t *free_vertex = malloc(nf * sizeof *free_vertex);
        if (!free_vertex) {
            rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "weights: out of memory");
            goto done;
        }
        for (size_t v = 0; v < n; v++)
            if (free_index[v] >= 0)
                free_vertex[free_index[v]] = v;
        for (size_t j0 = 0; j0 < joint_count; j0 += block) {
            size_t nb = joint_count - j0 < block ? joint_count - j0 : block;
            B->ncol = nb;
            double *bx = B->x;
            memset(bx, 0, nf * nb * sizeof *bx);
            for (size_t i = 0; i < lap.coupling_count; i++) {
                const pp_coupling *cp = &lap.coupling[i];
                if (cp->joint >= j0 && cp->joint < j0 + nb)
                    bx[(cp->joint - j0) * nf + cp->row] -= cp->value;
            }
            cholmod_dense *X = cholmod_solve(CHOLMOD_A, L, B, &cc);
            if (!X) {
                free(free_vertex);
                rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "weights: CHOLMOD solve failed");
                goto done;
            }
            const double *x = X->x;
            for (size_t f = 0; f < nf; f++) {
                size_t v = free_vertex[f];
                for (size_t c = 0; c < nb; c++) {
                    double w = x[c * X->d + f];
                    sum[f] += w;
                    rep.min_weight = fmin(rep.min_weight, w);
                    rep.max_weight = fmax(rep.max_weight, w);
                    double d = topk_insert(out->weights + v * K, out->joints + v * K, K, w,
                                           (unsigned)(j0 + c));
                    rep.max_dropped = fmax(rep.max_dropped, d);
                }
            }
            cholmod_free_dense(&X, &cc);
        }
        for (size_t f = 0; f < nf; f++)
            rep.max_sum_error = fmax(rep.max_sum_error, fabs(sum[f] - 1.0));
        free(free_vertex);
        rep.seconds_solve = pp_now_s() - t2;
    }
    /* Clamp round-off negatives, renormalize the K kept, pad unused slots. */
    for (size_t v = 0; v < n; v++) {
        float *w = out->weights + v * K;
        uint16_t *jj = out->joints + v * K;
        double s = 0;
        for (unsigned k = 0; k < K; k++) {
            if (!(w[k] > 0))
                w[k] = 0, jj[k] = jj[0];
            s += w[k];
        }
        if (!(s > 0)) { /* cannot happen with a valid solve; keep the data valid */
            w[0] = 1, s = 1;
        }
        for (unsigned k = 0; k < K; k++)
            w[k] = (float)(w[k] / s);
    }
done:
    if (B)
        cholmod_free_dense(&B, &cc);
    if (L)
        cholmod_free_factor(&L, &cc);
    pp_laplacian_free(&lap, &cc);
    cholmod_finish(&cc);
    free(sum);
    free(fixed);
    free(free_index);
    if (rc < 0)
        pp_weights_free(out);
    if (rep_out)
        *rep_out = rep;
    return rc;
}

void pp_weights_free(pp_weights *w)
{
    if (!w)
        return;
    free(w->joints);
    free(w->weights);
    memset(w, 0, sizeof *w);
}

float pp_weights_get(const pp_weights *w, size_t v, unsigned joint)
{
    for (unsigned k = 0; k < w->influences; k++)
        if (w->joints[v * w->influences + k] == joint && w->weights[v * w->influences + k] > 0)
            return w->weights[v * w->influences + k];
    return 0.0f;
}
