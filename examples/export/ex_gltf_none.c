/* SPDX-License-Identifier: Apache-2.0
 * ex_gltf for builds without cJSON: pose-export refuses --glb and --gltf-anim and says why. */
#include "ex_gltf.h"

#include <stdio.h>

int ex_gltf_available(void)
{
    return 0;
}

static int none(char *err, size_t err_size)
{
    snprintf(err, err_size, "built without cJSON: no glTF");
    return -1;
}

int ex_gltf_write_posed(const pose_state *st, const char *path, char *err, size_t err_size)
{
    (void)st, (void)path;
    return none(err, err_size);
}

int ex_gltf_session_begin(const pose_rig *rig, ex_gltf_session **out, char *err, size_t err_size)
{
    (void)rig;
    *out = NULL;
    return none(err, err_size);
}

int ex_gltf_session_add(ex_gltf_session *s, const pose_state *st, double t_s, char *err, size_t err_size)
{
    (void)s, (void)st, (void)t_s;
    return none(err, err_size);
}

int ex_gltf_session_write(const ex_gltf_session *s, const char *path, char *err, size_t err_size)
{
    (void)s, (void)path;
    return none(err, err_size);
}

void ex_gltf_session_free(ex_gltf_session *s)
{
    (void)s;
}

size_t ex_gltf_session_mesh_count(const ex_gltf_session *s)
{
    (void)s;
    return 0;
}
