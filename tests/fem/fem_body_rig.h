/* SPDX-License-Identifier: Apache-2.0 */
/* The body the fem_body_bake fixture bakes from the bundled anatomy, for
 * the tests/fem tests at body scale: its path comes in POSE_FEM_RIG. */
#ifndef POSE_TESTS_FEM_BODY_RIG_H
#define POSE_TESTS_FEM_BODY_RIG_H

#include <stdio.h>
#include <stdlib.h>

#include "pose/pose.h"

/* The rig, or NULL with the reason on stderr (a test's setup fails). */
static inline pose_rig *fem_body_rig_load(void)
{
    const char *path = getenv("POSE_FEM_RIG");
    pose_rig *rig = NULL;
    if (!path || pose_rig_load(path, &rig) != POSE_OK) {
        fprintf(stderr, "cannot load POSE_FEM_RIG=%s: %s\n", path ? path : "(unset)",
                pose_last_error());
        return NULL;
    }
    return rig;
}

#endif /* POSE_TESTS_FEM_BODY_RIG_H */
