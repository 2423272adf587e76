/* SPDX-License-Identifier: Apache-2.0
 *
 * Exact-position weld with an open-addressing hash of the float bits.
 */
#include "mesh_weld.h"

#include <stdlib.h>
#include <string.h>

static uint32_t fbits(float f)
{
    if (f == 0.0f)
        f = 0.0f; /* fold -0 onto +0 */
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static uint64_t hash3(const float *p)
{
    uint64_t h = 1469598103934665603ull;
    for (int k = 0; k < 3; k++) {
        h ^= fbits(p[k]);
        h *= 1099511628211ull;
        h ^= h >> 29;
    }
    return h;
}

static int same3(const float *a, const float *b)
{
    return fbits(a[0]) == fbits(b[0]) && fbits(a[1]) == fbits(b[1]) && fbits(a[2]) == fbits(b[2]);
}

static int zero_area(const float *a, const float *b, const float *c)
{
    double u[3], v[3];
    for (int k = 0; k < 3; k++) {
        u[k] = (double)b[k] - a[k];
        v[k] = (double)c[k] - a[k];
    }
    double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2],
           z = u[0] * v[1] - u[1] * v[0];
    return x == 0.0 && y == 0.0 && z == 0.0;
}

pose_status pp_mesh_weld(pp_mesh *m)
{
    size_t n = m->vertex_count;
    size_t cap = 16;
    while (cap < 2 * n)
        cap *= 2;
    uint32_t *table = malloc(cap * sizeof *table);
    uint32_t *remap = malloc((n ? n : 1) * sizeof *remap);
    if (!table || !remap) {
        free(table);
        free(remap);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    memset(table, 0xff, cap * sizeof *table);
    size_t kept = 0;
    for (size_t i = 0; i < n; i++) {
        const float *p = m->positions + 3 * i;
        size_t slot = (size_t)hash3(p) & (cap - 1);
        for (;;) {
            uint32_t e = table[slot];
            if (e == UINT32_MAX) {
                table[slot] = (uint32_t)kept;
                memmove(m->positions + 3 * kept, p, 3 * sizeof *p);
                remap[i] = (uint32_t)kept++;
                break;
            }
            if (same3(m->positions + 3 * (size_t)e, p)) {
                remap[i] = e;
                break;
            }
            slot = (slot + 1) & (cap - 1);
        }
    }
    free(table);

    size_t nt = 0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        uint32_t a = remap[m->triangles[3 * t]], b = remap[m->triangles[3 * t + 1]],
                 c = remap[m->triangles[3 * t + 2]];
        if (a == b || b == c || a == c)
            continue;
        if (zero_area(m->positions + 3 * (size_t)a, m->positions + 3 * (size_t)b,
                      m->positions + 3 * (size_t)c))
            continue;
        m->triangles[3 * nt] = a;
        m->triangles[3 * nt + 1] = b;
        m->triangles[3 * nt + 2] = c;
        nt++;
    }
    m->triangle_count = nt;

    /* Drop vertices that no surviving triangle uses. */
    memset(remap, 0xff, (n ? n : 1) * sizeof *remap);
    size_t nv = 0;
    for (size_t i = 0; i < 3 * nt; i++) {
        uint32_t v = m->triangles[i];
        if (remap[v] == UINT32_MAX)
            remap[v] = (uint32_t)nv++;
        m->triangles[i] = remap[v];
    }
    float *pos = malloc((nv ? nv : 1) * 3 * sizeof *pos);
    if (!pos) {
        free(remap);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < kept; i++)
        if (remap[i] != UINT32_MAX)
            memcpy(pos + 3 * (size_t)remap[i], m->positions + 3 * i, 3 * sizeof *pos);
    free(remap);
    free(m->positions);
    m->positions = pos;
    m->vertex_count = nv;
    return POSE_OK;
}
