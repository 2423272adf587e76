/* SPDX-License-Identifier: Apache-2.0 */
/* The owning pose_synth_rig: growable arrays, description assembly, CoR
 * and metadata. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "synth_internal.h"

static bool grow(void **p, size_t elem, size_t need, size_t *cap)
{
    if (need <= *cap)
        return true;
    size_t n = *cap ? *cap : 64;
    while (n < need)
        n *= 2;
    void *q = realloc(*p, n * elem);
    if (!q)
        return false;
    *p = q;
    *cap = n;
    return true;
}

pose_synth_rig *ps_rig_new(unsigned influences)
{
    pose_synth_rig *r = calloc(1, sizeof *r);
    if (r)
        r->influences = influences;
    return r;
}

static bool resize(void **p, size_t bytes)
{
    void *q = realloc(*p, bytes ? bytes : 1);
    if (!q)
        return false;
    *p = q;
    return true;
}

/* All per-vertex arrays share vertex_cap; per-tet arrays share tet_cap. */
bool ps_reserve(pose_synth_rig *r, size_t vertices, size_t tets)
{
    if (vertices > r->vertex_cap) {
        size_t n = vertices > 2 * r->vertex_cap ? vertices : 2 * r->vertex_cap;
        if (!resize((void **)&r->tet_positions, n * 3 * sizeof(float)) ||
            !resize((void **)&r->weight_joints, n * r->influences * sizeof(uint16_t)) ||
            !resize((void **)&r->weights, n * r->influences * sizeof(float)))
            return false;
        r->vertex_cap = n;
    }
    if (tets > r->tet_cap) {
        size_t n = tets > 2 * r->tet_cap ? tets : 2 * r->tet_cap;
        if (!resize((void **)&r->tets, n * 4 * sizeof(uint32_t)) ||
            !resize((void **)&r->labels, n * sizeof(uint16_t)))
            return false;
        r->tet_cap = n;
    }
    return true;
}

void pose_synth_free(pose_synth_rig *r)
{
    if (!r)
        return;
    for (size_t t = 0; t < r->tissue_count; t++) {
        free(r->tissues[t].positions);
        free(r->tissues[t].triangles);
        free(r->tissues[t].tet);
        free(r->tissues[t].bary);
    }
    free(r->tissues);
    free(r->tissue_descs);
    free(r->joints);
    free(r->joint_names);
    free(r->tet_positions);
    free(r->weight_joints);
    free(r->weights);
    free(r->tets);
    free(r->labels);
    free(r->cor);
    free(r->metadata);
    free(r);
}

const pose_rig_desc *pose_synth_desc(const pose_synth_rig *r)
{
    return r ? &r->desc : NULL;
}

pose_synth_cor_mode pose_synth_cor(const pose_synth_rig *r)
{
    return r ? r->cor_mode : POSE_SYNTH_COR_NONE;
}

void ps_progress(const pose_synth_rig *r, const char *stage, double fraction)
{
    if (r && r->progress)
        r->progress(stage, fraction, r->progress_user);
}

void ps_quat_rotate(const float q[4], const float v[3], float out[3])
{
    float tx = 2.0f * (q[1] * v[2] - q[2] * v[1]);
    float ty = 2.0f * (q[2] * v[0] - q[0] * v[2]);
    float tz = 2.0f * (q[0] * v[1] - q[1] * v[0]);
    out[0] = v[0] + q[3] * tx + (q[1] * tz - q[2] * ty);
    out[1] = v[1] + q[3] * ty + (q[2] * tx - q[0] * tz);
    out[2] = v[2] + q[3] * tz + (q[0] * ty - q[1] * tx);
}

void ps_quat_from_to(const float a[3], const float b[3], float q[4])
{
    double d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
    if (d < -0.999999) { /* opposite: half turn about any axis normal to a */
        double ax[3] = {0.0, -a[2], a[1]};
        if (fabs(a[0]) < 0.9 && hypot(ax[1], ax[2]) < 1e-6) {
            ax[0] = a[2]; ax[1] = 0.0; ax[2] = -a[0];
        } else if (hypot(ax[1], ax[2]) < 1e-6) {
            ax[0] = -a[1]; ax[1] = a[0]; ax[2] = 0.0;
        }
        double n = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
        q[0] = (float)(ax[0] / n); q[1] = (float)(ax[1] / n); q[2] = (float)(ax[2] / n); q[3] = 0.0f;
        return;
    }
    double c[3] = {(double)a[1] * b[2] - (double)a[2] * b[1], (double)a[2] * b[0] - (double)a[0] * b[2],
                   (double)a[0] * b[1] - (double)a[1] * b[0]};
    double w = 1.0 + d;
    double n = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + w * w);
    q[0] = (float)(c[0] / n); q[1] = (float)(c[1] / n); q[2] = (float)(c[2] / n);
    q[3] = (float)(w / n);
}

static const char *cor_label(pose_synth_cor_mode m)
{
    switch (m) {
    case POSE_SYNTH_COR_EXACT: return "exact (Le & Hodgins 2016 over tets, full sum)";
    case POSE_SYNTH_COR_CLUSTERED:
        return "APPROXIMATE (Le & Hodgins 2016 over tets; tets clustered by mean weights "
               "quantized to 1/64)";
    default: return "none";
    }
}

pose_status ps_finish(pose_synth_rig *r, pose_synth_cor_mode mode, float sigma,
                      const char *generator)
{
    for (size_t j = 0; j < r->joint_count; j++)
        r->joints[j].name = r->joint_names[j];
    r->tissue_descs = calloc(r->tissue_count ? r->tissue_count : 1, sizeof *r->tissue_descs);
    if (!r->tissue_descs)
        return POSE_ERR_OUT_OF_MEMORY;
    for (size_t t = 0; t < r->tissue_count; t++) {
        const ps_tissue *s = &r->tissues[t];
        r->tissue_descs[t] = (pose_tissue_desc){s->name, s->kind, s->joint, s->vertex_count,
                                                s->positions, s->triangle_count, s->triangles,
                                                s->tet, s->bary};
    }
    pose_rig_desc *d = &r->desc;
    *d = (pose_rig_desc){
        .joint_count = r->joint_count, .joints = r->joints,
        .tet_vertex_count = r->vertex_count, .tet_positions = r->tet_positions,
        .tet_count = r->tet_count, .tets = r->tets, .tet_labels = r->labels,
        .influences = r->influences, .weight_joints = r->weight_joints, .weights = r->weights,
        .tissue_count = r->tissue_count, .tissues = r->tissue_descs,
    };
    r->cor_mode = mode;
    if (mode != POSE_SYNTH_COR_NONE) {
        r->cor = malloc(r->vertex_count * 3 * sizeof(float));
        if (!r->cor)
            return POSE_ERR_OUT_OF_MEMORY;
        pose_status st = ps_compute_cor(d, sigma, mode, r->cor, r);
        if (st != POSE_OK)
            return st;
        d->cor = r->cor;
    }
    const char *fmt = "generator: pose-synth %s\n"
                      "weights: synthetic smooth falloff from bone distance (not harmonic), "
                      "K=%u largest kept and renormalized\n"
                      "cor: %s, sigma=%g\n";
    int n = snprintf(NULL, 0, fmt, generator, r->influences, cor_label(mode), (double)sigma);
    r->metadata = malloc((size_t)n + 1);
    if (!r->metadata)
        return POSE_ERR_OUT_OF_MEMORY;
    snprintf(r->metadata, (size_t)n + 1, fmt, generator, r->influences, cor_label(mode),
             (double)sigma);
    d->metadata = r->metadata;
    return POSE_OK;
}

bool ps_grow_joints(pose_synth_rig *r, size_t n)
{
    if (n <= r->joint_cap)
        return true;
    size_t cap = n > 2 * r->joint_cap ? n : 2 * r->joint_cap;
    if (!resize((void **)&r->joints, cap * sizeof *r->joints) ||
        !resize((void **)&r->joint_names, cap * sizeof *r->joint_names))
        return false;
    r->joint_cap = cap;
    return true;
}

bool ps_grow_tissues(pose_synth_rig *r, size_t n)
{
    return grow((void **)&r->tissues, sizeof *r->tissues, n, &r->tissue_cap);
}
