/* SPDX-License-Identifier: Apache-2.0
 *
 * The template's "couplings" resolved to simulation nodes (bake_pipeline.h
 * pp_bake_couplings): every soft node (a tet vertex of a soft tet and of no
 * bone tet: the nodes POSE_FEM and pose_step move) within an entry's reach
 * of its bone meshes' surface, tied to the entry's joint, anchored at its
 * rest position. A node within reach of several entries takes the nearest
 * bone surface (the earlier entry on a tie).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake_pipeline.h"
#include "embed_geom.h"

/* Whether bone mesh b belongs to entry e. */
static int entry_has(const pp_template_coupling *e, const pp_mesh *bones, const int *bone_joint,
                     size_t b)
{
    return e->bone[0] ? strcmp(bones[b].name, e->bone) == 0 : bone_joint[b] == e->joint;
}

/* Squared distance from p to mesh m's surface, or > r2 when beyond reach
 * (triangles whose box is farther than the reach are skipped). */
static double mesh_dist2(const pp_mesh *m, const double p[3], double reach, double r2)
{
    double best = r2 * 4.0 + 1.0;
    for (size_t f = 0; f < m->triangle_count; f++) {
        double c[3][3];
        int out = 0;
        for (int k = 0; k < 3 && !out; k++)
            for (int a = 0; a < 3; a++)
                c[k][a] = m->positions[3 * (size_t)m->triangles[3 * f + (size_t)k] + a];
        for (int a = 0; a < 3 && !out; a++)
            out = p[a] + reach < fmin(c[0][a], fmin(c[1][a], c[2][a])) ||
                  p[a] - reach > fmax(c[0][a], fmax(c[1][a], c[2][a]));
        if (!out)
            best = fmin(best, pp_point_triangle_dist2(p, c[0], c[1], c[2], NULL));
    }
    return best;
}

int pp_bake_couplings(const pp_template *t, const pp_mesh *bones, const int *bone_joint,
                      size_t bone_count, const pp_tetmesh *tet, pose_fem_coupling **out,
                      size_t *count, char *err, size_t err_size)
{
    *out = NULL;
    *count = 0;
    if (t->coupling_count == 0)
        return POSE_OK;
    const size_t nc = t->coupling_count, nv = tet->vertex_count;
    /* each entry's meshes must be there, and their box grown by the reach */
    double(*box)[6] = calloc(nc, sizeof *box);
    uint8_t *soft = calloc(nv ? nv : 1, 1);
    double *best = malloc((nv ? nv : 1) * sizeof *best);
    int *which = malloc((nv ? nv : 1) * sizeof *which);
    if (!box || !soft || !best || !which) {
        free(box), free(soft), free(best), free(which);
        return pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "out of memory for the couplings");
    }
    int rc = POSE_OK;
    for (size_t e = 0; e < nc && rc >= 0; e++) {
        const pp_template_coupling *ce = &t->couplings[e];
        const double reach = 1e-3 * ce->reach_mm;
        double *bx = box[e];
        for (int a = 0; a < 3; a++)
            bx[a] = INFINITY, bx[3 + a] = -INFINITY;
        if (ce->joint < 0) /* soft-soft: bake_soft_couplings.c */
            continue;
        size_t meshes = 0;
        for (size_t b = 0; b < bone_count; b++) {
            if (!entry_has(ce, bones, bone_joint, b))
                continue;
            meshes++;
            for (size_t v = 0; v < bones[b].vertex_count; v++)
                for (int a = 0; a < 3; a++) {
                    bx[a] = fmin(bx[a], bones[b].positions[3 * v + a] - reach);
                    bx[3 + a] = fmax(bx[3 + a], bones[b].positions[3 * v + a] + reach);
                }
        }
        if (!meshes)
            rc = pp_fail(err, err_size, POSE_ERR_INVALID_ARGUMENT,
                         "template '%s': couplings[%zu] names %s '%s', but no such bone mesh was "
                         "given to the bake", t->name, e, ce->bone[0] ? "bone" : "joint",
                         ce->bone[0] ? ce->bone : t->joints[ce->joint].name);
    }
    /* soft nodes: in a soft tet (bit 1) and in no bone tet (bit 2) */
    for (size_t k = 0; k < tet->tet_count; k++)
        for (int c = 0; c < 4; c++)
            soft[tet->tets[4 * k + (size_t)c]] |= tet->labels[k] ? 2 : 1;
    size_t n = 0;
    for (size_t v = 0; v < nv && rc >= 0; v++) {
        which[v] = -1;
        if (soft[v] != 1)
            continue;
        const double p[3] = {tet->positions[3 * v], tet->positions[3 * v + 1],
                             tet->positions[3 * v + 2]};
        for (size_t e = 0; e < nc; e++) {
            const pp_template_coupling *ce = &t->couplings[e];
            const double reach = 1e-3 * ce->reach_mm, r2 = reach * reach;
            const double *bx = box[e]; /* empty for a soft-soft entry */
            if (p[0] < bx[0] || p[1] < bx[1] || p[2] < bx[2] || p[0] > bx[3] || p[1] > bx[4] ||
                p[2] > bx[5])
                continue;
            for (size_t b = 0; b < bone_count; b++) {
                if (!entry_has(ce, bones, bone_joint, b))
                    continue;
                const double d2 = mesh_dist2(&bones[b], p, reach, r2);
                if (d2 <= r2 && (which[v] < 0 || d2 < best[v])) {
                    n += which[v] < 0;
                    which[v] = (int)e;
                    best[v] = d2;
                }
            }
        }
    }
    pose_fem_coupling *c = NULL;
    if (rc >= 0 && n) {
        c = malloc(n * sizeof *c);
        if (!c)
            rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "out of memory for the couplings");
    }
    size_t k = 0;
    for (size_t v = 0; c && v < nv; v++) {
        if (which[v] < 0)
            continue;
        const pp_template_coupling *ce = &t->couplings[which[v]];
        c[k] = (pose_fem_coupling){.node = (uint32_t)v, .joint = ce->joint,
                                   .stiffness = ce->stiffness};
        memcpy(c[k].anchor, tet->positions + 3 * v, sizeof c[k].anchor);
        k++;
    }
    free(box), free(soft), free(best), free(which);
    if (rc < 0)
        return rc;
    *out = c;
    *count = k;
    return POSE_OK;
}
