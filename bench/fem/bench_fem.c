/* SPDX-License-Identifier: Apache-2.0 */
/*
 * bench_fem: POSE_FEM on a baked body (pose-bake with the full_body
 * template), per posture of issue 12: skin volume change of CoR (DQS
 * without centres) and of FEM against rest, the time of pose_apply with
 * each (ratio measured in the same run), and where the FEM frame goes:
 * skinning, rotations + elastic forces, CG iterations, transfer. Each
 * posture is timed twice: cold, the first pose of a fresh state (every
 * tet's rotation found from identity), and warm, as a frame of an
 * animation: the state was posed at 90 % of the angles just before (the
 * mean of --reps such frames). Every run refines from the skinned pose.
 * "cpu ms" is the process CPU time of a warm FEM frame (all threads, the
 * pool's spinning included): on a machine shared with other work, where
 * wall times stretch, cpu / threads bounds what two idle cores take.
 *
 * Then dynamics (pose_step, default settings): --steps steps of
 * dt = 1/120 s while both shoulders and elbows swing 0 -> 90 -> 0 degrees
 * at 360 deg/s, then rest: steps per second (wall and per CPU second),
 * the mean cost of each part (skinning, assembly, CG, transfer), CG
 * iterations, and the bytes a step streams against the STREAM triad
 * bandwidth measured in the same run with the same thread count
 * (bound = triad / bytes per step; ratio = achieved / bound).
 *
 * --contact N: N rounds of the dynamics without and with the contact
 * response (pose/contact.h: soft nodes kept out of bone by velocity
 * constraints in the step, the skin pushed out of bone after it),
 * alternately, and the ratio of their wall times per step; the passes'
 * own timers, and the share of clusters they left quiet (contact_quiet.h:
 * nothing near them moved enough to matter). --steps 120 keeps to the
 * swing; the default 480 holds the rest posture 3 s after it. The first
 * step is timed apart (with contact it builds the response's nodes).
 *
 *   fem RIG [--threads N] [--reps N] [--tolerance T] [--outer N] [--steps N]
 *           [--dynamics-only] [--contact N]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_common.h"
#include "contact_push.h"
#include "fem_volume.h"
#include "pose/contact.h"
#include "pose/pose.h"
#include "state_internal.h"

typedef struct posture {
    const char *name;
    const char *joints[2];
    float deg[3];
} posture;

static const posture k_postures[] = {
    {"shoulder flexion 150", {"shoulder_r", "shoulder_l"}, {150, 0, 0}},
    {"arms at the sides", {"shoulder_r", "shoulder_l"}, {0, 0, 0}},
    {"hip flexion 90", {"hip_r", "hip_l"}, {90, 0, 0}},
    {"knee flexion 120", {"knee_r", "knee_l"}, {120, 0, 0}},
    {"elbow flexion 120", {"elbow_r", "elbow_l"}, {120, 0, 0}},
};

static int set_posture(const pose_rig *rig, pose_state *st, const posture *p, float scale)
{
    pose_reset(st);
    const float deg[3] = {scale * p->deg[0], scale * p->deg[1], scale * p->deg[2]};
    for (int s = 0; s < 2; s++) {
        int j = pose_rig_find_joint(rig, p->joints[s]);
        if (j < 0 || pose_set_joint_clinical(st, j, deg) < 0) {
            fprintf(stderr, "fem: %s: %s\n", p->joints[s], pose_last_error());
            return -1;
        }
    }
    return 0;
}

/* Both shoulders and elbows at `deg` (flexion). */
static int set_swing(const pose_rig *rig, pose_state *st, double deg)
{
    static const char *const joints[] = {"shoulder_r", "shoulder_l", "elbow_r", "elbow_l"};
    const float a[3] = {(float)deg, 0.0f, 0.0f};
    for (int k = 0; k < 4; k++) {
        int j = pose_rig_find_joint(rig, joints[k]);
        if (j < 0 || pose_set_joint_clinical(st, j, a) < 0) {
            fprintf(stderr, "fem: %s: %s\n", joints[k], pose_last_error());
            return -1;
        }
    }
    return 0;
}

/* The dynamics bench; with `contact` the contact response is on (pose/contact.h:
 * soft nodes kept out of bone in the step, the skin pushed out after it).
 * The wall time per step into *ms_step when given. */
static int bench_dynamics(const pose_rig *rig, int threads, int steps, int contact, double *ms_step)
{
    pose_state_options so = {.size = sizeof so, .threads = threads};
    pose_state *st;
    pose_contact_response cr = {.size = sizeof cr, .enabled = contact};
    if (pose_state_create_ex(rig, &so, &st) || pose_set_method(st, POSE_FEM) ||
        pose_set_dynamics_options(st, NULL) || pose_set_contact_response(st, &cr)) {
        fprintf(stderr, "fem: %s\n", pose_last_error());
        return -1;
    }
    const double dt = 1.0 / 120.0, rate = 360.0, swing = 4.0 * 90.0 / rate;
    /* start at rest in the swing's first pose (not the T-pose of the bake) */
    if (set_swing(rig, st, 0.0) || pose_reset_dynamics(st)) {
        fprintf(stderr, "fem: %s\n", pose_last_error());
        return -1;
    }
    pose_dynamics_stats ds = {.size = sizeof ds}, sum = {0};
    double wall = 0.0, cpu = 0.0, first = 0.0, peak = 0.0, skin_push = 0.0, quiet_nodes = 0.0, quiet_skin = 0.0;
    int cg_max = 0;
    for (int s = 1; s <= steps; s++) {
        const double t = s * dt, u = fmod(fmin(t, swing) * rate, 180.0);
        if (set_swing(rig, st, u <= 90.0 ? u : 180.0 - u))
            return -1;
        const double t0 = bench_now(), c0 = bench_cpu_seconds();
        if (pose_step(st, dt) != POSE_OK) {
            fprintf(stderr, "fem: %s\n", pose_last_error());
            return -1;
        }
        if (s == 1) { /* apart: with contact, the first step builds the response's nodes */
            first = bench_now() - t0;
        } else {
            wall += bench_now() - t0;
            cpu += bench_cpu_seconds() - c0;
        }
        pose_get_dynamics_stats(st, &ds);
        sum.seconds_skin += ds.seconds_skin;
        sum.seconds_assembly += ds.seconds_assembly;
        sum.seconds_cg += ds.seconds_cg;
        sum.seconds_transfer += ds.seconds_transfer;
        sum.seconds_contact += ds.seconds_contact;
        pose_contact_response_stats cs = {.size = sizeof cs};
        if (contact && pose_get_contact_response_stats(st, &cs) == POSE_OK) {
            skin_push += cs.seconds;
            const pose__push *p = st->push; /* clusters the passes left as they were (contact_quiet.h) */
            quiet_nodes += (double)pose__quiet_held(&p->node_quiet) / (double)p->node_clusters;
            quiet_skin += (double)pose__quiet_held(&p->skin_quiet) / (double)p->cluster_count;
        }
        sum.contacts += ds.contacts;
        sum.cg_iterations += ds.cg_iterations;
        cg_max = ds.cg_iterations > cg_max ? ds.cg_iterations : cg_max;
        peak = fmax(peak, ds.kinetic_energy);
    }
    const double cg_mean = (double)sum.cg_iterations / steps;
    const double bytes = pose__state_dynamics_bytes(st, cg_mean);
    const double triad = bench_triad_bytes_per_s((unsigned)threads, (size_t)1 << 24, 5);
    const double sps = (steps - 1) / wall, bound = triad / bytes, ms = 1e3 / steps, wall_ms = 1e3 / (steps - 1);
    pose_tet_info tet;
    pose_rig_tet_info(rig, &tet);
    size_t soft = 0;
    for (size_t t = 0; t < tet.tet_count; t++)
        soft += tet.labels[t] == 0;
    printf("dynamics%s: dt 1/120 s, %d steps (%.2f s swinging shoulders and elbows 0-90-0 at 360 "
           "deg/s twice, then rest), %zu tets (%zu soft), %d island(s), %d threads\n",
           contact ? " with contact" : "", steps, swing, tet.tet_count, soft, ds.islands, threads);
    printf("  %.1f steps/s (target 120), %.2f ms/step wall, %.2f ms CPU/step (all threads), after a first "
           "step of %.2f ms\n", sps, wall * wall_ms, cpu * wall_ms, 1e3 * first);
    printf("  per step: skin %.2f ms, assembly %.2f ms, CG %.2f ms (%.1f iterations, most %d, "
           "%.3f ms each), transfer %.2f ms\n",
           sum.seconds_skin * ms, sum.seconds_assembly * ms, sum.seconds_cg * ms, cg_mean, cg_max,
           sum.cg_iterations ? 1e3 * sum.seconds_cg / sum.cg_iterations : 0.0,
           sum.seconds_transfer * ms);
    if (contact)
        printf("  contact: %.2f ms/step (timers): nodes' constraints %.2f, the skin's push %.2f; %.1f "
               "constraints per step; clusters left quiet %.1f %% of the nodes', %.1f %% of the skin's; %.1f %% "
               "of the rest of the step's timers\n",
               sum.seconds_contact * ms, (sum.seconds_contact - skin_push) * ms, skin_push * ms,
               (double)sum.contacts / steps, 100.0 * quiet_nodes / steps, 100.0 * quiet_skin / steps,
               100.0 * sum.seconds_contact /
                   (sum.seconds_skin + sum.seconds_assembly + sum.seconds_cg + sum.seconds_transfer));
    if (ms_step)
        *ms_step = wall * wall_ms;
    printf("  memory: %.2f MB/step, triad %.2f GB/s -> bound %.0f steps/s; achieved/bound %.3f\n",
           bytes / 1e6, triad / 1e9, bound, sps / bound);
    printf("  kinetic energy: peak %.3e J, %.3e J at the end (%.2f s simulated)\n", peak,
           ds.kinetic_energy, ds.time);
    pose_state_free(st);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help")) {
        fprintf(stderr, "usage: fem RIG [--threads N] [--reps N] [--tolerance T] [--outer N] "
                        "[--steps N] [--dynamics-only] [--contact ROUNDS]\n");
        return argc < 2 ? 2 : 0;
    }
    int threads = 2, reps = 5, outer = 0, steps = 480, statics = 1, contact = 0;
    float tol = 0.0f;
    for (int i = 2; i < argc; i += 2) {
        if (!strcmp(argv[i], "--dynamics-only")) {
            statics = 0;
            i--;
            continue;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "fem: %s needs a value\n", argv[i]);
            return 2;
        }
        if (!strcmp(argv[i], "--steps"))
            steps = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--threads"))
            threads = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--reps"))
            reps = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--tolerance"))
            tol = (float)atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--outer"))
            outer = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--contact"))
            contact = atoi(argv[i + 1]);
        else {
            fprintf(stderr, "fem: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    if (steps == 1 || steps < 0) { /* the first step is timed apart from the others */
        fprintf(stderr, "fem: --steps must be 0 or at least 2\n");
        return 2;
    }
    pose_rig *rig;
    if (pose_rig_load(argv[1], &rig) != POSE_OK) {
        fprintf(stderr, "fem: %s\n", pose_last_error());
        return 1;
    }
    if (!pose_rig_has_fem(rig)) {
        fprintf(stderr, "fem: %s has no fem section (bake without --no-fem)\n", argv[1]);
        return 1;
    }
    int skin = -1;
    for (size_t t = 0; t < pose_rig_tissue_count(rig) && skin < 0; t++) {
        pose_tissue_info ti;
        pose_rig_tissue_info(rig, (int)t, &ti);
        if (ti.kind == POSE_TISSUE_SKIN)
            skin = (int)t;
    }
    pose_tissue_info si;
    pose_tet_info tet;
    pose_rig_tissue_info(rig, skin, &si);
    pose_rig_tet_info(rig, &tet);
    const double v0 = fx_mesh_volume(si.rest_positions, si.triangles, si.triangle_count);
    const pose_method skinning = tet.cor ? POSE_COR : POSE_DQS;
    size_t soft = 0;
    for (size_t t = 0; t < tet.tet_count; t++)
        soft += tet.labels[t] == 0;
    printf("rig %s: %zu tet vertices, %zu tets (%zu soft), skin %.3f L; %d threads, %d reps\n",
           argv[1], tet.vertex_count, tet.tet_count, soft, v0 * 1e3, threads, reps);
    printf("%-22s %8s %6s %8s %7s %7s %6s %5s %6s %6s %6s %6s %6s %6s %6s\n", "posture",
           skinning == POSE_COR ? "CoR dV%" : "DQS dV%", "ms", "FEM dV%", "cold ms", "warm ms",
           "outer", "CG", "skin", "rot", "cg", "xfer", "ms/CG", "ratio", "cpu ms");
    pose_state_options so = {.size = sizeof so, .threads = threads};
    double worst = 0.0, slowest = 0.0;
    for (size_t p = 0; statics && p < sizeof k_postures / sizeof k_postures[0]; p++) {
        pose_state *sk, *fem;
        if (pose_state_create_ex(rig, &so, &sk) || pose_state_create_ex(rig, &so, &fem)) {
            fprintf(stderr, "fem: %s\n", pose_last_error());
            return 1;
        }
        pose_set_method(sk, skinning);
        pose_set_method(fem, POSE_FEM);
        pose_fem_options fo = {.size = sizeof fo, .outer_iterations = outer, .tolerance = tol};
        pose_set_fem_options(fem, &fo);
        double t_sk = 0.0, t_fem = 0.0, cold = 0.0, cpu = 0.0;
        pose_fem_stats sum = {0}, fs = {.size = sizeof fs};
        if (set_posture(rig, fem, &k_postures[p], 1.0f))
            return 1;
        double c0 = bench_now();
        pose_apply(fem);
        cold = bench_now() - c0;
        for (int r = 0; r < reps; r++) {
            if (set_posture(rig, fem, &k_postures[p], 0.9f))
                return 1;
            pose_apply(fem);
            if (set_posture(rig, sk, &k_postures[p], 1.0f) || set_posture(rig, fem, &k_postures[p], 1.0f))
                return 1;
            double t0 = bench_now();
            pose_apply(sk);
            double t1 = bench_now(), c1 = bench_cpu_seconds();
            pose_apply(fem);
            double t2 = bench_now();
            cpu += bench_cpu_seconds() - c1;
            t_sk += t1 - t0;
            t_fem += t2 - t1;
            pose_get_fem_stats(fem, &fs);
            sum.seconds_skin += fs.seconds_skin;
            sum.seconds_rotations += fs.seconds_rotations;
            sum.seconds_cg += fs.seconds_cg;
            sum.seconds_transfer += fs.seconds_transfer;
            sum.cg_iterations += fs.cg_iterations;
        }
        double vs = fx_mesh_volume(pose_tissue_positions(sk, skin, NULL), si.triangles, si.triangle_count);
        double vf = fx_mesh_volume(pose_tissue_positions(fem, skin, NULL), si.triangles, si.triangle_count);
        double ms = 1e3 / reps;
        printf("%-22s %+8.3f %6.2f %+8.3f %7.1f %7.1f %6d %5d %6.2f %6.1f %6.1f %6.2f %6.3f %6.1f %6.1f\n",
               k_postures[p].name, 100 * (vs - v0) / v0, t_sk * ms, 100 * (vf - v0) / v0,
               cold * 1e3, t_fem * ms, fs.outer_iterations, fs.cg_iterations, sum.seconds_skin * ms,
               sum.seconds_rotations * ms, sum.seconds_cg * ms, sum.seconds_transfer * ms,
               sum.cg_iterations ? 1e3 * sum.seconds_cg / sum.cg_iterations : 0.0,
               t_fem / t_sk, cpu * ms);
        worst = fmax(worst, fabs(vf - v0) / v0);
        slowest = fmax(slowest, t_fem * ms);
        pose_state_free(sk);
        pose_state_free(fem);
    }
    if (statics)
        printf("FEM: largest |dV| %.3f %% (target 0.3 %%), slowest posture (warm) %.2f ms (target "
               "50 ms); process CPU %.1f s\n", 100 * worst, slowest, bench_cpu_seconds());
    if (steps > 0 && !contact && bench_dynamics(rig, threads, steps, 0, NULL))
        return 1;
    /* --contact N: N rounds of the dynamics without and with the contact
     * response, alternately (the machine's load drifts), and the ratio of
     * their wall times per step, each round and over all. */
    double off_sum = 0.0, on_sum = 0.0;
    for (int r = 0; steps > 0 && r < contact; r++) {
        double off = 0.0, on = 0.0;
        if (bench_dynamics(rig, threads, steps, 0, &off) || bench_dynamics(rig, threads, steps, 1, &on))
            return 1;
        off_sum += off;
        on_sum += on;
        printf("contact round %d: %.2f ms/step without, %.2f with: ratio %.3f (target <= 1.30)\n", r + 1,
               off, on, on / off);
    }
    if (contact > 0)
        printf("contact: %d rounds, %.2f ms/step without, %.2f with: ratio %.3f (target <= 1.30)\n", contact,
               off_sum / contact, on_sum / contact, on_sum / off_sum);
    pose_rig_free(rig);
    return 0;
}
