/* SPDX-License-Identifier: Apache-2.0 */
/* One bar: a cylinder of soft tissue along local +X around a line of bones.
 *
 * Tet mesh: the cross-section is a polar grid (centre + `rings` rings of
 * `sectors` vertices, ring k at radius k/rings * radius / cos(pi/sectors) so
 * the polygon circumscribes the circle of the same nominal radius), split
 * into triangles and extruded in layers; every prism is cut into 3 tets by
 * the vertex-index rule (the diagonal of each side face runs from its lower-
 * to its higher-indexed vertex), so neighbouring prisms always agree.
 * Tissues are circles of the nominal radii, so their vertices lie inside the
 * mesh and, in general, not on tet vertices. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "synth_internal.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/** Geometry of the bar being built, for weights and embedding. */
typedef struct bar {
    const ps_bar_spec *s;
    size_t v0, t0, j0;        /* first vertex, tet, joint of this bar */
    int layers, ntri;
    size_t per_layer;         /* vertices per layer */
    double dz, gap, bone_r;   /* bone_r: polygon radius of the bone ring */
    int (*tri)[3];            /* disk triangles as in-layer vertex offsets */
    int *band;                /* radial band of each triangle */
} bar;

static double ring_radius(const bar *b, int k)
{
    return b->s->radius * k / b->s->rings / cos(M_PI / b->s->sectors);
}

static size_t ring_vertex(const bar *b, int k, int sector)
{
    int S = b->s->sectors;
    return k == 0 ? 0 : 1 + (size_t)(k - 1) * S + (size_t)((sector % S + S) % S);
}

static void to_world(const bar *b, const double local[3], float out[3])
{
    float l[3] = {(float)local[0], (float)local[1], (float)local[2]}, r[3];
    ps_quat_rotate(b->s->frame, l, r);
    for (int i = 0; i < 3; i++)
        out[i] = b->s->origin[i] + r[i];
}

/* ------------------------------------------------------------- weights */

/* Distance from (x, r) to bone `k`'s solid [start, end] x [0, bone_r]. */
static double bone_distance(const bar *b, int k, double x, double r)
{
    double start = k * b->s->period + b->gap / 2, end = (k + 1) * b->s->period - b->gap / 2;
    double dx = x < start ? start - x : (x > end ? x - end : 0.0);
    double dr = r > b->bone_r ? r - b->bone_r : 0.0;
    double d = sqrt(dx * dx + dr * dr);
    return d < 1e-9 * b->s->period ? 0.0 : d;
}

/* Compact smooth falloff: 1 on the bone, (1 - d/h)^3 out to h = gap, so no
 * other bone reaches into a bone (bones move rigidly). Normalized, K largest
 * kept, renormalized; unused slots repeat the first joint with weight 0. */
static void vertex_weights(const bar *b, double x, double r, unsigned K, uint16_t *wj, float *w)
{
    int n = b->s->bones;
    double f[64], sum = 0.0;
    int nearest = 0;
    double dmin = INFINITY;
    for (int k = 0; k < n; k++) {
        double d = bone_distance(b, k, x, r);
        double h = b->gap;
        f[k] = d >= h * (1.0 - 1e-6) ? 0.0 : pow(1.0 - d / h, 3.0);
        sum += f[k];
        if (d < dmin) {
            dmin = d;
            nearest = k;
        }
    }
    if (sum <= 0.0) {
        f[nearest] = 1.0;
        sum = 1.0;
    }
    int pick[POSE_SYNTH_MAX_K];
    unsigned m = 0;
    for (unsigned i = 0; i < K; i++) {
        int best = -1;
        for (int k = 0; k < n; k++) {
            bool used = false;
            for (unsigned q = 0; q < m; q++)
                used |= pick[q] == k;
            if (!used && f[k] > 0.0 && (best < 0 || f[k] > f[best]))
                best = k;
        }
        if (best < 0)
            break;
        pick[m++] = best;
    }
    double kept = 0.0;
    for (unsigned i = 0; i < m; i++)
        kept += f[pick[i]];
    float total = 0.0f;
    for (unsigned i = 0; i < K; i++) {
        wj[i] = (uint16_t)(b->j0 + (size_t)pick[i < m ? i : 0]);
        w[i] = i < m ? (float)(f[pick[i]] / kept) : 0.0f;
        total += w[i];
    }
    w[0] += 1.0f - total; /* exact float partition of unity */
}

/* ------------------------------------------------------------- mesh */

static bool build_disk(bar *b)
{
    int R = b->s->rings, S = b->s->sectors;
    b->ntri = S + (R - 1) * 2 * S;
    b->tri = malloc((size_t)b->ntri * sizeof *b->tri);
    b->band = malloc((size_t)b->ntri * sizeof *b->band);
    if (!b->tri || !b->band)
        return false;
    int t = 0;
    for (int s = 0; s < S; s++, t++) {
        b->tri[t][0] = 0;
        b->tri[t][1] = (int)ring_vertex(b, 1, s);
        b->tri[t][2] = (int)ring_vertex(b, 1, s + 1);
        b->band[t] = 0;
    }
    for (int k = 1; k < R; k++)
        for (int s = 0; s < S; s++, t += 2) {
            int a = (int)ring_vertex(b, k, s), c = (int)ring_vertex(b, k + 1, s + 1);
            b->tri[t][0] = a;
            b->tri[t][1] = (int)ring_vertex(b, k, s + 1);
            b->tri[t][2] = c;
            b->tri[t + 1][0] = a;
            b->tri[t + 1][1] = c;
            b->tri[t + 1][2] = (int)ring_vertex(b, k + 1, s);
            b->band[t] = b->band[t + 1] = k;
        }
    return true;
}

static double orient(const float *p, const uint32_t v[4])
{
    const float *a = p + 3 * v[0], *b = p + 3 * v[1], *c = p + 3 * v[2], *d = p + 3 * v[3];
    double u[3], w[3], x[3];
    for (int i = 0; i < 3; i++) {
        u[i] = (double)b[i] - a[i];
        w[i] = (double)c[i] - a[i];
        x[i] = (double)d[i] - a[i];
    }
    return u[0] * (w[1] * x[2] - w[2] * x[1]) - u[1] * (w[0] * x[2] - w[2] * x[0]) +
           u[2] * (w[0] * x[1] - w[1] * x[0]);
}

static void add_joints(pose_synth_rig *r, const bar *b)
{
    const ps_bar_spec *s = b->s;
    for (int k = 0; k < s->bones; k++) {
        size_t j = r->joint_count++;
        pose_joint_desc *jd = &r->joints[j];
        memset(jd, 0, sizeof *jd);
        snprintf(r->joint_names[j], PS_NAME_SIZE, "%sjoint%d", s->prefix, k);
        jd->parent = k == 0 ? s->parent : (int)(j - 1);
        memcpy(jd->rest_model.rotation, s->frame, sizeof s->frame);
        double local[3] = {k * s->period, 0.0, 0.0};
        to_world(b, local, jd->rest_model.translation);
        if (jd->parent >= 0) {
            jd->limit_flags = POSE_LIMIT_X | POSE_LIMIT_Y | POSE_LIMIT_Z;
            jd->limit_order = POSE_EULER_XYZ;
            for (int a = 0; a < 3; a++) {
                jd->limit_min_deg[a] = -s->limit_deg;
                jd->limit_max_deg[a] = s->limit_deg;
            }
        }
    }
}

static void add_mesh(pose_synth_rig *r, const bar *b)
{
    const ps_bar_spec *s = b->s;
    int R = s->rings, S = s->sectors;
    unsigned K = r->influences;
    for (int l = 0; l <= b->layers; l++) {
        double x = l * b->dz;
        for (size_t i = 0; i < b->per_layer; i++) {
            int k = i == 0 ? 0 : 1 + (int)((i - 1) / (size_t)S);
            int sec = i == 0 ? 0 : (int)((i - 1) % (size_t)S);
            double rr = ring_radius(b, k), th = 2.0 * M_PI * sec / S;
            double local[3] = {x, rr * cos(th), rr * sin(th)};
            size_t v = r->vertex_count++;
            to_world(b, local, &r->tet_positions[3 * v]);
            vertex_weights(b, x, rr, K, &r->weight_joints[v * K], &r->weights[v * K]);
        }
    }
    int bone_band = R / 2;
    for (int l = 0; l < b->layers; l++) {
        double xc = (l + 0.5) * b->dz;
        int bone = (int)(xc / s->period);
        double in = xc - bone * s->period;
        bool in_bone = bone < s->bones && in > b->gap / 2 && in < s->period - b->gap / 2;
        size_t base = b->v0 + (size_t)l * b->per_layer;
        for (int t = 0; t < b->ntri; t++) {
            int o[3] = {b->tri[t][0], b->tri[t][1], b->tri[t][2]};
            for (int i = 0; i < 2; i++) /* sort the three offsets */
                for (int q = 0; q < 2 - i; q++)
                    if (o[q] > o[q + 1]) {
                        int tmp = o[q];
                        o[q] = o[q + 1];
                        o[q + 1] = tmp;
                    }
            uint32_t a = (uint32_t)(base + o[0]), bb = (uint32_t)(base + o[1]),
                     c = (uint32_t)(base + o[2]), up = (uint32_t)b->per_layer;
            uint32_t cut[3][4] = {{a, bb, c, c + up}, {a, bb, bb + up, c + up},
                                  {a, a + up, bb + up, c + up}};
            uint16_t label = in_bone && b->band[t] < bone_band ? (uint16_t)(b->j0 + bone + 1) : 0;
            for (int m = 0; m < 3; m++) {
                size_t ti = r->tet_count++;
                uint32_t *tv = &r->tets[4 * ti];
                memcpy(tv, cut[m], sizeof cut[m]);
                if (orient(r->tet_positions, tv) < 0.0) {
                    uint32_t tmp = tv[2];
                    tv[2] = tv[3];
                    tv[3] = tmp;
                }
                r->labels[ti] = label;
            }
        }
    }
}

/* ------------------------------------------------------------- embedding */

static double bary_of(const float *pos, const uint32_t v[4], const float p[3], double bc[4])
{
    const float *a = pos + 3 * v[0];
    double e[3][3], d[3];
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < 3; k++)
            e[k][i] = (double)pos[3 * v[k + 1] + i] - a[i];
        d[i] = (double)p[i] - a[i];
    }
    /* Cramer's rule on [e0 e1 e2] x = d (columns e_k). */
    double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                 e[1][0] * (e[0][1] * e[2][2] - e[0][2] * e[2][1]) +
                 e[2][0] * (e[0][1] * e[1][2] - e[0][2] * e[1][1]);
    double x[3];
    for (int c = 0; c < 3; c++) {
        double m[3][3];
        memcpy(m, e, sizeof m);
        for (int i = 0; i < 3; i++)
            m[c][i] = d[i];
        x[c] = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                m[1][0] * (m[0][1] * m[2][2] - m[0][2] * m[2][1]) +
                m[2][0] * (m[0][1] * m[1][2] - m[0][2] * m[1][1])) / det;
    }
    bc[1] = x[0];
    bc[2] = x[1];
    bc[3] = x[2];
    bc[0] = 1.0 - x[0] - x[1] - x[2];
    double mn = bc[0];
    for (int i = 1; i < 4; i++)
        mn = bc[i] < mn ? bc[i] : mn;
    return mn;
}

/* The containing tet, found analytically: the prisms around the point's
 * (layer, band, sector), best = largest smallest barycentric coordinate. */
static void embed(const pose_synth_rig *r, const bar *b, const double local[3], const float p[3],
                  uint32_t *tet, float bary[4])
{
    const ps_bar_spec *s = b->s;
    int R = s->rings, S = s->sectors;
    int l = (int)floor(local[0] / b->dz);
    l = l < 0 ? 0 : (l >= b->layers ? b->layers - 1 : l);
    double th = atan2(local[2], local[1]);
    if (th < 0)
        th += 2.0 * M_PI;
    int sec = (int)floor(th / (2.0 * M_PI / S));
    int band = (int)floor(hypot(local[1], local[2]) / (s->radius / R));
    band = band >= R ? R - 1 : band;
    double best = -INFINITY, bc[4], keep[4] = {1, 0, 0, 0};
    uint32_t best_tet = 0;
    /* Nearest prisms first: almost every point is inside the first one. */
    for (int ring = 0; ring <= 3 && best < -1e-7; ring++)
        for (int dl = -1; dl <= 1; dl++)
            for (int db = -1; db <= 1; db++)
                for (int ds = -1; ds <= 1; ds++) {
                    if (abs(dl) + abs(db) + abs(ds) != ring)
                        continue;
                    int ll = l + dl, k = band + db;
                    if (ll < 0 || ll >= b->layers || k < 0 || k >= R)
                        continue;
                    int sc = ((sec + ds) % S + S) % S;
                    int first = k == 0 ? sc : S + (k - 1) * 2 * S + 2 * sc;
                    int count = k == 0 ? 1 : 2;
                    for (int t = first; t < first + count; t++)
                        for (int m = 0; m < 3; m++) {
                            size_t ti = b->t0 + ((size_t)ll * b->ntri + (size_t)t) * 3 + (size_t)m;
                            double mn = bary_of(r->tet_positions, &r->tets[4 * ti], p, bc);
                            if (mn > best) {
                                best = mn;
                                best_tet = (uint32_t)ti;
                                memcpy(keep, bc, sizeof keep);
                            }
                        }
                }
    *tet = best_tet;
    for (int i = 0; i < 4; i++)
        bary[i] = (float)keep[i];
}

/* A closed tube x0..x1 of the given radius: `segments` + 1 rings of
 * `sectors` vertices (angles offset by half a sector), each end closed by a
 * ring at half the radius and a centre vertex; triangles face outwards. */
static bool add_tube(pose_synth_rig *r, const bar *b, const char *name, pose_tissue_kind kind,
                     int joint, double x0, double x1, double radius, int sectors, int segments)
{
    if (!ps_grow_tissues(r, r->tissue_count + 1))
        return false;
    ps_tissue *t = &r->tissues[r->tissue_count];
    memset(t, 0, sizeof *t);
    snprintf(t->name, PS_NAME_SIZE, "%s", name);
    t->kind = kind;
    t->joint = joint;
    size_t tube = (size_t)(segments + 1) * sectors;
    t->vertex_count = tube + 2 * ((size_t)sectors + 1);
    t->triangle_count = (size_t)segments * sectors * 2 + 2 * (size_t)sectors * 3;
    t->positions = malloc(t->vertex_count * 3 * sizeof(float));
    t->triangles = malloc(t->triangle_count * 3 * sizeof(uint32_t));
    t->tet = malloc(t->vertex_count * sizeof(uint32_t));
    t->bary = malloc(t->vertex_count * 4 * sizeof(float));
    r->tissue_count++; /* counted now so pose_synth_free releases the arrays */
    if (!t->positions || !t->triangles || !t->tet || !t->bary)
        return false;

    size_t v = 0;
    double local[3];
    for (int i = 0; i <= segments; i++)
        for (int s = 0; s < sectors; s++, v++) {
            double th = 2.0 * M_PI * (s + 0.5) / sectors;
            local[0] = x0 + (x1 - x0) * i / segments;
            local[1] = radius * cos(th);
            local[2] = radius * sin(th);
            to_world(b, local, &t->positions[3 * v]);
            embed(r, b, local, &t->positions[3 * v], &t->tet[v], &t->bary[4 * v]);
        }
    size_t cap[2];
    for (int e = 0; e < 2; e++) {
        cap[e] = v;
        for (int s = 0; s <= sectors; s++, v++) {
            double th = 2.0 * M_PI * (s + 0.5) / sectors;
            local[0] = e ? x1 : x0;
            local[1] = s < sectors ? 0.5 * radius * cos(th) : 0.0;
            local[2] = s < sectors ? 0.5 * radius * sin(th) : 0.0;
            to_world(b, local, &t->positions[3 * v]);
            embed(r, b, local, &t->positions[3 * v], &t->tet[v], &t->bary[4 * v]);
        }
    }
    uint32_t *tri = t->triangles;
#define TRI(A, B, C) (tri[0] = (uint32_t)(A), tri[1] = (uint32_t)(B), tri[2] = (uint32_t)(C), tri += 3)
    for (int i = 0; i < segments; i++)
        for (int s = 0; s < sectors; s++) {
            size_t a = (size_t)i * sectors + s, bb = (size_t)i * sectors + (s + 1) % sectors;
            size_t c = bb + sectors, d = a + sectors;
            TRI(a, bb, c);
            TRI(a, c, d);
        }
    for (int e = 0; e < 2; e++) {
        size_t outer = e ? (size_t)segments * sectors : 0, mid = cap[e], centre = cap[e] + sectors;
        for (int s = 0; s < sectors; s++) {
            size_t s1 = (size_t)(s + 1) % sectors;
            size_t ms = mid + s, m1 = mid + s1, os = outer + s, o1 = outer + s1;
            if (e == 0) { /* outward is -X */
                TRI(centre, m1, ms);
                TRI(ms, m1, o1);
                TRI(ms, o1, os);
            } else {
                TRI(centre, ms, m1);
                TRI(ms, o1, m1);
                TRI(ms, os, o1);
            }
        }
    }
#undef TRI
    return true;
}

bool ps_add_bar(pose_synth_rig *r, const ps_bar_spec *s)
{
    bar b = {.s = s, .v0 = r->vertex_count, .t0 = r->tet_count, .j0 = r->joint_count};
    b.layers = s->bones * s->layers_per_period;
    b.per_layer = 1 + (size_t)s->rings * s->sectors;
    b.dz = s->period / s->layers_per_period;
    b.gap = s->period / 4.0;
    b.bone_r = ring_radius(&b, s->rings / 2);
    bool ok = build_disk(&b) && ps_grow_joints(r, r->joint_count + (size_t)s->bones) &&
              ps_reserve(r, r->vertex_count + (size_t)(b.layers + 1) * b.per_layer,
                         r->tet_count + (size_t)b.layers * b.ntri * 3);
    if (ok) {
        add_joints(r, &b);
        add_mesh(r, &b);
        char name[PS_NAME_SIZE];
        double length = s->bones * s->period;
        snprintf(name, sizeof name, "%sskin", s->prefix);
        ok = add_tube(r, &b, name, POSE_TISSUE_SKIN, -1, 0.0, length, s->radius, s->skin_sectors,
                      s->bones * s->skin_layers_per_period);
        for (int k = 0; ok && k < s->bones; k++) {
            snprintf(name, sizeof name, "%sbone%d", s->prefix, k);
            /* Slightly inside the bone's tets, so every vertex moves with its bone alone. */
            double inset = 0.02 * s->period;
            ok = add_tube(r, &b, name, POSE_TISSUE_BONE, (int)(b.j0 + (size_t)k),
                          k * s->period + b.gap / 2 + inset,
                          (k + 1) * s->period - b.gap / 2 - inset, 0.97 * s->radius / 2,
                          s->bone_sectors, s->bone_layers);
        }
    }
    free(b.tri);
    free(b.band);
    return ok;
}
