/* SPDX-License-Identifier: Apache-2.0 */
/* The three synthetic rigs: the bar test object, and a body layout at
 * medium and full scale. */
#include <math.h>
#include <stdlib.h>

#include "synth_internal.h"

#define LIMIT_DEG 150.0f

static pose_status finish_or_free(pose_synth_rig *r, pose_synth_cor_mode cor, float sigma,
                                  const char *name, pose_synth_rig **out)
{
    pose_status st = ps_finish(r, cor, sigma, name);
    if (st != POSE_OK) {
        pose_synth_free(r);
        return st;
    }
    *out = r;
    return POSE_OK;
}

pose_status pose_synth_bar(const pose_synth_bar_options *options, pose_synth_rig **out)
{
    if (!out)
        return POSE_ERR_INVALID_ARGUMENT;
    *out = NULL;
    pose_synth_bar_options o = options ? *options : (pose_synth_bar_options){0};
    if (!o.bones) o.bones = 4;
    if (o.bone_length == 0.0f) o.bone_length = 1.0f;
    if (o.radius == 0.0f) o.radius = 0.25f;
    if (!o.layers_per_bone) o.layers_per_bone = 16;
    if (!o.rings) o.rings = 4;
    if (!o.sectors) o.sectors = 16;
    if (!o.skin_sectors) o.skin_sectors = 24;
    if (!o.skin_layers_per_bone) o.skin_layers_per_bone = 12;
    if (!o.influences) o.influences = 4;
    if (o.sigma == 0.0f) o.sigma = 0.1f;
    if (o.cor == POSE_SYNTH_COR_AUTO) o.cor = POSE_SYNTH_COR_EXACT;
    if (o.bones < 1 || o.bones > 64 || !(o.bone_length > 0.0f) || !isfinite(o.bone_length) ||
        !(o.radius > 0.0f) || !isfinite(o.radius) || o.layers_per_bone < 8 ||
        o.layers_per_bone % 8 != 0 || o.rings < 2 || o.rings % 2 != 0 || o.sectors < 6 ||
        o.skin_sectors < 3 || o.skin_layers_per_bone < 1 || o.influences > POSE_SYNTH_MAX_K ||
        !(o.sigma > 0.0f && o.sigma <= 0.1f) || o.cor > POSE_SYNTH_COR_NONE)
        return POSE_ERR_INVALID_ARGUMENT;

    pose_synth_rig *r = ps_rig_new(o.influences);
    if (!r)
        return POSE_ERR_OUT_OF_MEMORY;
    r->progress = o.progress;
    r->progress_user = o.progress_user;
    ps_bar_spec s = {
        .prefix = "", .origin = {0, 0, 0}, .frame = {0, 0, 0, 1}, .bones = o.bones,
        .period = o.bone_length, .radius = o.radius, .rings = o.rings, .sectors = o.sectors,
        .layers_per_period = o.layers_per_bone, .skin_sectors = o.skin_sectors,
        .skin_layers_per_period = o.skin_layers_per_bone, .bone_sectors = 12, .bone_layers = 6,
        .parent = -1, .limit_deg = LIMIT_DEG,
    };
    if (!ps_add_bar(r, &s)) {
        pose_synth_free(r);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    ps_progress(r, "mesh", 1.0);
    return finish_or_free(r, o.cor, o.sigma, "bar", out);
}

/* A body as six bars (metres, z up): spine from the pelvis, head on the
 * spine's top joint, arms on it sideways, legs down from the root. */
typedef struct body_bar {
    const char *prefix;
    float origin[3], dir[3];
    int bones;
    float period, radius;
    int parent_bar;   /* bar holding the parent joint, -1 for the root bar */
    int parent_joint; /* index of the parent joint within that bar */
} body_bar;

static const body_bar body_layout[] = {
    {"spine_", {0.0f, 0.0f, 0.95f}, {0, 0, 1}, 4, 0.15f, 0.14f, -1, 0},
    {"head_", {0.0f, 0.0f, 1.58f}, {0, 0, 1}, 2, 0.12f, 0.08f, 0, 3},
    {"arm_l_", {0.22f, 0.0f, 1.45f}, {1, 0, 0}, 4, 0.17f, 0.045f, 0, 3},
    {"arm_r_", {-0.22f, 0.0f, 1.45f}, {-1, 0, 0}, 4, 0.17f, 0.045f, 0, 3},
    {"leg_l_", {0.1f, 0.0f, 0.9f}, {0, 0, -1}, 4, 0.21f, 0.065f, 0, 0},
    {"leg_r_", {-0.1f, 0.0f, 0.9f}, {0, 0, -1}, 4, 0.21f, 0.065f, 0, 0},
};
#define BODY_BARS (sizeof body_layout / sizeof body_layout[0])
#define BODY_RINGS 2
#define BODY_SECTORS 24

static int round8(double x)
{
    int n = (int)lround(x / 8.0) * 8;
    return n < 8 ? 8 : n;
}

static pose_status make_body(size_t target_tets, size_t target_tissue, unsigned influences,
                             float sigma, pose_synth_cor_mode cor, const char *name,
                             pose_synth_progress_fn progress, void *progress_user,
                             pose_synth_rig **out)
{
    double length = 0.0;
    for (size_t i = 0; i < BODY_BARS; i++)
        length += body_layout[i].bones * body_layout[i].period;
    double tets_per_layer = 3.0 * (BODY_SECTORS + (BODY_RINGS - 1) * 2 * BODY_SECTORS);
    double layers_per_m = (double)target_tets / tets_per_layer / length;
    int skin_sectors = (int)lround(sqrt((double)target_tissue) / 12.0);
    skin_sectors = skin_sectors < 12 ? 12 : (skin_sectors > 96 ? 96 : skin_sectors);
    int bone_sectors = skin_sectors / 2 < 8 ? 8 : skin_sectors / 2;
    double rings_per_m = (double)target_tissue / (length * (skin_sectors + 0.75 * bone_sectors));

    pose_synth_rig *r = ps_rig_new(influences);
    if (!r)
        return POSE_ERR_OUT_OF_MEMORY;
    r->progress = progress;
    r->progress_user = progress_user;
    size_t first_joint[BODY_BARS];
    bool ok = ps_reserve(r, (size_t)(target_tets / 4.2), target_tets + target_tets / 8);
    for (size_t i = 0; ok && i < BODY_BARS; i++) {
        const body_bar *bb = &body_layout[i];
        ps_bar_spec s = {
            .prefix = bb->prefix, .origin = {bb->origin[0], bb->origin[1], bb->origin[2]},
            .bones = bb->bones, .period = bb->period, .radius = bb->radius,
            .rings = BODY_RINGS, .sectors = BODY_SECTORS,
            .layers_per_period = round8(layers_per_m * bb->period),
            .skin_sectors = skin_sectors,
            .skin_layers_per_period = (int)fmax(1.0, lround(rings_per_m * bb->period)),
            .bone_sectors = bone_sectors,
            .bone_layers = (int)fmax(1.0, lround(rings_per_m * 0.75 * bb->period)),
            .parent = bb->parent_bar < 0 ? -1
                                         : (int)first_joint[bb->parent_bar] + bb->parent_joint,
            .limit_deg = LIMIT_DEG,
        };
        const float x[3] = {1, 0, 0};
        ps_quat_from_to(x, bb->dir, s.frame);
        first_joint[i] = r->joint_count;
        ok = ps_add_bar(r, &s);
        ps_progress(r, "mesh", (double)(i + 1) / BODY_BARS);
    }
    if (!ok) {
        pose_synth_free(r);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    return finish_or_free(r, cor, sigma, name, out);
}

pose_status pose_synth_body(const pose_synth_body_options *options, pose_synth_rig **out)
{
    if (!out)
        return POSE_ERR_INVALID_ARGUMENT;
    *out = NULL;
    pose_synth_body_options o = options ? *options : (pose_synth_body_options){0};
    if (!o.target_tets) o.target_tets = 3500000;
    if (!o.target_tissue_vertices) o.target_tissue_vertices = (size_t)(o.target_tets * 0.37);
    if (!o.influences) o.influences = 4;
    if (o.sigma == 0.0f) o.sigma = 0.1f;
    if (o.cor == POSE_SYNTH_COR_AUTO) o.cor = POSE_SYNTH_COR_CLUSTERED;
    if (o.target_tets < 1000 || o.target_tets > 50000000 || o.target_tissue_vertices < 100 ||
        o.influences > POSE_SYNTH_MAX_K || !(o.sigma > 0.0f && o.sigma <= 0.1f) ||
        o.cor > POSE_SYNTH_COR_NONE)
        return POSE_ERR_INVALID_ARGUMENT;
    return make_body(o.target_tets, o.target_tissue_vertices, o.influences, o.sigma, o.cor,
                     "body", o.progress, o.progress_user, out);
}

pose_status pose_synth_medium(pose_synth_rig **out)
{
    if (!out)
        return POSE_ERR_INVALID_ARGUMENT;
    *out = NULL;
    return make_body(50000, 18500, 4, 0.1f, POSE_SYNTH_COR_EXACT, "medium", NULL, NULL, out);
}
