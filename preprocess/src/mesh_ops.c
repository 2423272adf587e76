/* SPDX-License-Identifier: Apache-2.0
 *
 * Small operations on pp_mesh: validation, merging, topology counts, bounds,
 * enclosed volume, vertex normals.
 */
#include "mesh_io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

pose_status pp_mesh_validate(const pp_mesh *m, const char *what, char *err, size_t errlen)
{
    const char *name = what ? what : (m && m->name[0] ? m->name : "mesh");
    if (!m) {
        if (err && errlen)
            snprintf(err, errlen, "%s: no mesh", name);
        return POSE_ERR_INVALID_ARGUMENT;
    }
    if (m->triangle_count == 0 || m->vertex_count == 0 || !m->positions || !m->triangles) {
        if (err && errlen)
            snprintf(err, errlen, "%s: empty mesh (no triangles)", name);
        return POSE_ERR_INVALID_ARGUMENT;
    }
    for (size_t i = 0; i < 3 * m->vertex_count; i++) {
        if (!isfinite(m->positions[i])) {
            if (err && errlen)
                snprintf(err, errlen, "%s: vertex %zu has a non-finite coordinate", name, i / 3);
            return POSE_ERR_INVALID_ARGUMENT;
        }
    }
    for (size_t i = 0; i < 3 * m->triangle_count; i++) {
        if (m->triangles[i] >= m->vertex_count) {
            if (err && errlen)
                snprintf(err, errlen, "%s: triangle %zu uses vertex %u of %zu", name, i / 3,
                         m->triangles[i], m->vertex_count);
            return POSE_ERR_INVALID_ARGUMENT;
        }
    }
    return POSE_OK;
}

pose_status pp_mesh_append(pp_mesh *dst, const pp_mesh *src)
{
    if (!dst || !src)
        return POSE_ERR_INVALID_ARGUMENT;
    size_t nv = dst->vertex_count + src->vertex_count;
    size_t nt = dst->triangle_count + src->triangle_count;
    if (nv > UINT32_MAX)
        return POSE_ERR_INVALID_ARGUMENT;
    float *p = realloc(dst->positions, (nv ? nv : 1) * 3 * sizeof *p);
    if (!p)
        return POSE_ERR_OUT_OF_MEMORY;
    dst->positions = p;
    uint32_t *t = realloc(dst->triangles, (nt ? nt : 1) * 3 * sizeof *t);
    if (!t)
        return POSE_ERR_OUT_OF_MEMORY;
    dst->triangles = t;
    if (src->vertex_count)
        memcpy(p + 3 * dst->vertex_count, src->positions, 3 * src->vertex_count * sizeof *p);
    for (size_t i = 0; i < 3 * src->triangle_count; i++)
        t[3 * dst->triangle_count + i] = src->triangles[i] + (uint32_t)dst->vertex_count;
    dst->vertex_count = nv;
    dst->triangle_count = nt;
    if (!dst->name[0])
        memcpy(dst->name, src->name, sizeof dst->name);
    return POSE_OK;
}

pose_status pp_mesh_copy(pp_mesh *dst, const pp_mesh *src)
{
    if (!dst || !src)
        return POSE_ERR_INVALID_ARGUMENT;
    memset(dst, 0, sizeof *dst);
    pose_status s = pp_mesh_append(dst, src);
    if (s != POSE_OK)
        pp_mesh_free(dst);
    return s;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

pose_status pp_mesh_topology_count(const pp_mesh *m, pp_mesh_topology *out)
{
    if (!m || !out)
        return POSE_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    size_t ne = 3 * m->triangle_count;
    if (ne == 0)
        return POSE_OK;
    /* key = lo << 33 | hi << 1 | (traversed lo -> hi) */
    uint64_t *e = malloc(ne * sizeof *e);
    if (!e)
        return POSE_ERR_OUT_OF_MEMORY;
    for (size_t t = 0; t < m->triangle_count; t++) {
        for (int k = 0; k < 3; k++) {
            uint64_t a = m->triangles[3 * t + k], b = m->triangles[3 * t + (k + 1) % 3];
            uint64_t fwd = a < b;
            uint64_t lo = a < b ? a : b, hi = a < b ? b : a;
            e[3 * t + k] = lo << 33 | hi << 1 | fwd;
        }
    }
    qsort(e, ne, sizeof *e, cmp_u64);
    for (size_t i = 0; i < ne;) {
        size_t j = i, fwd = 0;
        while (j < ne && (e[j] >> 1) == (e[i] >> 1))
            fwd += e[j++] & 1;
        size_t use = j - i;
        if (use == 1)
            out->boundary_edges++;
        else if (use > 2)
            out->nonmanifold_edges++;
        else if (fwd != 1)
            out->inconsistent_edges++;
        i = j;
    }
    free(e);
    return POSE_OK;
}

void pp_mesh_bounds(const pp_mesh *m, float lo[3], float hi[3])
{
    for (int k = 0; k < 3; k++)
        lo[k] = hi[k] = 0.0f;
    if (!m || m->vertex_count == 0)
        return;
    for (int k = 0; k < 3; k++)
        lo[k] = hi[k] = m->positions[k];
    for (size_t i = 1; i < m->vertex_count; i++) {
        for (int k = 0; k < 3; k++) {
            float v = m->positions[3 * i + k];
            lo[k] = v < lo[k] ? v : lo[k];
            hi[k] = v > hi[k] ? v : hi[k];
        }
    }
}

double pp_mesh_volume(const pp_mesh *m)
{
    double v = 0.0;
    if (!m || m->vertex_count == 0)
        return 0.0;
    /* Relative to the first vertex to keep the products small. */
    const float *o = m->positions;
    for (size_t t = 0; t < m->triangle_count; t++) {
        double p[3][3];
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++)
                p[c][k] = (double)m->positions[3 * (size_t)m->triangles[3 * t + c] + k] - o[k];
        v += p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) -
             p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
             p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0]);
    }
    return v / 6.0;
}

void pp_mesh_vertex_normals(const pp_mesh *m, float *normals)
{
    memset(normals, 0, 3 * m->vertex_count * sizeof *normals);
    for (size_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *tri = m->triangles + 3 * t;
        const float *a = m->positions + 3 * (size_t)tri[0], *b = m->positions + 3 * (size_t)tri[1],
                    *c = m->positions + 3 * (size_t)tri[2];
        float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        float v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        float n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                      u[0] * v[1] - u[1] * v[0]}; /* length = 2 * area: area weighting */
        for (int c2 = 0; c2 < 3; c2++)
            for (int k = 0; k < 3; k++)
                normals[3 * (size_t)tri[c2] + k] += n[k];
    }
    for (size_t i = 0; i < m->vertex_count; i++) {
        float *n = normals + 3 * i;
        float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (l > 0.0f) {
            n[0] /= l;
            n[1] /= l;
            n[2] /= l;
        }
    }
}
