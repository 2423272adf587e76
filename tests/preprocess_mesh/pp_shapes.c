/* SPDX-License-Identifier: Apache-2.0 */
#include "pp_shapes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void alloc_mesh(pp_mesh *m, size_t nv, size_t nt)
{
    memset(m, 0, sizeof *m);
    m->vertex_count = nv;
    m->triangle_count = nt;
    m->positions = calloc(3 * nv, sizeof *m->positions);
    m->triangles = calloc(3 * nt, sizeof *m->triangles);
    if (!m->positions || !m->triangles)
        abort();
}

void shape_box(pp_mesh *m, const float lo[3], const float hi[3])
{
    static const uint32_t tri[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                        {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                        {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    alloc_mesh(m, 8, 12);
    snprintf(m->name, sizeof m->name, "box");
    for (int i = 0; i < 8; i++) {
        m->positions[3 * i] = (i & 1) ? hi[0] : lo[0];
        m->positions[3 * i + 1] = (i & 2) ? hi[1] : lo[1];
        m->positions[3 * i + 2] = (i & 4) ? hi[2] : lo[2];
    }
    memcpy(m->triangles, tri, sizeof tri);
}

static uint32_t midpoint(float *pos, size_t *nv, uint32_t *cache, size_t cap, uint32_t a, uint32_t b)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    for (size_t i = 0; i < cap; i += 3)
        if (cache[i] == lo + 1 && cache[i + 1] == hi)
            return cache[i + 2];
    uint32_t v = (uint32_t)(*nv)++;
    for (int k = 0; k < 3; k++)
        pos[3 * v + k] = 0.5f * (pos[3 * a + k] + pos[3 * b + k]);
    for (size_t i = 0; i < cap; i += 3)
        if (cache[i] == 0) {
            cache[i] = lo + 1;
            cache[i + 1] = hi;
            cache[i + 2] = v;
            break;
        }
    return v;
}

void shape_sphere(pp_mesh *m, const float c[3], float r, int level)
{
    const float t = 1.6180339887f;
    static const uint32_t f0[20][3] = {
        {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    float v0[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                       {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    size_t nt = 20, nv = 12;
    for (int l = 0; l < level; l++)
        nt *= 4;
    size_t vcap = 12 + nt * 3 / 2 + 16;
    float *pos = calloc(3 * vcap, sizeof *pos);
    uint32_t *tri = malloc(3 * 20 * sizeof *tri);
    memcpy(pos, v0, sizeof v0);
    memcpy(tri, f0, sizeof f0);
    size_t cur = 20;
    for (int l = 0; l < level; l++) {
        uint32_t *nt2 = malloc(3 * 4 * cur * sizeof *nt2);
        size_t cap = 3 * 3 * cur;
        uint32_t *cache = calloc(cap, sizeof *cache);
        for (size_t i = 0; i < cur; i++) {
            uint32_t a = tri[3 * i], b = tri[3 * i + 1], cc = tri[3 * i + 2];
            uint32_t ab = midpoint(pos, &nv, cache, cap, a, b);
            uint32_t bc = midpoint(pos, &nv, cache, cap, b, cc);
            uint32_t ca = midpoint(pos, &nv, cache, cap, cc, a);
            uint32_t q[4][3] = {{a, ab, ca}, {b, bc, ab}, {cc, ca, bc}, {ab, bc, ca}};
            memcpy(nt2 + 12 * i, q, sizeof q);
        }
        free(cache);
        free(tri);
        tri = nt2;
        cur *= 4;
    }
    alloc_mesh(m, nv, cur);
    snprintf(m->name, sizeof m->name, "sphere");
    for (size_t i = 0; i < nv; i++) {
        float *p = pos + 3 * i;
        float l = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (int k = 0; k < 3; k++)
            m->positions[3 * i + k] = c[k] + r * p[k] / l;
    }
    memcpy(m->triangles, tri, 3 * cur * sizeof *tri);
    free(pos);
    free(tri);
}

void shape_cylinder(pp_mesh *m, float cx, float cy, float r, float z0, float z1, int seg)
{
    /* vertices: 2 centres, then seg bottom, seg top */
    alloc_mesh(m, 2 + 2 * (size_t)seg, 4 * (size_t)seg);
    snprintf(m->name, sizeof m->name, "cylinder");
    float *p = m->positions;
    p[0] = cx, p[1] = cy, p[2] = z0;
    p[3] = cx, p[4] = cy, p[5] = z1;
    for (int i = 0; i < seg; i++) {
        float a = 6.28318530718f * (float)i / (float)seg;
        float x = cx + r * cosf(a), y = cy + r * sinf(a);
        float *b = p + 3 * (2 + i), *t = p + 3 * (2 + seg + i);
        b[0] = t[0] = x;
        b[1] = t[1] = y;
        b[2] = z0;
        t[2] = z1;
    }
    uint32_t *tr = m->triangles;
    for (uint32_t i = 0; i < (uint32_t)seg; i++) {
        uint32_t j = (i + 1) % (uint32_t)seg;
        uint32_t b0 = 2 + i, b1 = 2 + j, t0 = 2 + (uint32_t)seg + i, t1 = 2 + (uint32_t)seg + j;
        uint32_t q[4][3] = {{0, b1, b0}, {1, t0, t1}, {b0, b1, t1}, {b0, t1, t0}};
        memcpy(tr + 12 * i, q, sizeof q);
    }
}

void shape_drop_triangles(pp_mesh *m, size_t n)
{
    if (n > m->triangle_count)
        n = m->triangle_count;
    memmove(m->triangles, m->triangles + 3 * n, 3 * (m->triangle_count - n) * sizeof *m->triangles);
    m->triangle_count -= n;
}

void shape_rotate_z(pp_mesh *m, float rad)
{
    float c = cosf(rad), s = sinf(rad);
    for (size_t i = 0; i < m->vertex_count; i++) {
        float *p = m->positions + 3 * i;
        float x = c * p[0] - s * p[1], y = s * p[0] + c * p[1];
        p[0] = x;
        p[1] = y;
    }
}

int shape_write_obj(const pp_mesh *m, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    for (size_t i = 0; i < m->vertex_count; i++)
        fprintf(f, "v %.9g %.9g %.9g\n", (double)m->positions[3 * i], (double)m->positions[3 * i + 1],
                (double)m->positions[3 * i + 2]);
    for (size_t t = 0; t < m->triangle_count; t++)
        fprintf(f, "f %u %u %u\n", m->triangles[3 * t] + 1, m->triangles[3 * t + 1] + 1,
                m->triangles[3 * t + 2] + 1);
    return fclose(f);
}

const char *shape_tmp(const char *name, char *buf, size_t cap)
{
    const char *d = getenv("POSE_TEST_TMP");
    snprintf(buf, cap, "%s/%s", d ? d : "/tmp", name);
    return buf;
}

const char *shape_data(const char *rel, char *buf, size_t cap)
{
    const char *d = getenv("POSE_DATA_DIR");
    snprintf(buf, cap, "%s/%s", d ? d : "data", rel);
    return buf;
}
