/* SPDX-License-Identifier: Apache-2.0 */
/* Building the simulation mesh (fem_mesh.h) from the rig's tets. */
#include "fem_mesh.h"

#include <math.h>
#include <string.h>

static size_t align64(size_t n)
{
    return (n + 63u) & ~(size_t)63u;
}

typedef struct layout {
    size_t tets, offsets, corners, inv_diag, mass, held, size;
} layout;

static layout layout_of(size_t nv, size_t soft)
{
    layout l;
    size_t off = 0;
    l.tets = off;
    off += align64(soft * sizeof(pose__fem_tet));
    l.offsets = off;
    off += align64((nv + 1) * sizeof(uint32_t));
    l.corners = off;
    off += align64(4 * soft * sizeof(uint32_t));
    l.inv_diag = off;
    off += align64(nv * sizeof(float));
    l.mass = off;
    off += align64(nv * sizeof(float));
    l.held = off;
    off += align64(nv);
    l.size = off;
    return l;
}

size_t pose__fem_mesh_size(size_t nv, size_t nt, const uint32_t *tets, const uint16_t *labels)
{
    (void)tets;
    size_t soft = 0;
    for (size_t t = 0; t < nt; t++)
        soft += labels[t] == 0;
    if (4 * soft >= UINT32_MAX || nv >= UINT32_MAX)
        return 0;
    return layout_of(nv, soft).size;
}

/* Inverse of the rest edge matrix; returns its determinant (6 x signed volume). */
static double rest_inverse(const float *x0, const float *x1, const float *x2, const float *x3,
                           double inv[9])
{
    double m[9]; /* columns: edges */
    for (int r = 0; r < 3; r++) {
        m[3 * r + 0] = (double)x1[r] - x0[r];
        m[3 * r + 1] = (double)x2[r] - x0[r];
        m[3 * r + 2] = (double)x3[r] - x0[r];
    }
    double c00 = m[4] * m[8] - m[5] * m[7], c01 = m[5] * m[6] - m[3] * m[8],
           c02 = m[3] * m[7] - m[4] * m[6];
    double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
    if (det == 0.0)
        return 0.0;
    double id = 1.0 / det;
    inv[0] = c00 * id;
    inv[1] = (m[2] * m[7] - m[1] * m[8]) * id;
    inv[2] = (m[1] * m[5] - m[2] * m[4]) * id;
    inv[3] = c01 * id;
    inv[4] = (m[0] * m[8] - m[2] * m[6]) * id;
    inv[5] = (m[2] * m[3] - m[0] * m[5]) * id;
    inv[6] = c02 * id;
    inv[7] = (m[1] * m[6] - m[0] * m[7]) * id;
    inv[8] = (m[0] * m[4] - m[1] * m[3]) * id;
    return det;
}

size_t pose__fem_mesh_build(size_t nv, const float *pos, size_t nt, const uint32_t *tets,
                            const uint16_t *labels, const pose__fem_material *soft,
                            void *memory, pose__fem_mesh *out)
{
    size_t soft_total = 0;
    for (size_t t = 0; t < nt; t++)
        soft_total += labels[t] == 0;
    layout l = layout_of(nv, soft_total);
    unsigned char *base = memory;
    memset(base, 0, l.size);
    pose__fem_tet *ft = (pose__fem_tet *)(base + l.tets);
    uint32_t *offset = (uint32_t *)(base + l.offsets);
    uint32_t *corners = (uint32_t *)(base + l.corners);
    float *inv_diag = (float *)(base + l.inv_diag);
    float *mass = (float *)(base + l.mass);
    uint8_t *held = base + l.held;

    /* Every vertex of a bone tet is held: bones are rigid. */
    for (size_t t = 0; t < nt; t++)
        if (labels[t] != 0)
            for (int c = 0; c < 4; c++)
                held[tets[4 * t + (size_t)c]] = 1;

    const double E = soft->young, nu = soft->poisson;
    const double mu = E / (2.0 * (1.0 + nu)), lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    size_t n = 0, degenerate = 0;
    /* Diagonal of the stiffness accumulated in double, then inverted. */
    for (size_t t = 0; t < nt; t++) {
        if (labels[t] != 0)
            continue;
        const uint32_t *v = tets + 4 * t;
        if (held[v[0]] && held[v[1]] && held[v[2]] && held[v[3]])
            continue; /* no free vertex: nothing to solve for */
        double inv[9];
        double det = rest_inverse(pos + 3 * (size_t)v[0], pos + 3 * (size_t)v[1],
                                  pos + 3 * (size_t)v[2], pos + 3 * (size_t)v[3], inv);
        double vol = fabs(det) / 6.0;
        if (!(vol > 0.0) || !isfinite(inv[0] + inv[4] + inv[8])) {
            degenerate++;
            continue;
        }
        pose__fem_tet *r = &ft[n++];
        memcpy(r->v, v, sizeof r->v);
        for (int k = 0; k < 9; k++)
            r->b[k] = (float)inv[k];
        r->vmu = (float)(vol * mu);
        r->vkappa = (float)(vol * (lam + 2.0 * mu / 3.0));
        double g0[3] = {-(inv[0] + inv[3] + inv[6]), -(inv[1] + inv[4] + inv[7]),
                        -(inv[2] + inv[5] + inv[8])};
        for (int c = 0; c < 4; c++) {
            const double *g = c == 0 ? g0 : inv + 3 * (c - 1);
            double gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
            /* trace / 3 of the 3x3 diagonal block V (mu |g|^2 I + (mu + lambda) g g^T):
             * invariant under the tet's rotation, so computed once */
            inv_diag[v[c]] += (float)(vol * (mu * gg + (mu + lam) * gg / 3.0));
            mass[v[c]] += (float)(vol * soft->density / 4.0);
            offset[v[c] + 1]++;
        }
    }
    for (size_t i = 0; i < nv; i++) {
        offset[i + 1] += offset[i];
        inv_diag[i] = held[i] || inv_diag[i] <= 0.0f ? 0.0f : 1.0f / inv_diag[i];
    }
    /* Corners in tet order per vertex: the gather sums in this fixed order. */
    for (size_t t = 0; t < n; t++)
        for (uint32_t c = 0; c < 4; c++) {
            uint32_t vi = ft[t].v[c];
            corners[offset[vi]++] = (uint32_t)(4 * t + c);
        }
    for (size_t i = nv; i > 0; i--)
        offset[i] = offset[i - 1];
    offset[0] = 0;

    size_t free_count = 0;
    for (size_t i = 0; i < nv; i++)
        free_count += inv_diag[i] > 0.0f;
    *out = (pose__fem_mesh){
        .vertex_count = nv,
        .tet_count = n,
        .chunk_count = (nv + POSE__FEM_CHUNK - 1) / POSE__FEM_CHUNK,
        .free_count = free_count,
        .tets = ft,
        .corner_offset = offset,
        .corners = corners,
        .inv_diag = inv_diag,
        .mass = mass,
        .bulk = lam + 2.0 * mu / 3.0,
    };
    return degenerate;
}

static void surface_point(const pose__fem_surface *s, const float *x, size_t v, double p[3])
{
    const uint32_t *t = s->tets + 4 * (size_t)s->tet[v];
    const float *b = s->bary + 4 * v;
    for (int a = 0; a < 3; a++)
        p[a] = (double)b[0] * x[3 * (size_t)t[0] + a] + (double)b[1] * x[3 * (size_t)t[1] + a] +
               (double)b[2] * x[3 * (size_t)t[2] + a] + (double)b[3] * x[3 * (size_t)t[3] + a];
}

double pose__fem_surface_volume(const pose__fem_surface *s, const float *x)
{
    double v = 0.0;
    for (size_t f = 0; f < s->triangle_count; f++) {
        double a[3], b[3], c[3];
        surface_point(s, x, s->triangles[3 * f], a);
        surface_point(s, x, s->triangles[3 * f + 1], b);
        surface_point(s, x, s->triangles[3 * f + 2], c);
        v += a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
             a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return v / 6.0;
}

void pose__fem_mesh_set_surface(pose__fem_mesh *m, const pose__fem_surface *s, const float *x)
{
    m->surface = *s;
    double v = pose__fem_surface_volume(s, x);
    if (!(v > 0.0)) {
        m->surface.vertex_count = 0;
        return;
    }
    m->surface.rest_volume = v;
    /* A uniform dilation e of the whole body costs 100 times more through
     * this term than through the tets' own volume terms: kappa_g V0^2 (3e)^2
     * = 100 kappa V0 (3e)^2. */
    m->surface.stiffness = 100.0 * m->bulk / v;
}
