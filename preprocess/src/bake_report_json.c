/* SPDX-License-Identifier: Apache-2.0
 *
 * The bake report as JSON (pose-bake --json / --report): per-stage seconds,
 * counts, rigging residuals, mesh quality, weight checks, mapping figures.
 */
#include "bake_pipeline.h"

#include <cjson/cJSON.h>
#include <math.h>

static void add_vec(cJSON *o, const char *key, const double *v, int n)
{
    cJSON *a = cJSON_AddArrayToObject(o, key);
    for (int i = 0; i < n; i++)
        cJSON_AddItemToArray(a, cJSON_CreateNumber(round(v[i] * 1e6) / 1e6));
}

static const char *kind_name(pose_tissue_kind k)
{
    switch (k) {
    case POSE_TISSUE_SKIN: return "skin";
    case POSE_TISSUE_BONE: return "bone";
    case POSE_TISSUE_MUSCLE: return "muscle";
    case POSE_TISSUE_ORGAN: return "organ";
    case POSE_TISSUE_OTHER: return "other";
    }
    return "other";
}

char *pp_bake_report_json(const pp_bake_report *r, const pp_bake_options *o)
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return NULL;
    cJSON_AddStringToObject(root, "output", o->output_path ? o->output_path : "");
    cJSON_AddStringToObject(root, "template", r->tmpl.name);
    cJSON_AddStringToObject(root, "backend", pp_tet_backend_name(o->backend));
    cJSON_AddNumberToObject(root, "voxel_mm", r->voxel_mm);
    cJSON_AddNumberToObject(root, "total_seconds", r->total_seconds);
    cJSON_AddNumberToObject(root, "peak_rss_mb", round(r->peak_rss_mb * 10) / 10);
    cJSON_AddNumberToObject(root, "rig_bytes", (double)r->rig_bytes);
    cJSON_AddNumberToObject(root, "coupled_nodes", (double)r->coupled_nodes);
    cJSON_AddNumberToObject(root, "soft_coupled_nodes", (double)r->soft_coupled_nodes);
    cJSON *st = cJSON_AddObjectToObject(root, "stage_seconds");
    for (int s = 0; s < PP_STAGE_COUNT; s++)
        cJSON_AddNumberToObject(st, pp_bake_stage_name((pp_bake_stage)s),
                                round(r->seconds[s] * 1e4) / 1e4);

    cJSON *joints = cJSON_AddArrayToObject(root, "joints");
    for (size_t j = 0; r->fits && j < r->tmpl.joint_count; j++) {
        const pp_template_joint *tj = &r->tmpl.joints[j];
        const pp_fit_joint *f = &r->fits[j];
        cJSON *o2 = cJSON_CreateObject();
        cJSON_AddStringToObject(o2, "name", tj->name);
        cJSON_AddStringToObject(o2, "parent", tj->parent >= 0 ? r->tmpl.joints[tj->parent].name : "");
        cJSON_AddStringToObject(o2, "rule", pp_fit_rule_name(tj->rule));
        add_vec(o2, "centre", f->centre, 3);
        double axis[3] = {f->frame[0][1], f->frame[1][1], f->frame[2][1]};
        add_vec(o2, "axis", axis, 3);
        cJSON_AddNumberToObject(o2, "contact_points", (double)f->contact_points);
        cJSON_AddNumberToObject(o2, "radius_mm", round(f->radius_mm * 100) / 100);
        cJSON_AddNumberToObject(o2, "residual_mm", round(f->residual_mm * 100) / 100);
        const pp_clinical_joint *cl = r->clinical ? &r->clinical[j] : NULL;
        if (cl && (cl->c.flags & POSE_CLINICAL_DEFINED)) {
            /* The neutral posture's offset from rest, and the axes (model
             * space, neutral posture) the clinical angles turn about. */
            cJSON_AddNumberToObject(o2, "neutral_offset_deg", round(cl->neutral_deg * 100) / 100);
            cJSON *ax = cJSON_AddObjectToObject(o2, "clinical_axes");
            static const char *keys[3] = {"flexion", "abduction", "rotation"};
            for (int k = 0; k < 3; k++)
                add_vec(ax, keys[k], cl->model_axes[k], 3);
        }
        cJSON_AddItemToArray(joints, o2);
    }

    cJSON *vx = cJSON_AddObjectToObject(root, "voxels");
    cJSON_AddNumberToObject(vx, "total", (double)r->voxels.total_voxels);
    cJSON_AddNumberToObject(vx, "body", (double)r->voxels.body_voxels);
    cJSON_AddNumberToObject(vx, "bone", (double)r->voxels.bone_voxels);
    cJSON_AddNumberToObject(vx, "skin_boundary_edges", (double)r->voxels.skin_boundary_edges);
    cJSON_AddNumberToObject(vx, "skin_volume_m3", r->voxels.skin_volume);
    cJSON_AddNumberToObject(vx, "open_bone_meshes", (double)r->voxels.open_bone_meshes);
    cJSON_AddNumberToObject(vx, "bone_voxels_outside_skin", (double)r->voxels.bone_voxels_outside_skin);
    cJSON_AddNumberToObject(vx, "overlap_voxels", (double)r->voxels.overlap_voxels);
    cJSON_AddNumberToObject(vx, "ambiguous_voxels", (double)r->voxels.ambiguous_voxels);
    cJSON_AddNumberToObject(vx, "thin_bones", (double)r->voxels.thin_bones);
    cJSON_AddNumberToObject(vx, "empty_joints", (double)r->voxels.empty_joints);

    cJSON *tq = cJSON_AddObjectToObject(root, "tetmesh");
    cJSON_AddNumberToObject(tq, "vertices", (double)r->quality.vertex_count);
    cJSON_AddNumberToObject(tq, "tets", (double)r->quality.tet_count);
    cJSON_AddNumberToObject(tq, "min_dihedral_deg", r->quality.min_dihedral_deg);
    cJSON_AddNumberToObject(tq, "max_dihedral_deg", r->quality.max_dihedral_deg);
    cJSON_AddNumberToObject(tq, "max_radius_edge", r->quality.max_radius_edge);
    cJSON_AddNumberToObject(tq, "inverted", (double)r->quality.inverted_count);
    /* against voxels.skin_volume_m3: the mesh encloses the skin (tetmesh.h) */
    cJSON_AddNumberToObject(tq, "volume_m3", r->quality.total_volume);

    cJSON *w = cJSON_AddObjectToObject(root, "weights");
    cJSON_AddNumberToObject(w, "free_vertices", (double)r->weights.free_vertices);
    cJSON_AddNumberToObject(w, "bone_vertices", (double)r->weights.fixed_vertices);
    cJSON_AddNumberToObject(w, "conflict_vertices", (double)r->weights.conflict_vertices);
    cJSON_AddNumberToObject(w, "floating_regions", (double)r->weights.floating_regions);
    cJSON_AddNumberToObject(w, "floating_vertices", (double)r->weights.floating_vertices);
    cJSON_AddNumberToObject(w, "empty_joints", (double)r->weights.empty_joints);
    cJSON_AddBoolToObject(w, "supernodal", r->weights.supernodal);
    cJSON_AddNumberToObject(w, "factor_nnz", (double)r->weights.factor_nnz);
    cJSON_AddNumberToObject(w, "min_weight", r->weights.min_weight);
    cJSON_AddNumberToObject(w, "max_weight", r->weights.max_weight);
    cJSON_AddNumberToObject(w, "max_sum_error", r->weights.max_sum_error);
    cJSON_AddNumberToObject(w, "max_dropped", r->weights.max_dropped);
    cJSON_AddNumberToObject(w, "clipped_entries", (double)r->weights.clipped_entries);
    cJSON_AddBoolToObject(w, "non_negative", r->weights.min_weight > -1e-6);
    cJSON_AddBoolToObject(w, "bounded", r->weights.max_weight < 1 + 1e-6);
    cJSON_AddBoolToObject(w, "partition_of_unity", r->weights.max_sum_error < 1e-6);
    cJSON_AddNumberToObject(w, "seconds_assemble", r->weights.seconds_assemble);
    cJSON_AddNumberToObject(w, "seconds_factor", r->weights.seconds_factor);
    cJSON_AddNumberToObject(w, "seconds_solve", r->weights.seconds_solve);

    cJSON *mp = cJSON_AddObjectToObject(root, "mapping");
    cJSON_AddNumberToObject(mp, "vertices", (double)r->mapping.vertices);
    cJSON_AddNumberToObject(mp, "outside", (double)r->mapping.outside);
    cJSON_AddNumberToObject(mp, "max_distance_mm", round(r->mapping.max_distance * 1e5) / 100);
    cJSON_AddNumberToObject(mp, "bone_label_fallback", (double)r->mapping.label_fallback);
    cJSON *ts = cJSON_AddArrayToObject(mp, "tissues");
    for (size_t t = 0; t < r->tissue_count; t++) {
        const pp_bake_tissue *bt = &r->tissues[t];
        cJSON *o2 = cJSON_CreateObject();
        cJSON_AddStringToObject(o2, "name", bt->name);
        cJSON_AddStringToObject(o2, "kind", kind_name(bt->kind));
        cJSON_AddStringToObject(o2, "joint", bt->joint >= 0 ? r->tmpl.joints[bt->joint].name : "");
        cJSON_AddNumberToObject(o2, "vertices", (double)bt->vertices);
        cJSON_AddNumberToObject(o2, "outside", (double)bt->outside);
        cJSON_AddNumberToObject(o2, "max_distance_mm", round(bt->max_distance * 1e5) / 100);
        cJSON_AddItemToArray(ts, o2);
    }

    cJSON *c = cJSON_AddObjectToObject(root, "cor");
    cJSON_AddBoolToObject(c, "computed", !o->no_cor);
    cJSON_AddNumberToObject(c, "vertices_with_cor", (double)r->cor.vertices_with_cor);
    cJSON_AddNumberToObject(c, "tets_used", (double)r->cor.tets_used);
    cJSON_AddNumberToObject(c, "pairs", (double)r->cor.pairs);
    cJSON_AddNumberToObject(c, "bins", (double)r->cor.bins);
    cJSON_AddNumberToObject(c, "cells", (double)r->cor.cells);
    cJSON_AddNumberToObject(c, "evaluations", (double)r->cor.evaluations);
    cJSON_AddNumberToObject(c, "seconds", r->cor.seconds);

    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    return text;
}
