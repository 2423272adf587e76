/* SPDX-License-Identifier: Apache-2.0 */
/* Runtime-derived rig data (see rig_runtime.h), built once per rig. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "rig_internal.h"
#include "rig_outside.h"
#include "rig_runtime.h"

static size_t align64(size_t n)
{
    return (n + 63u) & ~(size_t)63u;
}

/* Quantize one vertex's K weights to 15-bit fixed point summing to exactly
 * POSE__WEIGHT_ONE, largest first (DQS/CoR align signs to the first joint). */
static void compact_weights(unsigned K, const uint16_t *joints, const float *weights,
                            uint16_t *out_joints, uint16_t *out_weights)
{
    unsigned order[POSE__MAX_INFLUENCES];
    for (unsigned k = 0; k < K; k++)
        order[k] = k;
    for (unsigned a = 1; a < K; a++) { /* insertion sort, stable, K <= 8 */
        unsigned v = order[a], b = a;
        while (b > 0 && weights[order[b - 1]] < weights[v]) {
            order[b] = order[b - 1];
            b--;
        }
        order[b] = v;
    }
    double sum = 0.0;
    for (unsigned k = 0; k < K; k++)
        sum += weights[k];
    long total = 0;
    for (unsigned k = 0; k < K; k++) {
        unsigned src = order[k];
        long q = lround((double)weights[src] / sum * POSE__WEIGHT_ONE);
        out_joints[k] = joints[src];
        out_weights[k] = (uint16_t)q;
        total += q;
    }
    /* Rounding leaves at most K/2 units over or under: give them to the
     * largest weight, which is at least POSE__WEIGHT_ONE / K. */
    out_weights[0] = (uint16_t)((long)out_weights[0] + ((long)POSE__WEIGHT_ONE - total));
}

/* Area-weighted unit vertex normals of one tissue from its rest triangles. */
static void rest_normals(const pose__tissue *t, float *out)
{
    memset(out, 0, 3 * t->vertex_count * sizeof(float));
    const float *p = t->positions;
    for (size_t f = 0; f < t->triangle_count; f++) {
        const uint32_t *tri = t->triangles + 3 * f;
        const float *a = p + 3 * (size_t)tri[0], *b = p + 3 * (size_t)tri[1],
                    *c = p + 3 * (size_t)tri[2];
        float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        float v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        float n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                      u[0] * v[1] - u[1] * v[0]};
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++)
                out[3 * (size_t)tri[k] + d] += n[d];
    }
    for (size_t i = 0; i < t->vertex_count; i++) {
        float *n = out + 3 * i;
        double l = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        float s = l > 0.0 ? (float)(1.0 / l) : 0.0f;
        n[0] *= s; n[1] *= s; n[2] *= s;
    }
}

/* One tissue vertex: tet vertices with the largest coordinate first, the
 * other three ordered so that det D > 0 (D = [v1-v0 v2-v0 v3-v0] at rest:
 * an inverted tet then shows as det D' <= 0), b1..b3, and the normal key
 * D^T n (see rt_transfer.h). */
static void embed_vertex(const pose_rig *rig, const uint32_t *tet, const float *b4,
                         const float *normal, uint32_t *tv, float *b3, int16_t *key)
{
    unsigned first = 0;
    for (unsigned k = 1; k < 4; k++)
        if (b4[k] > b4[first])
            first = k;
    unsigned perm[4] = {first, 0, 0, 0};
    for (unsigned k = 0, n = 1; k < 4; k++)
        if (k != first)
            perm[n++] = k;

    double e[3][3];
    const float *v0 = rig->tet_positions + 3 * (size_t)tet[perm[0]];
    for (int k = 0; k < 3; k++) {
        const float *vk = rig->tet_positions + 3 * (size_t)tet[perm[k + 1]];
        for (int d = 0; d < 3; d++)
            e[k][d] = (double)vk[d] - v0[d];
    }
    double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                 e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                 e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    if (det < 0.0) { /* swapping two edges flips the sign */
        unsigned t = perm[2]; perm[2] = perm[3]; perm[3] = t;
        for (int d = 0; d < 3; d++) {
            double x = e[1][d]; e[1][d] = e[2][d]; e[2][d] = x;
        }
    }
    for (unsigned k = 0; k < 4; k++)
        tv[k] = tet[perm[k]];
    double m[3];
    for (unsigned k = 0; k < 3; k++) {
        b3[k] = b4[perm[k + 1]];
        m[k] = e[k][0] * normal[0] + e[k][1] * normal[1] + e[k][2] * normal[2];
    }
    double big = fmax(fabs(m[0]), fmax(fabs(m[1]), fabs(m[2])));
    for (int k = 0; k < 3; k++)
        key[k] = (big > 0.0 && det != 0.0) ? (int16_t)lround(m[k] / big * 32767.0) : 0;
}

/* For every tissue vertex v (all tissues, one numbering), the other two
 * corners (a, b) of each triangle around it, in winding order: the
 * area-weighted normal is sum (a - v) x (b - v). */
static void build_fans(const pose_rig *rig, const size_t *tissue_offset, uint32_t *fan_offset,
                       uint32_t *fan)
{
    for (size_t t = 0; t < rig->tissue_count; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        for (size_t f = 0; f < 3 * ts->triangle_count; f++)
            fan_offset[tissue_offset[t] + ts->triangles[f] + 1]++;
    }
    size_t total = tissue_offset[rig->tissue_count];
    for (size_t v = 0; v < total; v++)
        fan_offset[v + 1] += fan_offset[v];
    /* fill, using fan_offset[v] as a cursor, then shift back */
    for (size_t t = 0; t < rig->tissue_count; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        const uint32_t base = (uint32_t)tissue_offset[t];
        for (size_t f = 0; f < ts->triangle_count; f++) {
            const uint32_t *tri = ts->triangles + 3 * f;
            for (int k = 0; k < 3; k++) {
                uint32_t v = base + tri[k];
                uint32_t at = fan_offset[v]++;
                fan[2 * (size_t)at] = base + tri[(k + 1) % 3];
                fan[2 * (size_t)at + 1] = base + tri[(k + 2) % 3];
            }
        }
    }
    for (size_t v = total; v > 0; v--)
        fan_offset[v] = fan_offset[v - 1];
    fan_offset[0] = 0;
}

/* The simulation mesh of POSE_FEM is the rig's own tet mesh: bone tets are
 * rigid (their vertices held), soft tets take the fem section's material.
 * Its vertices are the skinned ones, so nothing needs embedding. At load
 * only its size is counted (and checked); pose__rig_fem_mesh builds it. */
static pose_status prepare_fem(pose_rig *rig)
{
    if (!rig->fem)
        return POSE_OK;
    rig->rt->fem_size = pose__fem_mesh_size(rig->tet_vertex_count, rig->tet_count, rig->tets, rig->tet_labels);
    if (rig->rt->fem_size == 0)
        return pose__fail(POSE_ERR_UNSUPPORTED, "fem: tet mesh too large for 32-bit corner indices");
    if (pose__mutex_init(&rig->rt->fem_lock) != 0)
        return pose__fail(POSE_ERR_THREAD, "fem: could not create the simulation mesh's lock");
    rig->rt->fem_lock_ready = 1;
    return POSE_OK;
}

pose_status pose__rig_fem_mesh(const pose_rig *rig, const char *fn)
{
    struct pose__rig_runtime *rt = rig->rt;
    if (!rig->fem || !rt->fem_size)
        return pose__fail(POSE_ERR_UNSUPPORTED, "%s: the rig has no fem section", fn);
    pose_status s = POSE_OK;
    pose__mutex_lock(&rt->fem_lock);
    if (!rt->fem_block) {
        void *block = pose__alloc(&rig->allocator, rt->fem_size, POSE__ALIGN);
        if (!block) {
            s = pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: out of memory for the simulation mesh (%zu bytes)", fn,
                           rt->fem_size);
        } else {
            const pose__fem_material m = {rig->fem->young, rig->fem->poisson, rig->fem->density};
            pose__fem_mesh_build(rig->tet_vertex_count, rig->tet_positions, rig->tet_count, rig->tets,
                                 rig->tet_labels, &m, block, &rt->fem);
            /* The body's volume is held through its closed skin (fem_mesh.h). */
            for (size_t t = 0; t < rig->tissue_count; t++) {
                const pose__tissue *ts = &rig->tissues[t];
                if (ts->kind != POSE_TISSUE_SKIN || ts->triangle_count == 0)
                    continue;
                pose__fem_surface sf = {
                    .vertex_count = ts->vertex_count, .triangle_count = ts->triangle_count,
                    .tets = rig->tets, .tet = ts->tet, .bary = ts->bary, .triangles = ts->triangles,
                };
                pose__fem_mesh_set_surface(&rt->fem, &sf, rig->tet_positions);
                break;
            }
            rt->fem_block = block; /* last: the mesh is whole once this is set */
        }
    }
    pose__mutex_unlock(&rt->fem_lock);
    return s;
}

pose_status pose__rig_prepare(pose_rig *rig)
{
    rig->rt = NULL;
    const size_t nv = rig->tet_vertex_count, K = rig->influences, nj = rig->joint_count;
    const size_t B = POSE__BLOCK, nb = (nv + B - 1) / B;
    size_t total = 0;
    for (size_t t = 0; t < rig->tissue_count; t++)
        total += rig->tissues[t].vertex_count;
    const size_t tb = (total + B - 1) / B;
    /* The kernels index vertex coordinates with 32-bit offsets (3 * index). */
    if (nv > (size_t)INT32_MAX / 4)
        return pose__fail(POSE_ERR_UNSUPPORTED,
                          "tet mesh of %zu vertices: the runtime handles at most %d", nv,
                          INT32_MAX / 4);

    /* One block of memory: header, skin blocks, tissue blocks, rest frames. */
    size_t off = align64(sizeof(struct pose__rig_runtime));
    const size_t off_rest = off;
    off += align64(nb * 3 * B * sizeof(float));
    const size_t off_cor = off;
    off += rig->cor ? align64(nb * 3 * B * sizeof(float)) : 0;
    const size_t off_active = off;
    off += align64(nb);
    const size_t off_joints = off;
    off += align64(nb * K * B * sizeof(uint16_t));
    const size_t off_weights = off;
    off += align64(nb * K * B * 2);
    const size_t off_offsets = off;
    off += align64((rig->tissue_count + 1) * sizeof(size_t));
    const size_t off_tv = off;
    off += align64(tb * 4 * B * sizeof(uint32_t));
    const size_t off_bary = off;
    off += align64(tb * 3 * B * sizeof(float));
    const size_t off_key = off;
    off += align64(tb * 3 * B * sizeof(int16_t));
    const size_t off_normals = off;
    off += align64(total * 3 * sizeof(float));
    size_t fan_entries = 0;
    for (size_t t = 0; t < rig->tissue_count; t++)
        fan_entries += 3 * rig->tissues[t].triangle_count;
    if (total >= UINT32_MAX || fan_entries >= UINT32_MAX)
        return pose__fail(POSE_ERR_UNSUPPORTED,
                          "tissues with %zu vertices and %zu triangle corners: the runtime "
                          "handles fewer than 2^32", total, fan_entries);
    const size_t off_fan_offset = off;
    off += align64((total + 1) * sizeof(uint32_t));
    const size_t off_fan = off;
    off += align64(2 * fan_entries * sizeof(uint32_t));
    const size_t off_frames = off;
    off += align64(nj * sizeof(pose__xform));
    const size_t size = off;
    unsigned char *block = pose__calloc(&rig->allocator, size, POSE__ALIGN);
    if (!block)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY,
                          "out of memory preparing the rig for the runtime (%zu bytes)", size);
    struct pose__rig_runtime *rt = (struct pose__rig_runtime *)block;
    rt->block = block;

    /* ---- tet vertices: blocks of 8 lanes; padding lanes repeat vertex 0
     * bound to joint 0 (valid input, never stored) */
    float *rest = (float *)(block + off_rest);
    float *cor = rig->cor ? (float *)(block + off_cor) : NULL;
    uint8_t *active = block + off_active;
    uint16_t *j16 = (uint16_t *)(block + off_joints);
    uint16_t *w16 = (uint16_t *)(block + off_weights);
    for (size_t b = 0; b < nb; b++) {
        unsigned used = 1;
        for (size_t l = 0; l < B; l++) {
            size_t i = b * B + l, src = i < nv ? i : 0;
            for (int c = 0; c < 3; c++) {
                rest[(b * 3 + (size_t)c) * B + l] = rig->tet_positions[3 * src + (size_t)c];
                if (cor)
                    cor[(b * 3 + (size_t)c) * B + l] = rig->cor[3 * src + (size_t)c];
            }
            uint16_t joints[POSE__MAX_INFLUENCES], weights[POSE__MAX_INFLUENCES];
            compact_weights((unsigned)K, rig->weight_joints + src * K, rig->weights + src * K,
                            joints, weights);
            for (size_t k = 0; k < K; k++) {
                size_t at = (b * K + k) * B + l;
                j16[at] = joints[k];
                w16[at] = weights[k];
                if (weights[k] != 0 && k + 1 > used)
                    used = (unsigned)k + 1;
            }
        }
        active[b] = (uint8_t)used;
    }
    rt->skin = (pose__skin_mesh){
        .vertex_count = nv, .block_count = nb, .influences = (unsigned)K, .rest = rest,
        .cor = cor, .active = active, .joints = j16, .weights = w16,
    };

    /* ---- tissue vertices, all tissues one after another, same blocking */
    rt->tissue_offset = (size_t *)(block + off_offsets);
    rt->rest_normals = (float *)(block + off_normals);
    uint32_t *tv = (uint32_t *)(block + off_tv);
    float *bary = (float *)(block + off_bary);
    int16_t *key = (int16_t *)(block + off_key);
    size_t base = 0;
    for (size_t t = 0; t < rig->tissue_count; t++) {
        const pose__tissue *ts = &rig->tissues[t];
        rt->tissue_offset[t] = base;
        rest_normals(ts, rt->rest_normals + 3 * base);
        for (size_t v = 0; v < ts->vertex_count; v++) {
            size_t g = base + v, b = g / B, l = g % B;
            uint32_t corners[4];
            float b3[3];
            int16_t k3[3];
            embed_vertex(rig, rig->tets + 4 * (size_t)ts->tet[v], ts->bary + 4 * v,
                         rt->rest_normals + 3 * g, corners, b3, k3);
            for (size_t c = 0; c < 4; c++)
                tv[(b * 4 + c) * B + l] = corners[c];
            for (size_t c = 0; c < 3; c++) {
                bary[(b * 3 + c) * B + l] = b3[c];
                key[(b * 3 + c) * B + l] = k3[c];
            }
        }
        base += ts->vertex_count;
    }
    rt->tissue_offset[rig->tissue_count] = base;
    uint32_t *fan_offset = (uint32_t *)(block + off_fan_offset);
    uint32_t *fan = (uint32_t *)(block + off_fan);
    build_fans(rig, rt->tissue_offset, fan_offset, fan);
    rt->transfer = (pose__transfer_mesh){
        .vertex_count = total, .block_count = tb, .tet_vertices = tv, .bary = bary,
        .normal_key = key, .fan_offset = fan_offset, .fan = fan,
    };

    rt->rest_model = (pose__xform *)(block + off_frames);
    for (size_t j = 0; j < nj; j++) {
        memcpy(rt->rest_model[j].q, rig->joint_rest_model[j].rotation, sizeof(float) * 4);
        memcpy(rt->rest_model[j].t, rig->joint_rest_model[j].translation, sizeof(float) * 3);
    }
    rig->rt = rt;
    pose_status s = prepare_fem(rig);
    return s == POSE_OK ? pose__rig_prepare_outside(rig) : s;
}

void pose__rig_release(pose_rig *rig)
{
    if (rig->rt)
        pose__rig_release_outside(rig);
    if (rig->rt && rig->rt->fem_block)
        pose__free(&rig->allocator, rig->rt->fem_block);
    if (rig->rt && rig->rt->fem_lock_ready)
        pose__mutex_destroy(&rig->rt->fem_lock);
    if (rig->rt)
        pose__free(&rig->allocator, rig->rt->block);
    rig->rt = NULL;
}
