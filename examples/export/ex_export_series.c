/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_export_series.h"

#include <stdio.h>

#include "ex_gltf.h"
#include "ex_vtk.h"

int ex_export_series_run(ex_scene *sc, ex_motion *m, ex_export_series *o, char *err, size_t err_size)
{
    ex_vtk_series *vtk = NULL;
    ex_gltf_session *gltf = NULL;
    int rc = -1;
    double t0 = 0.0;
    o->apply_ms = 0.0;
    if (o->count == 0) {
        snprintf(err, err_size, "no frames to export");
        return -1;
    }
    if (o->pvd && ex_vtk_series_begin(o->pvd, &vtk, err, err_size) < 0)
        goto done;
    if (o->anim && ex_gltf_session_begin(sc->rig, &gltf, err, err_size) < 0)
        goto done;
    for (size_t i = 0; i < o->count; i++) {
        double t;
        if (o->frames) {
            t = (double)o->frames[i] * ex_motion_frame_time(m);
            if (ex_motion_set_frame(m, sc->state, o->frames[i], err, err_size) < 0)
                goto done;
        } else {
            t = o->times[i];
            if (ex_motion_set_time(m, sc->state, t, err, err_size) < 0)
                goto done;
        }
        if (ex_scene_apply(sc, err, err_size) < 0)
            goto done;
        o->apply_ms += sc->last_apply_ms;
        if (i == 0)
            t0 = t;
        /* the animation starts at 0 whatever frame the export starts at */
        if (gltf && ex_gltf_session_add(gltf, sc->state, t - t0, err, err_size) < 0)
            goto done;
        if (vtk && ex_vtk_series_add(vtk, sc->state, t, err, err_size) < 0)
            goto done;
        if (i == 0)
            o->first_s = t;
        o->last_s = t;
    }
    if (vtk && ex_vtk_series_finish(vtk, err, err_size) < 0)
        goto done;
    if (gltf) {
        o->meshes = ex_gltf_session_mesh_count(gltf);
        if (ex_gltf_session_write(gltf, o->anim, err, err_size) < 0)
            goto done;
    }
    rc = 0;
done:
    ex_vtk_series_free(vtk);
    ex_gltf_session_free(gltf);
    return rc;
}
