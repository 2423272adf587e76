/* SPDX-License-Identifier: Apache-2.0
 *
 * pp_voxelize: skin and bones -> labelled voxel image, with the repairs
 * described in voxelize.h counted in the report.
 */
#include "mesh_io.h"
#include "voxelize.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void voxel_of(const pp_voxels *v, const float p[3], int idx[3])
{
    for (int k = 0; k < 3; k++)
        idx[k] = (int)floor(((double)p[k] - v->origin[k]) / v->spacing + 0.5);
}

uint16_t pp_voxels_sample(const pp_voxels *v, const float p[3])
{
    int i[3];
    voxel_of(v, p, i);
    if (i[0] < 0 || i[1] < 0 || i[2] < 0 || i[0] >= v->nx || i[1] >= v->ny || i[2] >= v->nz)
        return PP_VOXEL_OUTSIDE;
    return v->labels[(size_t)i[0] + (size_t)v->nx * ((size_t)i[1] + (size_t)v->ny * i[2])];
}

/* Label one bone inside its own bounding sub-grid. */
static pose_status label_bone(const pp_mesh *bone, uint16_t label, pp_voxels *v,
                              const uint8_t *in_skin, pp_voxel_report *r, size_t *inside_skin)
{
    *inside_skin = 0;
    float lo[3], hi[3];
    pp_mesh_bounds(bone, lo, hi);
    int i0[3], i1[3], n[3];
    int dims[3] = {v->nx, v->ny, v->nz};
    for (int k = 0; k < 3; k++) {
        i0[k] = (int)floor((lo[k] - v->origin[k]) / v->spacing) - 1;
        i1[k] = (int)ceil((hi[k] - v->origin[k]) / v->spacing) + 1;
        i0[k] = i0[k] < 0 ? 0 : i0[k];
        i1[k] = i1[k] >= dims[k] ? dims[k] - 1 : i1[k];
        n[k] = i1[k] - i0[k] + 1;
    }
    size_t cnt = (size_t)n[0] * n[1] * n[2];
    uint8_t *in = malloc(cnt);
    if (!in)
        return POSE_ERR_OUT_OF_MEMORY;
    float o[3] = {v->origin[0] + i0[0] * v->spacing, v->origin[1] + i0[1] * v->spacing,
                  v->origin[2] + i0[2] * v->spacing};
    size_t amb = 0;
    pose_status s = pp_voxel_inside(bone, o, v->spacing, n[0], n[1], n[2], in, &amb);
    if (s != POSE_OK) {
        free(in);
        return s;
    }
    r->ambiguous_voxels += amb;
    size_t got = 0;
    for (int z = 0; z < n[2]; z++)
        for (int y = 0; y < n[1]; y++)
            for (int x = 0; x < n[0]; x++) {
                if (!in[(size_t)x + (size_t)n[0] * ((size_t)y + (size_t)n[1] * z)])
                    continue;
                size_t g = (size_t)(x + i0[0]) +
                           (size_t)v->nx * ((size_t)(y + i0[1]) + (size_t)v->ny * (z + i0[2]));
                *inside_skin += in_skin[g];
                uint16_t old = v->labels[g];
                if (old >= PP_VOXEL_BONE0) {
                    if (old != label)
                        r->overlap_voxels++;
                    else
                        got++;
                    continue;
                }
                got++;
                if (!in_skin[g])
                    r->bone_voxels_outside_skin++;
                v->labels[g] = label;
            }
    free(in);
    if (got == 0) {
        /* Thinner than a voxel, or wholly inside earlier bones: keep the bone
         * by the voxels holding its vertices. */
        r->thin_bones++;
        size_t marked = 0;
        for (size_t i = 0; i < bone->vertex_count; i++) {
            int c[3];
            voxel_of(v, bone->positions + 3 * i, c);
            size_t g = (size_t)c[0] + (size_t)v->nx * ((size_t)c[1] + (size_t)v->ny * c[2]);
            *inside_skin += in_skin[g];
            if (v->labels[g] >= PP_VOXEL_BONE0) {
                marked += v->labels[g] == label;
                continue;
            }
            if (!in_skin[g])
                r->bone_voxels_outside_skin++;
            v->labels[g] = label;
            marked++;
        }
        if (marked == 0) {
            /* Every vertex voxel belongs to another bone: take the first
             * vertex's voxel anyway, so that the joint is not left empty. */
            int c[3];
            voxel_of(v, bone->positions, c);
            v->labels[(size_t)c[0] + (size_t)v->nx * ((size_t)c[1] + (size_t)v->ny * c[2])] = label;
            r->overlap_voxels++;
        }
    }
    return POSE_OK;
}

/* At least half of the bone's vertices within the box [lo, hi] grown by one
 * voxel. */
static int mostly_within(const pp_mesh *bone, const float lo[3], const float hi[3], float spacing)
{
    size_t in = 0;
    for (size_t i = 0; i < bone->vertex_count; i++) {
        const float *p = bone->positions + 3 * i;
        int ok = 1;
        for (int k = 0; k < 3; k++)
            ok &= p[k] >= lo[k] - spacing && p[k] <= hi[k] + spacing;
        in += (size_t)ok;
    }
    return 2 * in >= bone->vertex_count;
}

static pose_status fail(pp_voxels *out, char *err, size_t errlen, pose_status s, const char *msg)
{
    pp_voxels_free(out);
    if (err && errlen && msg)
        snprintf(err, errlen, "%s", msg);
    return s;
}

pose_status pp_voxelize(const pp_mesh *skin, const pp_mesh *bones, const uint16_t *bone_label,
                        size_t bone_count, float spacing, pp_voxels *out,
                        pp_voxel_report *report, char *err, size_t errlen)
{
    double t0 = pp_now_s();
    pp_voxel_report local;
    pp_voxel_report *r = report ? report : &local;
    memset(r, 0, sizeof *r);
    if (!out)
        return POSE_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    char msg[256];
    if (!isfinite(spacing) || spacing < PP_VOXEL_MIN_SPACING || spacing > PP_VOXEL_MAX_SPACING) {
        snprintf(msg, sizeof msg, "voxel spacing %g m is outside %g .. %g m", (double)spacing,
                 (double)PP_VOXEL_MIN_SPACING, (double)PP_VOXEL_MAX_SPACING);
        return fail(out, err, errlen, POSE_ERR_INVALID_ARGUMENT, msg);
    }
    pose_status s = pp_mesh_validate(skin, skin && skin->name[0] ? skin->name : "skin", err, errlen);
    if (s != POSE_OK)
        return s;
    if (bone_count && (!bones || !bone_label))
        return fail(out, err, errlen, POSE_ERR_INVALID_ARGUMENT, "bones: NULL bone array");
    for (size_t b = 0; b < bone_count; b++) {
        char what[80];
        snprintf(what, sizeof what, "%s", bones[b].name[0] ? bones[b].name : "bone");
        if (!bones[b].name[0])
            snprintf(what, sizeof what, "bone %zu", b);
        s = pp_mesh_validate(&bones[b], what, err, errlen);
        if (s != POSE_OK)
            return s;
        if (bone_label[b] > UINT16_MAX - PP_VOXEL_BONE0) {
            snprintf(msg, sizeof msg, "%s: joint label %u is too large", what, bone_label[b]);
            return fail(out, err, errlen, POSE_ERR_INVALID_ARGUMENT, msg);
        }
    }

    /* Grid: the union of all bounds, centred, one outside voxel on every side. */
    float lo[3], hi[3];
    pp_mesh_bounds(skin, lo, hi);
    for (size_t b = 0; b < bone_count; b++) {
        float bl[3], bh[3];
        pp_mesh_bounds(&bones[b], bl, bh);
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], bl[k]);
            hi[k] = fmaxf(hi[k], bh[k]);
        }
    }
    int n[3];
    double total = 1.0;
    for (int k = 0; k < 3; k++) {
        double cells = ceil(((double)hi[k] - lo[k]) / spacing) + 3.0;
        total *= cells;
        if (cells > 1e9 || total > (double)PP_VOXEL_MAX_COUNT) {
            snprintf(msg, sizeof msg,
                     "voxel spacing %g m gives more than %zu voxels over a %.3g x %.3g x %.3g m "
                     "body; use a larger spacing",
                     (double)spacing, PP_VOXEL_MAX_COUNT, (double)(hi[0] - lo[0]),
                     (double)(hi[1] - lo[1]), (double)(hi[2] - lo[2]));
            return fail(out, err, errlen, POSE_ERR_INVALID_ARGUMENT, msg);
        }
        n[k] = (int)cells;
        out->origin[k] = (float)(0.5 * ((double)lo[k] + hi[k]) - 0.5 * (n[k] - 1) * (double)spacing);
    }
    out->nx = n[0];
    out->ny = n[1];
    out->nz = n[2];
    out->spacing = spacing;
    size_t count = (size_t)n[0] * n[1] * n[2];
    out->labels = calloc(count, sizeof *out->labels);
    uint8_t *in_skin = malloc(count);
    if (!out->labels || !in_skin) {
        free(in_skin);
        return fail(out, err, errlen, POSE_ERR_OUT_OF_MEMORY, "voxelize: out of memory");
    }
    size_t amb = 0;
    s = pp_voxel_inside(skin, out->origin, spacing, n[0], n[1], n[2], in_skin, &amb);
    if (s != POSE_OK) {
        free(in_skin);
        return fail(out, err, errlen, s, "voxelize: out of memory");
    }
    r->ambiguous_voxels = amb;
    size_t skin_count = 0;
    for (size_t i = 0; i < count; i++) {
        out->labels[i] = in_skin[i] ? PP_VOXEL_SOFT : PP_VOXEL_OUTSIDE;
        skin_count += in_skin[i];
    }
    pp_mesh_topology topo;
    if (pp_mesh_topology_count(skin, &topo) == POSE_OK)
        r->skin_boundary_edges = topo.boundary_edges;

    float skin_lo[3], skin_hi[3];
    pp_mesh_bounds(skin, skin_lo, skin_hi);
    uint16_t max_label = 0;
    for (size_t b = 0; b < bone_count; b++) {
        if (pp_mesh_topology_count(&bones[b], &topo) == POSE_OK &&
            (topo.boundary_edges || topo.nonmanifold_edges))
            r->open_bone_meshes++;
        size_t inside = 0;
        s = label_bone(&bones[b], (uint16_t)(PP_VOXEL_BONE0 + bone_label[b]), out, in_skin, r,
                       &inside);
        if (s != POSE_OK) {
            free(in_skin);
            return fail(out, err, errlen, s, "voxelize: out of memory");
        }
        if (inside == 0 && !mostly_within(&bones[b], skin_lo, skin_hi, spacing)) {
            /* Not a bone poking out, nor one in a part of the skin thinner
             * than a voxel (a finger at 16 mm holds no voxel centre, but its
             * bones lie within the skin's box): a bone in another frame or
             * unit. */
            free(in_skin);
            snprintf(msg, sizeof msg,
                     "%s: the bone lies entirely outside the skin (check its units and frame)",
                     bones[b].name[0] ? bones[b].name : "bone");
            return fail(out, err, errlen, POSE_ERR_INVALID_DATA, msg);
        }
        if (bone_label[b] + 1 > max_label)
            max_label = (uint16_t)(bone_label[b] + 1);
    }
    free(in_skin);

    uint8_t *seen = calloc((size_t)max_label + 1, 1);
    if (!seen)
        return fail(out, err, errlen, POSE_ERR_OUT_OF_MEMORY, "voxelize: out of memory");
    for (size_t i = 0; i < count; i++) {
        uint16_t l = out->labels[i];
        if (l == PP_VOXEL_OUTSIDE)
            continue;
        r->body_voxels++;
        if (l == PP_VOXEL_SOFT) {
            r->soft_voxels++;
        } else {
            r->bone_voxels++;
            if (l - PP_VOXEL_BONE0 < max_label)
                seen[l - PP_VOXEL_BONE0] = 1;
        }
    }
    /* Only joints some bone names can be missing. */
    for (size_t b = 0; b < bone_count; b++)
        if (seen[bone_label[b]] == 0) {
            seen[bone_label[b]] = 2;
            r->empty_joints++;
        }
    free(seen);
    double cell = (double)spacing * spacing * spacing;
    r->total_voxels = count;
    r->body_volume = (double)r->body_voxels * cell;
    r->skin_volume = (double)skin_count * cell;
    r->seconds = pp_now_s() - t0;
    return POSE_OK;
}
