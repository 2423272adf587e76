/* SPDX-License-Identifier: Apache-2.0 */
/* Stiffness products of the soft-soft couplings (fem_links.h). */
#include "fem_links.h"

static inline void at(const float *a, const float *b, float s, uint32_t v, float y[3])
{
    const float *p = a + 3 * (size_t)v;
    if (b) {
        const float *q = b + 3 * (size_t)v;
        y[0] = p[0] + s * q[0];
        y[1] = p[1] + s * q[1];
        y[2] = p[2] + s * q[2];
    } else {
        y[0] = p[0];
        y[1] = p[1];
        y[2] = p[2];
    }
}

void pose__fem_links_product(const pose__fem_links *l, const float *a, const float *b, float s,
                             float *out)
{
    for (size_t i = 0; i < l->touched_count; i++) {
        float *o = out + 3 * (size_t)l->touched[i];
        o[0] = o[1] = o[2] = 0.0f;
    }
    for (size_t i = 0; i < l->count; i++) {
        const uint32_t *c = l->corner + 4 * i;
        const float *w = l->weight + 4 * i;
        float d[3], y[3];
        at(a, b, s, l->node[i], d);
        for (int k = 0; k < 4; k++) {
            if (w[k] == 0.0f)
                continue;
            at(a, b, s, c[k], y);
            for (int e = 0; e < 3; e++)
                d[e] -= w[k] * y[e];
        }
        const float kk = l->k[i];
        float *o = out + 3 * (size_t)l->node[i];
        for (int e = 0; e < 3; e++)
            o[e] += kk * d[e];
        for (int k = 0; k < 4; k++) {
            if (w[k] == 0.0f)
                continue;
            o = out + 3 * (size_t)c[k];
            for (int e = 0; e < 3; e++)
                o[e] -= kk * w[k] * d[e];
        }
    }
}
