/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge replay --method: what the host does with each fresh pose.
 * lbs, dqs, cor and fem (spelled as pose-render's and pose-export's
 * --method) run pose_apply with that method; dynamics runs pose_step on the
 * recording's clock instead: each fresh pose advances the simulation by the
 * recorded time since the last one. Figures for --json. */
#ifndef POSE_BRIDGE_CLI_REPLAY_METHOD_H
#define POSE_BRIDGE_CLI_REPLAY_METHOD_H

#include <stdio.h>

#include "pose/bridge.h"
#include "pose/pose.h"

/** The method's names, as --help and the messages list them. */
#define PB_REPLAY_METHODS "lbs, dqs, cor, fem or dynamics"

typedef struct pb_replay_method {
    const char *name;   /**< lbs, dqs, cor, fem, dynamics */
    pose_method method; /**< pose_set_method's (dynamics: POSE_FEM, whose skinning places the bones) */
    int dynamics;       /**< pose_step instead of pose_apply */
    /* figures */
    unsigned long long updates; /**< fresh poses applied (pose_apply or steps toward them) */
    double update_s;            /**< wall seconds in pose_apply / pose_step, summed */
    long long fem_cg;           /**< POSE_FEM: CG iterations, summed over the applies */
    double fem_residual;        /**< POSE_FEM: the last apply's */
    int started;                /**< dynamics: the simulation has started */
    double sim_media_s;         /**< dynamics: recorded time the simulation has reached */
    unsigned long long steps, restarts;
    double simulated_s, kinetic_energy, kinetic_energy_peak;
    int cg_max;
} pb_replay_method;

/** The method named s (NULL: lbs, pose_state's default); 0, or -1 for an unknown name. */
int pb_replay_method_parse(const char *s, pb_replay_method *out);

/** Set the state's method (pose_set_method's status: unsupported without the rig's data). */
pose_status pb_replay_method_start(pb_replay_method *m, pose_state *st);

/** After pose_bridge_apply applied a fresh pose `fr`: pose_apply, or the
 *  steps of dynamics (the first fresh pose starts the simulation at rest). */
pose_status pb_replay_method_update(pb_replay_method *m, pose_state *st, const pose_bridge_frame *fr);

/** ", \"method\": ..." and the method's figures, for the replay's JSON object. */
void pb_replay_method_json(const pb_replay_method *m, FILE *f);

#endif /* POSE_BRIDGE_CLI_REPLAY_METHOD_H */
