/* SPDX-License-Identifier: Apache-2.0
 *
 * The sparsity pattern is built directly in compressed-column form (count,
 * fill, sort and merge each column) rather than through a CHOLMOD triplet
 * matrix: at the paper's scale (3.5 M tets) triplets would need ~35 M
 * entries of 16 bytes before being summed; the column lists need a quarter.
 */
#include "weights_matrix.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double pp_tet_local_stiffness(const float *p0, const float *p1, const float *p2, const float *p3,
                        double k[4][4])
{
    double d[3][3]; /* columns p1-p0, p2-p0, p3-p0 */
    for (int r = 0; r < 3; r++) {
        d[r][0] = (double)p1[r] - p0[r];
        d[r][1] = (double)p2[r] - p0[r];
        d[r][2] = (double)p3[r] - p0[r];
    }
    double det = d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) -
                 d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0]) +
                 d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
    memset(k, 0, 16 * sizeof(double));
    if (!(fabs(det) > 0) || !isfinite(det))
        return 0.0;
    /* Rows of D^-1 are ∇φ1..∇φ3 (φ = D^-1 (x - p0)); ∇φ0 = -(their sum). */
    double inv[3][3];
    inv[0][0] = (d[1][1] * d[2][2] - d[1][2] * d[2][1]) / det;
    inv[0][1] = (d[0][2] * d[2][1] - d[0][1] * d[2][2]) / det;
    inv[0][2] = (d[0][1] * d[1][2] - d[0][2] * d[1][1]) / det;
    inv[1][0] = (d[1][2] * d[2][0] - d[1][0] * d[2][2]) / det;
    inv[1][1] = (d[0][0] * d[2][2] - d[0][2] * d[2][0]) / det;
    inv[1][2] = (d[0][2] * d[1][0] - d[0][0] * d[1][2]) / det;
    inv[2][0] = (d[1][0] * d[2][1] - d[1][1] * d[2][0]) / det;
    inv[2][1] = (d[0][1] * d[2][0] - d[0][0] * d[2][1]) / det;
    inv[2][2] = (d[0][0] * d[1][1] - d[0][1] * d[1][0]) / det;
    double g[4][3];
    for (int c = 0; c < 3; c++) {
        g[1][c] = inv[0][c];
        g[2][c] = inv[1][c];
        g[3][c] = inv[2][c];
        g[0][c] = -(inv[0][c] + inv[1][c] + inv[2][c]);
    }
    double vol = fabs(det) / 6.0;
    for (int a = 0; a < 4; a++)
        for (int b = 0; b < 4; b++)
            k[a][b] = vol * (g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2]);
    return vol;
}

static void sort_unique(int *v, size_t *n)
{
    /* Columns hold ~15-30 entries: insertion sort beats qsort's overhead. */
    for (size_t i = 1; i < *n; i++) {
        int x = v[i];
        size_t j = i;
        while (j > 0 && v[j - 1] > x) {
            v[j] = v[j - 1];
            j--;
        }
        v[j] = x;
    }
    size_t m = 0;
    for (size_t i = 0; i < *n; i++)
        if (m == 0 || v[m - 1] != v[i])
            v[m++] = v[i];
    *n = m;
}

static size_t find_row(const int *rows, size_t lo, size_t hi, int r)
{
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (rows[mid] < r)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Merge the coupling terms per (row, joint) in place: counting sort by row,
 * then a scan per row (a row meets few joints). The right-hand sides only
 * need these sums, and the sign test below must see them, not the per-tet
 * parts. Returns -1 when out of memory. */
static int merge_coupling(pp_laplacian *l, size_t n_free)
{
    size_t n = l->coupling_count;
    size_t *start = calloc(n_free + 1, sizeof *start);
    pp_coupling *sorted = malloc((n ? n : 1) * sizeof *sorted);
    if (!start || !sorted) {
        free(start), free(sorted);
        return -1;
    }
    for (size_t i = 0; i < n; i++)
        start[l->coupling[i].row + 1]++;
    for (size_t r = 0; r < n_free; r++)
        start[r + 1] += start[r];
    for (size_t i = 0; i < n; i++)
        sorted[start[l->coupling[i].row]++] = l->coupling[i];
    size_t m = 0, begin = 0;
    for (size_t r = 0; r < n_free; r++) {
        size_t end = start[r]; /* advanced to the row's end by the fill */
        size_t first = m;
        for (size_t i = begin; i < end; i++) {
            size_t k = first;
            while (k < m && l->coupling[k].joint != sorted[i].joint)
                k++;
            if (k == m)
                l->coupling[m++] = sorted[i];
            else
                l->coupling[k].value += sorted[i].value;
        }
        begin = end;
    }
    l->coupling_count = m;
    free(start);
    free(sorted);
    return 0;
}

/* Drop the positive off-diagonal entries (free-free, and free-bone per
 * joint) and add each to the diagonal of its rows, so that every row still
 * sums to zero. Obtuse tets, which snapping creates, give such entries; with
 * them the matrix is not an M-matrix and weights overshoot [0, 1] (to -0.07
 * on the shared body at 10 mm). Without them the discrete maximum principle
 * holds: weights are >= 0 and, summing to 1, <= 1. The cost is a local
 * change of the operator where the mesh is poor (counted in `clipped`). */
static size_t clip_positive(pp_laplacian *l, size_t n_free)
{
    int *Ap = l->A->p, *Ai = l->A->i;
    double *Ax = l->A->x;
    size_t clipped = 0;
    for (size_t j = 0; j < n_free; j++)
        for (int q = Ap[j]; q < Ap[j + 1]; q++) {
            int i = Ai[q];
            if (i == (int)j || !(Ax[q] > 0.0))
                continue;
            /* upper storage: the diagonal is the last entry of its column */
            double *dj = &Ax[Ap[j + 1] - 1], *di = &Ax[Ap[i + 1] - 1];
            clipped += Ax[q] > 1e-12 * fmin(*di, *dj);
            *di += Ax[q];
            *dj += Ax[q];
            Ax[q] = 0.0;
        }
    for (size_t k = 0; k < l->coupling_count; k++) {
        pp_coupling *cp = &l->coupling[k];
        if (!(cp->value > 0.0))
            continue;
        double *d = &Ax[Ap[cp->row + 1] - 1];
        clipped += cp->value > 1e-12 * *d;
        *d += cp->value;
        cp->value = 0.0;
    }
    return clipped;
}

int pp_laplacian_assemble(const pp_tetmesh *m, const int32_t *free_index, size_t n_free,
                          const int32_t *fixed_joint, int lump_obtuse, pp_laplacian *out,
                          cholmod_common *c)
{
    memset(out, 0, sizeof *out);
    size_t *count = calloc(n_free + 1, sizeof *count);
    if (!count)
        return -1;
    size_t coupling = 0;
    for (size_t t = 0; t < m->tet_count; t++) {
        const uint32_t *tv = m->tets + 4 * t;
        for (int a = 0; a < 4; a++) {
            int32_t fa = free_index[tv[a]];
            for (int b = 0; b < 4; b++) {
                int32_t fb = free_index[tv[b]];
                if (fa >= 0 && fb >= 0 && fa <= fb)
                    count[fb + 1]++;
                else if (fa >= 0 && fb < 0)
                    coupling++;
            }
        }
    }
    for (size_t j = 0; j < n_free; j++)
        count[j + 1] += count[j];
    size_t raw = count[n_free];
    int *rows = malloc((raw ? raw : 1) * sizeof *rows);
    size_t *fill = malloc((n_free + 1) * sizeof *fill);
    out->coupling = malloc((coupling ? coupling : 1) * sizeof *out->coupling);
    if (!rows || !fill || !out->coupling) {
        free(count), free(rows), free(fill);
        pp_laplacian_free(out, c);
        return -1;
    }
    memcpy(fill, count, (n_free + 1) * sizeof *fill);
    for (size_t t = 0; t < m->tet_count; t++) {
        const uint32_t *tv = m->tets + 4 * t;
        for (int a = 0; a < 4; a++)
            for (int b = 0; b < 4; b++) {
                int32_t fa = free_index[tv[a]], fb = free_index[tv[b]];
                if (fa >= 0 && fb >= 0 && fa <= fb)
                    rows[fill[fb]++] = fa;
            }
    }
    /* Merge duplicates column by column, compacting in place. */
    size_t nnz = 0;
    for (size_t j = 0; j < n_free; j++) {
        size_t n = count[j + 1] - count[j];
        sort_unique(rows + count[j], &n);
        memmove(rows + nnz, rows + count[j], n * sizeof *rows);
        fill[j] = nnz;
        nnz += n;
    }
    fill[n_free] = nnz;
    free(count);
    cholmod_sparse *A = cholmod_allocate_sparse(n_free, n_free, nnz, 1, 1, 1, CHOLMOD_REAL, c);
    if (!A) {
        free(rows), free(fill);
        pp_laplacian_free(out, c);
        return -1;
    }
    int *Ap = A->p, *Ai = A->i;
    double *Ax = A->x;
    for (size_t j = 0; j <= n_free; j++)
        Ap[j] = (int)fill[j];
    memcpy(Ai, rows, nnz * sizeof *Ai);
    memset(Ax, 0, nnz * sizeof *Ax);
    free(rows);
    free(fill);
    out->A = A;
    for (size_t t = 0; t < m->tet_count; t++) {
        const uint32_t *tv = m->tets + 4 * t;
        double k[4][4];
        if (pp_tet_local_stiffness(m->positions + 3 * (size_t)tv[0], m->positions + 3 * (size_t)tv[1],
                             m->positions + 3 * (size_t)tv[2], m->positions + 3 * (size_t)tv[3],
                             k) == 0.0)
            continue;
        for (int a = 0; a < 4; a++) {
            int32_t fa = free_index[tv[a]];
            if (fa < 0)
                continue;
            for (int b = 0; b < 4; b++) {
                int32_t fb = free_index[tv[b]];
                if (fb >= 0 && fa <= fb) {
                    size_t pos = find_row(Ai, (size_t)Ap[fb], (size_t)Ap[fb + 1], fa);
                    Ax[pos] += k[a][b];
                } else if (fb < 0) {
                    out->coupling[out->coupling_count++] =
                        (pp_coupling){(uint32_t)fa, (uint32_t)fixed_joint[tv[b]], k[a][b]};
                }
            }
        }
    }
    if (merge_coupling(out, n_free) < 0) {
        pp_laplacian_free(out, c);
        return -1;
    }
    if (lump_obtuse)
        out->clipped = clip_positive(out, n_free);
    return 0;
}

void pp_laplacian_free(pp_laplacian *l, cholmod_common *c)
{
    if (!l)
        return;
    if (l->A)
        cholmod_free_sparse(&l->A, c);
    free(l->coupling);
    memset(l, 0, sizeof *l);
}
