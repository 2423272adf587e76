/* SPDX-License-Identifier: Apache-2.0 */
/* POSE_FEM on a state: solver settings, statistics, the solver's work
 * arrays, and the refinement pose_apply runs between skinning and
 * transfer. */
#include <math.h>
#include <string.h>

#include "alloc.h"
#include "error.h"
#include "rt_thread.h"
#include "state_internal.h"

double pose__seconds(void)
{
    return 1e-9 * (double)pose__now_ns();
}

int pose__state_skin_method(const pose_state *st)
{
    if (st->method != POSE_FEM)
        return (int)st->method;
    /* Refinement starts from the best skinning the rig allows: the closer
     * the start, the fewer iterations (CoR already keeps most volume). */
    return st->rig->cor ? POSE__SKIN_COR : POSE__SKIN_DQS;
}

void pose__state_fem_defaults(pose__fem_params *out)
{
    /* Enough for the volume (the skin's, held by its own term, stays within
     * 0.15 % on the baked body at 120-150 degrees), not a tight residual:
     * each further outer iteration moves the skin by well under a
     * millimetre and costs as much as the first. */
    *out = (pose__fem_params){.outer_iterations = 2, .cg_iterations = 200, .tolerance = 0.05f};
}

pose_status pose_set_fem_options(pose_state *st, const pose_fem_options *o)
{
    pose__clear_error();
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_fem_options: state is NULL");
    pose__fem_params p;
    pose__state_fem_defaults(&p);
    if (o) {
        if (o->size != 0 && o->size < sizeof(pose_fem_options))
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "pose_set_fem_options: options.size %zu is below the 0.2 layout (%zu)",
                              o->size, sizeof(pose_fem_options));
        if (o->outer_iterations < 0 || o->cg_iterations < 0)
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "pose_set_fem_options: iteration counts must be >= 0 (%d, %d)",
                              o->outer_iterations, o->cg_iterations);
        if (!(o->tolerance >= 0.0f && o->tolerance < 1.0f))
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "pose_set_fem_options: tolerance %g is not in [0, 1)",
                              (double)o->tolerance);
        for (int a = 0; a < 3; a++)
            if (!isfinite(o->gravity[a]))
                return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                                  "pose_set_fem_options: gravity is not finite");
        if (o->outer_iterations)
            p.outer_iterations = o->outer_iterations;
        if (o->cg_iterations)
            p.cg_iterations = o->cg_iterations;
        if (o->tolerance > 0.0f)
            p.tolerance = o->tolerance;
        memcpy(p.gravity, o->gravity, sizeof p.gravity);
    }
    st->fem_params = p;
    return POSE_OK;
}

pose_status pose_get_fem_stats(const pose_state *st, pose_fem_stats *out)
{
    pose__clear_error();
    if (!st || !out)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_get_fem_stats: state and out are required");
    if (out->size < sizeof(pose_fem_stats))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_get_fem_stats: out->size %zu is below the 0.2 layout (%zu)",
                          out->size, sizeof(pose_fem_stats));
    *out = st->fem_stats;
    out->size = sizeof(pose_fem_stats);
    return POSE_OK;
}

pose_status pose__state_fem_work(pose_state *st, const char *fn)
{
    if (st->fem_block)
        return POSE_OK;
    pose_status s = pose__rig_fem_mesh(st->rig, fn); /* the rig's simulation mesh (rig_prepare.c) */
    if (s < 0)
        return s;
    const size_t size = pose__fem_work_size(&st->rt->fem);
    st->fem_block = pose__alloc(&st->allocator, size, POSE__ALIGN);
    if (!st->fem_block)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "%s: out of memory for the FEM solver's work (%zu bytes)", fn,
                          size);
    pose__fem_work_init(&st->rt->fem, st->fem_block, &st->fem_work);
    return POSE_OK;
}

void pose__state_fem_refine(pose_state *st)
{
    pose__fem_stats s;
    pose__fem_params prm = st->fem_params;
    /* Couplings (state_coupling.c; NULL without): coupled nodes start at
     * their springs' ends, so that the first residual, which the
     * tolerance is relative to, is the tissue's, not the springs' pull
     * from the skinned pose (100 times as stiff: CG stopped after 2
     * iterations on the body at knee flexion 120 and the skin lost
     * 0.22 % of its volume, 0.03 % when started at the ends). */
    prm.spring = pose__state_couplings_bones(st);
    prm.target = st->cpl_target;
    prm.links = pose__state_links(st); /* soft-soft couplings (state_links.c) */
    pose__fem_solve(&st->rt->fem, &st->fem_work, st->pool, &prm, st->tet_positions, &s);
    st->fem_stats.outer_iterations = s.outer_iterations;
    st->fem_stats.cg_iterations = s.cg_iterations;
    st->fem_stats.residual = s.residual;
    st->fem_stats.seconds_rotations = s.seconds_rotations;
    st->fem_stats.seconds_cg = s.seconds_cg;
}
