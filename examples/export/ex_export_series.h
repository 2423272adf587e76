/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-export's multi-frame outputs: pose a state at each frame or time of
 * a source (through the bridge, ex_motion) and write every pose into a
 * ParaView series (.pvd of tissue-surface .vtu files) and/or an animated
 * glTF (.glb: skinned skin and bones, the session's joint animation).
 */
#ifndef POSE_EX_EXPORT_SERIES_H
#define POSE_EX_EXPORT_SERIES_H

#include <stddef.h>

#include "ex_motion.h"
#include "ex_scene.h"

typedef struct ex_export_series {
    const long *frames;   /* clip frames, or NULL */
    const double *times;  /* seconds of recorded time (when frames is NULL) */
    size_t count;
    const char *pvd;      /* the collection to write, or NULL */
    const char *anim;     /* the animated .glb to write, or NULL */
    /* results */
    double first_s, last_s; /* times of the first and last pose */
    size_t meshes;          /* skinned meshes in the .glb */
    double apply_ms;        /* pose_apply over all frames */
} ex_export_series;

/** Pose and write every frame. Returns 0, or -1 with a message in err. */
int ex_export_series_run(ex_scene *sc, ex_motion *m, ex_export_series *o, char *err, size_t err_size);

#endif
