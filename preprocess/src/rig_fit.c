/* SPDX-License-Identifier: Apache-2.0
 *
 * Rigging driver: per joint, gather the articular contact region between its
 * segment and its parent's, fit the rule's shape, then build frames once all
 * centres are known (a frame's z axis points along the segment, towards the
 * child joint).
 */
#include "rig_fit.h"

#include "embed_geom.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A growable list of points (xyz doubles). */
typedef struct pt_list {
    double *p;
    size_t n, cap;
} pt_list;

static int pts_push(pt_list *l, const float *v)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 256;
        double *p = realloc(l->p, cap * 3 * sizeof *p);
        if (!p)
            return 0;
        l->p = p;
        l->cap = cap;
    }
    for (int k = 0; k < 3; k++)
        l->p[3 * l->n + k] = v[k];
    l->n++;
    return 1;
}

/* Uniform grid of triangles (a set of meshes) for "is this point within d of
 * the surface" queries; each triangle is filed in every cell its box, grown
 * by d, overlaps, so one cell answers a query. */
typedef struct tri_grid {
    double lo[3], h;
    int dim[3];
    uint32_t *start;  /* cells + 1 */
    uint32_t *items;  /* (mesh, triangle) packed as index into refs */
    const pp_mesh **meshes;
    size_t mesh_count;
    uint32_t *ref_mesh, *ref_tri;
} tri_grid;

static void tri_grid_free(tri_grid *g)
{
    free(g->start);
    free(g->items);
    free(g->ref_mesh);
    free(g->ref_tri);
    memset(g, 0, sizeof *g);
}

static void tri_box(const pp_mesh *m, size_t t, double d, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++)
        lo[k] = INFINITY, hi[k] = -INFINITY;
    for (int c = 0; c < 3; c++) {
        const float *v = m->positions + 3 * (size_t)m->triangles[3 * t + c];
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], v[k] - d);
            hi[k] = fmax(hi[k], v[k] + d);
        }
    }
}

static int cell_of(const tri_grid *g, double x, int k)
{
    int c = (int)floor((x - g->lo[k]) / g->h);
    return c < 0 ? 0 : c >= g->dim[k] ? g->dim[k] - 1 : c;
}

static int tri_grid_build(tri_grid *g, const pp_mesh **meshes, size_t mesh_count, double d)
{
    memset(g, 0, sizeof *g);
    g->meshes = meshes;
    g->mesh_count = mesh_count;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t ntri = 0;
    for (size_t m = 0; m < mesh_count; m++) {
        ntri += meshes[m]->triangle_count;
        for (size_t v = 0; v < meshes[m]->vertex_count; v++)
            for (int k = 0; k < 3; k++) {
                lo[k] = fmin(lo[k], meshes[m]->positions[3 * v + k] - d);
                hi[k] = fmax(hi[k], meshes[m]->positions[3 * v + k] + d);
            }
    }
    if (ntri == 0)
        return 0;
    double ext = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    g->h = fmax(ext / 96.0, 1e-4);
    size_t cells = 1;
    for (int k = 0; k < 3; k++) {
        g->lo[k] = lo[k];
        g->dim[k] = (int)ceil((hi[k] - lo[k]) / g->h) + 1;
        cells *= (size_t)g->dim[k];
    }
    g->start = calloc(cells + 1, sizeof *g->start);
    g->ref_mesh = malloc(ntri * sizeof *g->ref_mesh);
    g->ref_tri = malloc(ntri * sizeof *g->ref_tri);
    if (!g->start || !g->ref_mesh || !g->ref_tri)
        return -1;
    /* Two passes: count, then fill (CSR). */
    for (int pass = 0; pass < 2; pass++) {
        size_t r = 0;
        for (size_t m = 0; m < mesh_count; m++)
            for (size_t t = 0; t < meshes[m]->triangle_count; t++, r++) {
                double blo[3], bhi[3];
                tri_box(meshes[m], t, d, blo, bhi);
                int c0[3], c1[3];
                for (int k = 0; k < 3; k++) {
                    c0[k] = cell_of(g, blo[k], k);
                    c1[k] = cell_of(g, bhi[k], k);
                }
                if (pass == 1) {
                    g->ref_mesh[r] = (uint32_t)m;
                    g->ref_tri[r] = (uint32_t)t;
                }
                for (int z = c0[2]; z <= c1[2]; z++)
                    for (int y = c0[1]; y <= c1[1]; y++)
                        for (int x = c0[0]; x <= c1[0]; x++) {
                            size_t cell = ((size_t)z * g->dim[1] + y) * g->dim[0] + x;
                            if (pass == 0)
                                g->start[cell + 1]++;
                            else
                                g->items[g->start[cell]++] = (uint32_t)r;
                        }
            }
        if (pass == 0) {
            for (size_t c = 0; c < cells; c++)
                g->start[c + 1] += g->start[c];
            g->items = malloc((g->start[cells] ? g->start[cells] : 1) * sizeof *g->items);
            if (!g->items)
                return -1;
        } else {
            /* The fill advanced each start to the next cell's; shift back. */
            memmove(g->start + 1, g->start, cells * sizeof *g->start);
            g->start[0] = 0;
        }
    }
    return 1;
}

static int tri_grid_near(const tri_grid *g, const float *vf, double d)
{
    double p[3] = {vf[0], vf[1], vf[2]};
    int c[3];
    for (int k = 0; k < 3; k++) {
        double x = (p[k] - g->lo[k]) / g->h;
        if (x < 0 || x >= g->dim[k])
            return 0;
        c[k] = (int)x;
    }
    size_t cell = ((size_t)c[2] * g->dim[1] + c[1]) * g->dim[0] + c[0];
    for (uint32_t i = g->start[cell]; i < g->start[cell + 1]; i++) {
        uint32_t r = g->items[i];
        const pp_mesh *m = g->meshes[g->ref_mesh[r]];
        const uint32_t *t = m->triangles + 3 * (size_t)g->ref_tri[r];
        double a[3], b[3], cc[3];
        for (int k = 0; k < 3; k++) {
            a[k] = m->positions[3 * (size_t)t[0] + k];
            b[k] = m->positions[3 * (size_t)t[1] + k];
            cc[k] = m->positions[3 * (size_t)t[2] + k];
        }
        if (pp_point_triangle_dist2(p, a, b, cc, NULL) <= d * d)
            return 1;
    }
    return 0;
}

/* Points of meshes `from` lying within d of meshes `to`. */
static int contact_points(const pp_mesh **from, size_t nfrom, const pp_mesh **to, size_t nto,
                          double d, pt_list *out)
{
    tri_grid g;
    int rc = tri_grid_build(&g, to, nto, d);
    if (rc <= 0) {
        tri_grid_free(&g);
        return rc;
    }
    for (size_t m = 0; m < nfrom; m++)
        for (size_t v = 0; v < from[m]->vertex_count; v++)
            if (tri_grid_near(&g, from[m]->positions + 3 * v, d) &&
                !pts_push(out, from[m]->positions + 3 * v)) {
                tri_grid_free(&g);
                return -1;
            }
    tri_grid_free(&g);
    return 1;
}

static const pp_mesh *find_bone(const pp_mesh *bones, size_t n, const char *name)
{
    for (size_t i = 0; i < n; i++)
        if (strcmp(bones[i].name, name) == 0)
            return &bones[i];
    return NULL;
}

/* Resolve a list of names (or, when count is 0, the whole segment). */
static int resolve(const pp_template_joint *j, char (*names)[PP_NAME_MAX], size_t count,
                   const pp_mesh *bones, size_t nb, const pp_mesh **out, size_t *nout, char *err,
                   size_t err_size)
{
    if (count == 0) {
        names = j->bones;
        count = j->bone_count;
    }
    *nout = 0;
    for (size_t i = 0; i < count; i++) {
        const pp_mesh *m = find_bone(bones, nb, names[i]);
        if (!m)
            return pp_fail(err, err_size, POSE_ERR_NOT_FOUND,
                        "joint '%s': bone mesh '%s' named by the template was not given", j->name,
                        names[i]);
        out[(*nout)++] = m;
    }
    return POSE_OK;
}

static void covariance_axes(const double *pts, size_t n, double mean[3], double w[3],
                            double v[3][3])
{
    double cov[3][3] = {{0}};
    mean[0] = mean[1] = mean[2] = 0;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            mean[k] += pts[3 * i + k] / (double)n;
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                cov[a][b] += (pts[3 * i + a] - mean[a]) * (pts[3 * i + b] - mean[b]) / (double)n;
    pp_sym3_eigen(cov, w, v);
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static int normalize3(double a[3])
{
    double n = sqrt(dot3(a, a));
    if (!(n > 1e-12))
        return 0;
    for (int k = 0; k < 3; k++)
        a[k] /= n;
    return 1;
}

static void cross3(const double a[3], const double b[3], double r[3])
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}

/* Fit one joint's centre (and hinge axis into axis_out). */
static int fit_centre(const pp_template *t, size_t ji, const pp_mesh *bones, size_t nb,
                      pp_fit_joint *o, double axis_out[3], char *err, size_t err_size)
{
    const pp_template_joint *j = &t->joints[ji];
    size_t cap = 0;
    for (size_t k = 0; k < t->joint_count; k++)
        cap = t->joints[k].bone_count > cap ? t->joints[k].bone_count : cap;
    const pp_mesh **child = calloc(cap, sizeof *child), **parent = calloc(cap, sizeof *parent);
    pt_list pts = {0};
    int rc = POSE_OK;
    size_t nc = 0, np = 0;
    for (int k = 0; k < 3; k++)
        axis_out[k] = j->axis[k];
    if (!child || !parent) {
        rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    /* Every bone of the segment must exist, contact or not. */
    rc = resolve(j, NULL, 0, bones, nb, child, &nc, err, err_size);
    if (rc < 0)
        goto done;
    if (j->rule == PP_FIT_ROOT || j->rule == PP_FIT_FIXED) {
        double sum[3] = {0};
        size_t n = 0;
        for (size_t b = 0; b < nc; b++)
            for (size_t v = 0; v < child[b]->vertex_count; v++, n++)
                for (int k = 0; k < 3; k++)
                    sum[k] += child[b]->positions[3 * v + k];
        if (n == 0) {
            rc = pp_fail(err, err_size, POSE_ERR_INVALID_DATA, "joint '%s': its bones have no vertices",
                      j->name);
            goto done;
        }
        for (int k = 0; k < 3; k++)
            o->centre[k] = j->has_at ? j->at[k] : sum[k] / (double)n;
        goto done;
    }
    const pp_template_joint *pj = &t->joints[j->parent];
    rc = resolve(j, j->contact, j->contact_count, bones, nb, child, &nc, err, err_size);
    if (rc >= 0)
        rc = resolve(pj, j->parent_contact, j->parent_contact_count, bones, nb, parent, &np, err,
                     err_size);
    if (rc < 0)
        goto done;
    double d = j->contact_mm * 1e-3;
    int both = j->rule == PP_FIT_SPINE || j->side == PP_SIDE_BOTH;
    int r1 = 1, r2 = 1;
    if (both || j->side == PP_SIDE_CHILD)
        r1 = contact_points(child, nc, parent, np, d, &pts);
    if (r1 >= 0 && (both || j->side == PP_SIDE_PARENT))
        r2 = contact_points(parent, np, child, nc, d, &pts);
    if (r1 < 0 || r2 < 0) {
        rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    o->contact_points = pts.n;
    size_t need = j->rule == PP_FIT_SPINE ? 1 : 8;
    if (pts.n < need) {
        rc = pp_fail(err, err_size, POSE_ERR_INVALID_DATA,
                  "joint '%s': no contact region: %zu vertices of its bones lie within %.1f mm of "
                  "parent '%s' (need %zu); the bones are too far apart or 'contact_mm' is too small",
                  j->name, pts.n, (double)j->contact_mm, pj->name, need);
        goto done;
    }
    double mean[3], w[3], v[3][3], r = 0, rms = 0;
    covariance_axes(pts.p, pts.n, mean, w, v);
    if (j->grow_mm > 0 && j->rule != PP_FIT_SPINE) {
        /* Fit to the whole articular surface around the contact strip; the
         * axis keeps coming from the strip itself (computed above). */
        double g2 = (double)j->grow_mm * j->grow_mm * 1e-6;
        pts.n = 0;
        for (int s = 0; s < 2; s++) {
            if ((s == 0 && j->side == PP_SIDE_PARENT) || (s == 1 && j->side == PP_SIDE_CHILD))
                continue;
            const pp_mesh **set = s == 0 ? child : parent;
            size_t ns = s == 0 ? nc : np;
            for (size_t b = 0; b < ns; b++)
                for (size_t q = 0; q < set[b]->vertex_count; q++) {
                    const float *x = set[b]->positions + 3 * q;
                    double dd = 0;
                    for (int k = 0; k < 3; k++)
                        dd += (x[k] - mean[k]) * (x[k] - mean[k]);
                    if (dd <= g2 && !pts_push(&pts, x)) {
                        rc = pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "out of memory");
                        goto done;
                    }
                }
        }
        o->contact_points = pts.n;
    }
    int ok = 1;
    if (j->rule == PP_FIT_SPINE) {
        memcpy(o->centre, mean, sizeof mean);
    } else if (j->rule == PP_FIT_BALL) {
        ok = pp_fit_sphere(pts.p, pts.n, o->centre, &r, &rms);
    } else { /* hinge: the axis from the contact strip (v), fit to pts */
        int best = 0;
        double bd = -1;
        for (int c = 0; c < 3; c++) {
            double col[3] = {v[0][c], v[1][c], v[2][c]};
            double hint[3] = {j->axis[0], j->axis[1], j->axis[2]};
            if (fabs(dot3(col, hint)) > bd) {
                bd = fabs(dot3(col, hint));
                best = c;
            }
        }
        double hint[3] = {j->axis[0], j->axis[1], j->axis[2]};
        double ax[3] = {v[0][best], v[1][best], v[2][best]};
        if (dot3(ax, hint) < 0)
            for (int k = 0; k < 3; k++)
                ax[k] = -ax[k];
        memcpy(axis_out, ax, sizeof ax);
        ok = pp_fit_circle(pts.p, pts.n, ax, o->centre, &r, &rms);
    }
    /* A fitted centre far outside the region means the surface was nearly
     * flat; refuse it rather than rig a joint metres away. */
    double span = 2 * sqrt(fmax(w[0], 0)) + d + j->grow_mm * 1e-3;
    if (ok && j->rule != PP_FIT_SPINE) {
        double off[3] = {o->centre[0] - mean[0], o->centre[1] - mean[1], o->centre[2] - mean[2]};
        if (sqrt(dot3(off, off)) > 4 * span + 0.02)
            ok = 0;
    }
    if (!ok) {
        rc = pp_fail(err, err_size, POSE_ERR_INVALID_DATA,
                  "joint '%s': the %s fit of its %zu contact points degenerates (flat or "
                  "collinear region); try 'fit': \"parent\" or \"both\", or a larger 'contact_mm'",
                  j->name, pp_fit_rule_name(j->rule), pts.n);
        goto done;
    }
    o->radius_mm = r * 1e3;
    o->residual_mm = rms * 1e3;
done:
    free(child);
    free(parent);
    free(pts.p);
    return rc;
}

/* Direction of the segment at joint ji: towards the child joint whose
 * direction best agrees with "up", or the segment's principal axis for a
 * leaf, signed like "up"; "up" itself when nothing better is known. */
static void segment_direction(const pp_template *t, size_t ji, const pp_fit_joint *fits,
                              const pp_mesh *bones, size_t nb, double z[3])
{
    const pp_template_joint *j = &t->joints[ji];
    double up[3] = {j->up[0], j->up[1], j->up[2]};
    memcpy(z, up, sizeof up);
    if (j->rule == PP_FIT_ROOT)
        return;
    double best = 0.5;
    int found = 0;
    for (size_t c = ji + 1; c < t->joint_count; c++) {
        if (t->joints[c].parent != (int)ji)
            continue;
        double dir[3];
        for (int k = 0; k < 3; k++)
            dir[k] = fits[ji].centre[k] - fits[c].centre[k]; /* child joint -> this joint */
        if (!normalize3(dir))
            continue;
        double s = fabs(dot3(dir, up));
        if (s > best) {
            best = s;
            memcpy(z, dir, sizeof dir);
            found = 1;
        }
    }
    if (!found) {
        pt_list pts = {0};
        for (size_t b = 0; b < j->bone_count; b++) {
            const pp_mesh *m = find_bone(bones, nb, j->bones[b]);
            for (size_t v = 0; m && v < m->vertex_count; v++)
                if (!pts_push(&pts, m->positions + 3 * v))
                    break;
        }
        if (pts.n >= 4) {
            double mean[3], w[3], v[3][3];
            covariance_axes(pts.p, pts.n, mean, w, v);
            double ax[3] = {v[0][0], v[1][0], v[2][0]};
            if (fabs(dot3(ax, up)) > 0.7 && w[0] > 1.5 * w[1])
                memcpy(z, ax, sizeof ax);
        }
        free(pts.p);
    }
    if (dot3(z, up) < 0)
        for (int k = 0; k < 3; k++)
            z[k] = -z[k];
}

static void build_frame(const pp_template_joint *j, const double axis[3], const double zdir[3],
                        pp_fit_joint *o)
{
    double y[3] = {axis[0], axis[1], axis[2]}, z[3] = {zdir[0], zdir[1], zdir[2]}, x[3];
    normalize3(y);
    normalize3(z);
    if (j->rule == PP_FIT_HINGE) { /* the fitted axis is exact; bend z to it */
        double s = dot3(z, y);
        for (int k = 0; k < 3; k++)
            z[k] -= s * y[k];
        if (!normalize3(z)) { /* segment along the axis: any perpendicular */
            double alt[3] = {y[1], y[2], y[0]};
            cross3(y, alt, z);
            normalize3(z);
        }
    } else { /* z from the segment; the template axis is only a hint */
        double s = dot3(y, z);
        for (int k = 0; k < 3; k++)
            y[k] -= s * z[k];
        if (!normalize3(y)) {
            double alt[3] = {z[1], z[2], z[0]};
            cross3(z, alt, y);
            normalize3(y);
        }
    }
    cross3(y, z, x);
    normalize3(x);
    cross3(z, x, y); /* exact orthonormality after rounding */
    for (int r = 0; r < 3; r++) {
        o->frame[r][0] = x[r];
        o->frame[r][1] = y[r];
        o->frame[r][2] = z[r];
    }
    pp_quat_from_matrix(o->frame, o->rotation);
}

int pp_rig_fit(const pp_template *t, const pp_mesh *bones, size_t bone_count, pp_fit_joint *out,
               char *err, size_t err_size)
{
    if (!t || !out || (bone_count && !bones))
        return pp_fail(err, err_size, POSE_ERR_INVALID_ARGUMENT, "rig fit: NULL argument");
    memset(out, 0, t->joint_count * sizeof *out);
    double(*axes)[3] = calloc(t->joint_count ? t->joint_count : 1, sizeof *axes);
    if (!axes)
        return pp_fail(err, err_size, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    int rc = POSE_OK;
    for (size_t i = 0; i < t->joint_count && rc >= 0; i++)
        rc = fit_centre(t, i, bones, bone_count, &out[i], axes[i], err, err_size);
    for (size_t i = 0; i < t->joint_count && rc >= 0; i++) {
        double z[3];
        segment_direction(t, i, out, bones, bone_count, z);
        build_frame(&t->joints[i], axes[i], z, &out[i]);
    }
    free(axes);
    return rc;
}
