/* SPDX-License-Identifier: Apache-2.0 */
/* Dynamics on a state (pose_step): settings, statistics, the simulation's
 * allocation, and the step between skinning and transfer. */
#include <math.h>
#include <string.h>

#include "alloc.h"
#include "contact_push.h"
#include "error.h"
#include "state_internal.h"

void pose_dynamics_defaults(pose_dynamics_options *out)
{
    if (!out)
        return;
    /* Damping: alpha 1/s and beta 0.01 s give the soft tissue's slow
     * jiggle (a few Hz) a damping ratio of a few percent and its stiff
     * (volume) modes far more, so motion visibly rings, then settles.
     * Coupling 100: a bone node lags its bone by about 1 % of what the
     * tissue alone would stretch. Tolerance 1e-2: 2-3 CG iterations per
     * step of 1/120 s on the baked body; the swings of the tests and the
     * bench stay stable up to 1e-1. */
    *out = (pose_dynamics_options){.size = sizeof *out, .mass_damping = 1.0f,
                                   .stiffness_damping = 0.01f, .coupling_stiffness = 100.0f,
                                   .tolerance = 1e-2f, .cg_iterations = 50};
}

/* Why the state cannot simulate, or POSE_OK. */
static pose_status check_rig(const pose_state *st, const char *fn)
{
    if (!pose_rig_has_fem(st->rig))
        return pose__fail(POSE_ERR_UNSUPPORTED,
                          "%s: dynamics needs the rig's fem section (soft tissue material)", fn);
    if (!(st->rig->fem->density > 0.0f))
        return pose__fail(POSE_ERR_UNSUPPORTED,
                          "%s: the rig's soft tissue has density %g: nothing to move", fn,
                          (double)st->rig->fem->density);
    return POSE_OK;
}

/* Skin the tet mesh (where the bones are) and restart the simulation at
 * rest there. */
static void restart(pose_state *st)
{
    pose__state_skin_pass(st);
    pose__state_couplings_bones(st); /* coupled nodes start at their springs' ends */
    pose__fem_dyn_reset(&st->rt->fem, &st->dyn, st->tet_positions);
    if (st->push && st->push->nodes_built)
        pose__push_forget(st->push, st->rig->tet_vertex_count);
    memset(&st->dyn_stats, 0, sizeof st->dyn_stats);
    st->dyn_stats.size = sizeof st->dyn_stats;
    st->dyn_stats.islands = (int)st->dyn.island_count;
}

/* The simulation's buffers (first use): islands need a scratch array of
 * their own before the block's size is known. */
static pose_status enable(pose_state *st, const char *fn)
{
    pose_status s = check_rig(st, fn);
    if (s < 0 || st->dyn_block)
        return s;
    if ((s = pose__state_fem_work(st, fn)) < 0) /* the solver's work arrays (state_fem.c) */
        return s;
    const pose__fem_mesh *m = &st->rt->fem;
    uint32_t *island = pose__alloc(&st->allocator, m->vertex_count * sizeof(uint32_t) + 64,
                                   POSE__ALIGN);
    if (!island)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: out of memory for the islands", fn);
    size_t ni, ns;
    pose__fem_dyn_islands(m, island, &ni, &ns);
    const size_t size = pose__fem_dyn_size(m, ni, ns);
    void *block = pose__alloc(&st->allocator, size, POSE__ALIGN);
    if (block) {
        pose__fem_dyn_init(m, island, ni, ns, block, &st->dyn);
        pose__state_links_islands(st, island); /* joined by soft couplings (state_links.c) */
    }
    pose__free(&st->allocator, island);
    if (!block)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: out of memory for the simulation (%zu bytes)",
                          fn, size);
    if (pose__state_mark_outside_tets(st) < 0) {
        pose__free(&st->allocator, block);
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: out of memory classifying the tets", fn);
    }
    st->dyn_block = block;
    restart(st);
    return POSE_OK;
}

pose_status pose_set_dynamics_options(pose_state *st, const pose_dynamics_options *o)
{
    pose__clear_error();
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_dynamics_options: state is NULL");
    pose_dynamics_options p;
    pose_dynamics_defaults(&p);
    if (o) {
        if (o->size < sizeof(pose_dynamics_options))
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "pose_set_dynamics_options: options.size %zu is below the 0.2 layout "
                              "(%zu; start from pose_dynamics_defaults)",
                              o->size, sizeof(pose_dynamics_options));
        int finite = isfinite(o->mass_damping) && isfinite(o->stiffness_damping);
        for (int a = 0; a < 3; a++)
            finite = finite && isfinite(o->gravity[a]);
        if (!finite || !(o->mass_damping >= 0.0f) || !(o->stiffness_damping >= 0.0f))
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "pose_set_dynamics_options: damping (%g, %g) must be finite and >= 0, "
                              "gravity finite",
                              (double)o->mass_damping, (double)o->stiffness_damping);
        if (!(o->coupling_stiffness > 0.0f) || !isfinite(o->coupling_stiffness))
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "pose_set_dynamics_options: coupling_stiffness %g must be > 0",
                              (double)o->coupling_stiffness);
        if (!(o->tolerance > 0.0f && o->tolerance < 1.0f) || o->cg_iterations < 1)
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "pose_set_dynamics_options: tolerance %g (in (0, 1)) or cg_iterations "
                              "%d (>= 1) out of range",
                              (double)o->tolerance, o->cg_iterations);
        p = *o;
        p.size = sizeof p;
    }
    pose_status s = enable(st, "pose_set_dynamics_options");
    if (s < 0)
        return s;
    st->dyn_options = p;
    return POSE_OK;
}

pose_status pose_reset_dynamics(pose_state *st)
{
    pose__clear_error();
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_reset_dynamics: state is NULL");
    const int fresh = st->dyn_block == NULL;
    pose_status s = enable(st, "pose_reset_dynamics");
    if (s < 0)
        return s;
    if (!fresh)
        restart(st);
    pose__state_transfer_pass(st);
    pose__state_push(st); /* with the contact response on, as pose_apply */
    return POSE_OK;
}

/* The contact response between the solve and the integration
 * (contact_dyn.c). */
static void constrain(void *ctx)
{
    pose_state *st = ctx;
    pose__state_contact_step(st, st->push->step_dt);
}

pose_status pose_step(pose_state *st, double dt)
{
    pose__clear_error();
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_step: state is NULL");
    if (!(dt > 0.0 && dt <= 1.0))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_step: dt %g is not in (0, 1] s", dt);
    pose_status s = enable(st, "pose_step");
    if (s < 0)
        return s;
    /* With the contact response on, its nodes (the first such step). */
    pose__push *push = st->push && st->push_enabled ? st->push : NULL;
    if (push && !push->nodes_built && (s = pose__push_build_nodes(push, st)) < 0)
        return s;
    const pose_dynamics_options *o = &st->dyn_options;
    pose__fem_dyn_params prm = {
        .dt = (float)dt, .alpha = o->mass_damping, .beta = o->stiffness_damping,
        .coupling = o->coupling_stiffness, .tolerance = o->tolerance,
        .cg_iterations = o->cg_iterations,
        .gravity = {o->gravity[0], o->gravity[1], o->gravity[2]},
        .constrain = push ? constrain : NULL, .constrain_ctx = st,
        .joint_q = st->palette[0].q, /* skeletal tets' rotations (state_dyn_outside.c) */
    };
    if (push)
        push->step_dt = (float)dt;
    pose_dynamics_stats *ds = &st->dyn_stats;
    const double t0 = pose__seconds();
    pose__state_skin_pass(st); /* the bones' positions at the end of the step */
    prm.spring = pose__state_couplings_bones(st); /* and the couplings' (state_coupling.c) */
    prm.links = pose__state_links(st);             /* soft-soft couplings (state_links.c) */
    pose__fem_dyn_contact rests;
    if (push) { /* resting contacts, where the bones end (contact_dyn.c) */
        pose__state_contact_rests(st, (float)dt, &rests);
        prm.contact = &rests;
    }
    const double t1 = pose__seconds();
    pose__fem_dyn_stats fs;
    pose__fem_dyn_step(&st->rt->fem, &st->fem_work, &st->dyn, st->pool, &prm, st->tet_positions,
                       &fs);
    memcpy(st->tet_positions, st->dyn.x, 3 * st->rig->tet_vertex_count * sizeof(float));
    const double t2 = pose__seconds();
    pose__state_transfer_pass(st);
    const double t3 = pose__seconds();
    if (push && !push->step_keeps_skin)
        pose__state_push(st); /* the skin out of bone, as pose_apply leaves it (contact_push.c) */
    ds->size = sizeof *ds;
    ds->islands = (int)st->dyn.island_count;
    ds->cg_iterations = fs.cg_iterations;
    ds->residual = fs.residual;
    ds->kinetic_energy = fs.kinetic_energy;
    ds->time += dt;
    ds->seconds_skin = t1 - t0;
    ds->seconds_assembly = t2 - t1 - fs.seconds_cg; /* with the copy to the outputs */
    ds->seconds_cg = fs.seconds_cg;
    ds->seconds_transfer = t3 - t2;
    ds->contacts = 0;
    ds->contact_iterations = 0;
    ds->max_impulse = 0.0;
    ds->seconds_contact = fs.seconds_constrain + (pose__seconds() - t3);
    ds->seconds_assembly -= fs.seconds_constrain;
    for (size_t k = 0; push && k < POSE__PUSH_ITEMS; k++) {
        ds->contacts += (int)push->constraints[k];
        ds->contact_iterations =
            push->sweeps[k] > ds->contact_iterations ? push->sweeps[k] : ds->contact_iterations;
        ds->max_impulse = fmax(ds->max_impulse, (double)push->max_impulse[k]);
    }
    return POSE_OK;
}

pose_status pose_get_dynamics_stats(const pose_state *st, pose_dynamics_stats *out)
{
    pose__clear_error();
    if (!st || !out)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_get_dynamics_stats: state and out are required");
    if (out->size < POSE_DYNAMICS_STATS_SIZE_0_2)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_get_dynamics_stats: out->size %zu is below the 0.2 layout (%zu)",
                          out->size, (size_t)POSE_DYNAMICS_STATS_SIZE_0_2);
    /* a caller built before the contact fields gets the fields it has */
    const size_t size = out->size < sizeof(pose_dynamics_stats) ? out->size : sizeof(pose_dynamics_stats);
    memcpy(out, &st->dyn_stats, size);
    out->size = size;
    return POSE_OK;
}

double pose__state_dynamics_bytes(const pose_state *st, double cg_iterations)
{
    return (double)pose__state_frame_bytes(st) + pose__fem_dyn_bytes(&st->rt->fem, cg_iterations) +
           24.0 * (double)st->rig->tet_vertex_count;
}
