/* SPDX-License-Identifier: Apache-2.0
 *
 * The template's soft-soft "couplings" resolved on the tet mesh
 * (bake_pipeline.h pp_bake_soft_couplings): the free soft nodes of one
 * tissue's part of the mesh (the soft tets its vertices are embedded in)
 * that lie within reach of the other tissue's part, each tied to the
 * nearest point of the nearest of those tets (its corners and barycentric
 * weights). Brute force over the other part's tets, boxes first: a set-up
 * step.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_pipeline.h"
#include "embed_geom.h"

static const pose_tissue_desc *find_tissue(const pose_tissue_desc *tissues, size_t n,
                                           const char *name)
{
    for (size_t i = 0; i < n; i++)
        if (strcmp(tissues[i].name, name) == 0)
            return &tissues[i];
    return NULL;
}

/* Marks the soft tets tissue `td` is embedded in (bit `bit` of tet_mark). */
static void mark_part(const pose_tissue_desc *td, const pp_tetmesh *tet, uint8_t *tet_mark,
                      uint8_t bit)
{
    for (size_t v = 0; v < td->vertex_count; v++)
        if (tet->labels[td->tet[v]] == 0)
            tet_mark[td->tet[v]] |= bit;
}

static void corner(const pp_tetmesh *tet, size_t k, int c, double out[3])
{
    const float *p = tet->positions + 3 * (size_t)tet->tets[4 * k + (size_t)c];
    out[0] = p[0], out[1] = p[1], out[2] = p[2];
}

/* Squared distance from p to tet k and the barycentric weights of its
 * nearest point (clamped to the tet, summing to 1). */
static double nearest_in_tet(const pp_tetmesh *tet, size_t k, const double p[3], double w[4])
{
    double c[4][3];
    for (int i = 0; i < 4; i++)
        corner(tet, k, i, c[i]);
    double q[3] = {p[0], p[1], p[2]}, d2 = pp_point_tet_dist2(p, c[0], c[1], c[2], c[3]);
    if (d2 > 0.0) { /* outside: the nearest point lies on a face */
        static const int face[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
        double best = INFINITY, f[3];
        for (int i = 0; i < 4; i++) {
            const double x = pp_point_triangle_dist2(p, c[face[i][0]], c[face[i][1]],
                                                     c[face[i][2]], f);
            if (x < best)
                best = x, q[0] = f[0], q[1] = f[1], q[2] = f[2];
        }
    }
    if (!pp_tet_barycentric(q, c[0], c[1], c[2], c[3], w))
        return INFINITY; /* flat: never nearest */
    double sum = 0.0;
    for (int i = 0; i < 4; i++)
        sum += w[i] = w[i] > 0.0 ? w[i] : 0.0;
    for (int i = 0; i < 4; i++)
        w[i] /= sum;
    return d2;
}

int pp_bake_soft_couplings(const pp_template *t, const pose_tissue_desc *tissues,
                           size_t tissue_count, const pp_tetmesh *tet,
                           pose_fem_soft_coupling **out, size_t *count, char *err, size_t err_size)
{
    *out = NULL;
    *count = 0;
    const size_t nv = tet->vertex_count, nt = tet->tet_count;
    uint8_t *tet_mark = malloc(nt ? nt : 1), *node = malloc(nv ? nv : 1);
    double *box = malloc((nt ? nt : 1) * 6 * sizeof *box);
    if (!tet_mark || !node || !box) {
        free(tet_mark), free(node), free(box);
        return pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "out of memory for the couplings");
    }
    for (size_t k = 0; k < nt; k++) /* every tet's box */
        for (int a = 0; a < 3; a++) {
            double lo = INFINITY, hi = -INFINITY;
            for (int c = 0; c < 4; c++) {
                const double x = tet->positions[3 * (size_t)tet->tets[4 * k + (size_t)c] + a];
                lo = fmin(lo, x), hi = fmax(hi, x);
            }
            box[6 * k + (size_t)a] = lo, box[6 * k + 3 + (size_t)a] = hi;
        }
    pose_fem_soft_coupling *c = NULL;
    size_t n = 0, cap = 0;
    int rc = POSE_OK;
    for (size_t e = 0; e < t->coupling_count && rc >= 0; e++) {
        const pp_template_coupling *ce = &t->couplings[e];
        if (ce->joint >= 0) /* to a bone: bake_couplings.c */
            continue;
        const pose_tissue_desc *a = find_tissue(tissues, tissue_count, ce->tissue),
                               *b = find_tissue(tissues, tissue_count, ce->to);
        if (!a || !b) {
            rc = pp_fail(err, err_size, POSE_ERR_INVALID_ARGUMENT,
                         "template '%s': couplings[%zu] names tissue '%s', but the bake has no "
                         "such mesh", t->name, e, a ? ce->to : ce->tissue);
            break;
        }
        memset(tet_mark, 0, nt ? nt : 1);
        mark_part(a, tet, tet_mark, 1);
        mark_part(b, tet, tet_mark, 2);
        /* node bits: 1 in a's part, 2 in b's, 4 in a bone tet (held) */
        memset(node, 0, nv ? nv : 1);
        for (size_t k = 0; k < nt; k++)
            for (int i = 0; i < 4; i++)
                node[tet->tets[4 * k + (size_t)i]] |=
                    (uint8_t)((tet_mark[k] & 3) | (tet->labels[k] ? 4 : 0));
        const double reach = 1e-3 * ce->reach_mm, r2 = reach * reach;
        for (size_t v = 0; v < nv && rc >= 0; v++) {
            if (node[v] != 1) /* a's free node, not b's */
                continue;
            const double p[3] = {tet->positions[3 * v], tet->positions[3 * v + 1],
                                 tet->positions[3 * v + 2]};
            double best = INFINITY, w[4], bw[4] = {0, 0, 0, 0};
            size_t bk = 0;
            for (size_t k = 0; k < nt; k++) {
                const double *bx = box + 6 * k;
                if (!(tet_mark[k] & 2) || p[0] < bx[0] - reach || p[1] < bx[1] - reach ||
                    p[2] < bx[2] - reach || p[0] > bx[3] + reach || p[1] > bx[4] + reach ||
                    p[2] > bx[5] + reach)
                    continue;
                const double d2 = nearest_in_tet(tet, k, p, w);
                if (d2 < best)
                    best = d2, bk = k, memcpy(bw, w, sizeof bw);
            }
            if (!(best <= r2))
                continue;
            if (n == cap) {
                cap = cap ? 2 * cap : 64;
                pose_fem_soft_coupling *grown = realloc(c, cap * sizeof *c);
                if (!grown) {
                    rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY,
                                 "out of memory for the couplings");
                    break;
                }
                c = grown;
            }
            c[n] = (pose_fem_soft_coupling){.node = (uint32_t)v, .stiffness = ce->stiffness};
            for (int i = 0; i < 4; i++) {
                c[n].other[i] = tet->tets[4 * bk + (size_t)i];
                c[n].weight[i] = (float)bw[i];
            }
            n++;
        }
    }
    free(tet_mark), free(node), free(box);
    if (rc < 0) {
        free(c);
        return rc;
    }
    *out = c;
    *count = n;
    return POSE_OK;
}
