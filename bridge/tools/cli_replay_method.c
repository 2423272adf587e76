/* SPDX-License-Identifier: Apache-2.0 */
#include "cli_replay_method.h"

#include <math.h>
#include <strings.h>
#include <time.h>

/* pose_step is stable up to dt = 1/30 s (pose.h): longer gaps between two
 * poses are split into equal steps no longer than that. */
#define LONGEST_STEP_S (1.0 / 30.0)
/* A gap longer than this (a seek, a loop's wrap, a recording that paused) is
 * not motion to integrate: the simulation restarts at rest in the new pose. */
#define RESTART_GAP_S 1.0

static const struct {
    const char *name;
    pose_method method;
    int dynamics;
} k_methods[] = {
    {"lbs", POSE_LBS, 0}, {"dqs", POSE_DQS, 0}, {"cor", POSE_COR, 0},
    {"fem", POSE_FEM, 0}, {"dynamics", POSE_FEM, 1},
};

int pb_replay_method_parse(const char *s, pb_replay_method *out)
{
    *out = (pb_replay_method){.name = "lbs", .method = POSE_LBS};
    if (!s)
        return 0;
    for (size_t i = 0; i < sizeof k_methods / sizeof k_methods[0]; i++)
        if (!strcasecmp(s, k_methods[i].name)) {
            out->name = k_methods[i].name;
            out->method = k_methods[i].method;
            out->dynamics = k_methods[i].dynamics;
            return 0;
        }
    return -1;
}

pose_status pb_replay_method_start(pb_replay_method *m, pose_state *st)
{
    return pose_set_method(st, m->method);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static pose_status restart(pb_replay_method *m, pose_state *st, double media_s)
{
    m->started = 1;
    m->sim_media_s = media_s;
    m->restarts++;
    return pose_reset_dynamics(st);
}

/* Advance the simulation to the pose of recorded time media_s. */
static pose_status step_to(pb_replay_method *m, pose_state *st, double media_s)
{
    const double gap = media_s - m->sim_media_s;
    if (!m->started || gap < 0.0 || gap > RESTART_GAP_S)
        return restart(m, st, media_s);
    if (gap == 0.0)
        return POSE_OK;
    const int n = (int)ceil(gap / LONGEST_STEP_S - 1e-9);
    pose_dynamics_stats ds = {.size = sizeof ds};
    for (int i = 0; i < n; i++) {
        pose_status s = pose_step(st, gap / n);
        if (s < 0)
            return s;
        if ((s = pose_get_dynamics_stats(st, &ds)) < 0)
            return s;
        m->steps++;
        m->kinetic_energy = ds.kinetic_energy;
        m->kinetic_energy_peak = fmax(m->kinetic_energy_peak, ds.kinetic_energy);
        m->cg_max = ds.cg_iterations > m->cg_max ? ds.cg_iterations : m->cg_max;
    }
    m->simulated_s += gap;
    m->sim_media_s = media_s;
    return POSE_OK;
}

pose_status pb_replay_method_update(pb_replay_method *m, pose_state *st, const pose_bridge_frame *fr)
{
    const double t0 = now_s();
    pose_status s;
    if (m->dynamics) {
        s = step_to(m, st, fr->media_s);
    } else if ((s = pose_apply(st)) >= 0 && m->method == POSE_FEM) {
        pose_fem_stats fs = {.size = sizeof fs};
        s = pose_get_fem_stats(st, &fs);
        m->fem_cg += fs.cg_iterations;
        m->fem_residual = fs.residual;
    }
    m->update_s += now_s() - t0;
    m->updates += s >= 0;
    return s;
}

void pb_replay_method_json(const pb_replay_method *m, FILE *f)
{
    fprintf(f, ", \"method\": \"%s\", \"updates\": %llu, \"update_ms_mean\": %.3f", m->name, m->updates,
            m->updates ? 1e3 * m->update_s / (double)m->updates : 0.0);
    if (m->dynamics)
        fprintf(f,
                ", \"steps\": %llu, \"restarts\": %llu, \"simulated_s\": %.6f, \"kinetic_energy_j\": %.6g, "
                "\"kinetic_energy_peak_j\": %.6g, \"cg_iterations_max\": %d",
                m->steps, m->restarts, m->simulated_s, m->kinetic_energy, m->kinetic_energy_peak, m->cg_max);
    else if (m->method == POSE_FEM)
        fprintf(f, ", \"fem_cg_iterations_mean\": %.2f, \"fem_residual_last\": %.4g",
                m->updates ? (double)m->fem_cg / (double)m->updates : 0.0, m->fem_residual);
}
