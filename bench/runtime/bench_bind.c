/* SPDX-License-Identifier: Apache-2.0 */
/*
 * bench_bind: the cost of multi-anchor binding (pose/binding.h) on a baked
 * rig:
 *   - load: binding the tissue vertices outside the tet mesh at rig load
 *     (what pose__rig_prepare adds; no format change);
 *   - pose_apply: placing those vertices after the transfer, per vertex and
 *     against the whole frame (one thread, the pass that runs them);
 *   - a host mesh: the rig's skin pushed 5 mm out along its normals (a
 *     drape), bound with n = 1, 4 and 8: pose_binding_create, and
 *     pose_binding_apply per vertex.
 * Times are CPU seconds of the one thread that runs them.
 * Usage: bench_bind RIG [--seconds S]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_common.h"
#include "pose/binding.h"
#include "pose/pose.h"
#include "rig_outside.h"
#include "state_internal.h"

/* Mean CPU seconds per call of fn(ctx), repeated for `seconds` (at least 3
 * calls). CPU time, not wall time: everything timed here runs on one
 * thread, and the figures then hold on a machine shared with other work. */
static double mean_seconds(double seconds, void (*fn)(void *), void *ctx)
{
    int reps = 0;
    double t0 = bench_cpu_seconds(), t;
    do {
        fn(ctx);
        reps++;
    } while ((t = bench_cpu_seconds() - t0) < seconds || reps < 3);
    return t / reps;
}

static void rebind_outside(void *rig)
{
    pose__rig_release_outside(rig);
    if (pose__rig_prepare_outside(rig) != POSE_OK) {
        fprintf(stderr, "%s\n", pose_last_error());
        exit(1);
    }
}

static void apply(void *st)
{
    pose_apply(st);
}

static void place_outside(void *st)
{
    pose__state_place_outside(st, 0, ((pose_state *)st)->rt->transfer.vertex_count);
}

typedef struct host {
    pose_binding *binding;
    const pose_state *state;
    float *out;
} host;

static void apply_binding(void *h)
{
    host *x = h;
    pose_binding_apply(x->binding, x->state, x->out);
}

static void deep_pose(pose_state *st)
{
    static const struct { const char *joint; float deg[3]; } set[] = {
        {"knee_r", {120, 0, 0}}, {"elbow_r", {120, 0, 0}}, {"hip_l", {90, 0, 0}},
        {"shoulder_l", {150, 0, 0}},
    };
    const pose_rig *rig = pose_state_rig(st);
    pose_set_neutral(st);
    for (size_t i = 0; i < sizeof set / sizeof set[0]; i++) {
        int j = pose_rig_find_joint(rig, set[i].joint);
        if (j >= 0)
            pose_set_joint_clinical(st, j, set[i].deg);
    }
}

int main(int argc, char **argv)
{
    const char *path = NULL;
    double seconds = 1.0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--seconds") && i + 1 < argc)
            seconds = atof(argv[++i]);
        else if (argv[i][0] != '-' && !path)
            path = argv[i];
        else {
            fprintf(stderr, "usage: bench_bind RIG [--seconds S]\n");
            return 2;
        }
    }
    if (!path) {
        fprintf(stderr, "usage: bench_bind RIG [--seconds S]   (e.g. the demo's out/demo/body.rig)\n");
        return 2;
    }
    pose_rig *rig;
    if (pose_rig_load(path, &rig) != POSE_OK) {
        fprintf(stderr, "%s\n", pose_last_error());
        return 1;
    }
    struct pose__rig_runtime *rt = rig->rt;
    const size_t outside = rt->outside.vertex_count, tissue = rt->transfer.vertex_count;
    printf("rig %s: %zu tet vertices, %zu tets, %zu tissue vertices, %zu outside the tet mesh "
           "(%.2f %%, bones excepted)\n", path, rig->tet_vertex_count, rig->tet_count, tissue,
           outside, 100.0 * (double)outside / (double)tissue);

    /* load: the outside binding alone, built again */
    double load = mean_seconds(seconds, rebind_outside, rig);
    printf("load: binding the outside vertices %.2f ms\n", 1e3 * load);

    pose_state_options so = {.size = sizeof so, .threads = 1, .method = POSE_DQS};
    pose_state *st;
    if (pose_state_create_ex(rig, &so, &st) != POSE_OK) {
        fprintf(stderr, "%s\n", pose_last_error());
        return 1;
    }
    deep_pose(st);
    double frame = mean_seconds(seconds, apply, st);
    double place = mean_seconds(seconds, place_outside, st);
    printf("pose_apply (DQS, 1 thread, deep pose): %.3f ms; placing the outside vertices %.4f ms "
           "(%.0f ns per vertex, %.2f %% of the frame)\n", 1e3 * frame, 1e3 * place,
           outside ? 1e9 * place / (double)outside : 0.0, 100.0 * place / frame);

    /* a host mesh: the skin 5 mm out along its normals */
    int skin = -1;
    pose_tissue_info ti = {0};
    for (int t = 0; t < (int)pose_rig_tissue_count(rig) && skin < 0; t++)
        if (pose_rig_tissue_info(rig, t, &ti) == POSE_OK && ti.kind == POSE_TISSUE_SKIN)
            skin = t;
    if (skin >= 0) {
        pose_state *rest;
        pose_state_create(rig, &rest);
        const float *nrm = pose_tissue_normals(rest, skin, NULL);
        float *drape = malloc(3 * ti.vertex_count * sizeof(float)), *out = malloc(3 * ti.vertex_count * sizeof(float));
        for (size_t i = 0; i < 3 * ti.vertex_count; i++)
            drape[i] = ti.rest_positions[i] + 0.005f * nrm[i];
        pose_state_free(rest);
        printf("host mesh: %zu vertices (the skin 5 mm out)\n", ti.vertex_count);
        const unsigned ns[3] = {1, 4, 8};
        for (int k = 0; k < 3; k++) {
            pose_binding_options bo = {.size = sizeof bo, .anchors = ns[k]};
            pose_binding *b = NULL;
            double t0 = bench_cpu_seconds();
            if (pose_binding_create(rig, drape, ti.vertex_count, &bo, &b) != POSE_OK) {
                fprintf(stderr, "%s\n", pose_last_error());
                return 1;
            }
            double create = bench_cpu_seconds() - t0;
            host h = {b, st, out};
            double each = mean_seconds(seconds, apply_binding, &h);
            printf("  n = %u: pose_binding_create %.1f ms, pose_binding_apply %.3f ms (%.0f ns per "
                   "vertex)\n", ns[k], 1e3 * create, 1e3 * each, 1e9 * each / (double)ti.vertex_count);
            pose_binding_free(b);
        }
        free(drape);
        free(out);
    }
    pose_state_free(st);
    pose_rig_free(rig);
    return 0;
}
