/* SPDX-License-Identifier: Apache-2.0
 *
 * pp_tetrahedralize: the backend switch, timing and the final checks every
 * backend must pass (labels in range, no inverted tet).
 */
#include "tetmesh.h"
#include "voxelize.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

const char *pp_tet_backend_name(pp_tet_backend b)
{
    switch (b) {
    case PP_TET_DEFAULT:
    case PP_TET_LATTICE:
        return "lattice";
    case PP_TET_TETGEN:
        return "tetgen";
    }
    return "unknown";
}

int pp_tet_backend_parse(const char *name, pp_tet_backend *out)
{
    if (!name || !out)
        return -1;
    if (strcmp(name, "lattice") == 0 || strcmp(name, "builtin") == 0 ||
        strcmp(name, "default") == 0) {
        *out = strcmp(name, "default") == 0 ? PP_TET_DEFAULT : PP_TET_LATTICE;
        return 0;
    }
    if (strcmp(name, "tetgen") == 0) {
        *out = PP_TET_TETGEN;
        return 0;
    }
    return -1;
}

int pp_tet_backend_available(pp_tet_backend b)
{
    switch (b) {
    case PP_TET_DEFAULT:
    case PP_TET_LATTICE:
        return 1;
    case PP_TET_TETGEN:
#ifdef POSE_HAVE_TETGEN
        return 1;
#else
        return 0;
#endif
    }
    return 0;
}

/* Bone labels present in the image but on no tet. */
static size_t lost_labels(const pp_voxels *vox, const pp_tetmesh *t)
{
    uint8_t *seen = calloc(65536, 1);
    if (!seen)
        return 0;
    size_t n = (size_t)vox->nx * vox->ny * vox->nz, lost = 0;
    for (size_t i = 0; i < n; i++)
        if (vox->labels[i] >= PP_VOXEL_BONE0)
            seen[vox->labels[i]] = 1;
    for (size_t i = 0; i < t->tet_count; i++)
        if (t->labels[i] + 1 < 65536)
            seen[t->labels[i] + 1] = 0;
    for (size_t l = PP_VOXEL_BONE0; l < 65536; l++)
        lost += seen[l];
    free(seen);
    return lost;
}

pose_status pp_tetrahedralize(const pp_voxels *vox, const pp_mesh *skin,
                              const pp_tet_options *opt, pp_tetmesh *out, pp_tet_quality *q,
                              char *err, size_t errlen)
{
    if (!out)
        return POSE_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    if (q)
        memset(q, 0, sizeof *q);
    if (!vox || !vox->labels || vox->nx <= 0 || vox->ny <= 0 || vox->nz <= 0) {
        if (err && errlen)
            snprintf(err, errlen, "tetrahedralize: no voxel image");
        return POSE_ERR_INVALID_ARGUMENT;
    }
    pp_tet_options def = {0};
    if (!opt)
        opt = &def;
    pp_tet_backend b = opt->backend == PP_TET_DEFAULT ? PP_TET_LATTICE : opt->backend;
    if (!pp_tet_backend_available(b)) {
        if (err && errlen)
            snprintf(err, errlen,
                     "tetrahedralize: backend '%s' is not in this build (configure with "
                     "-DPOSE_WITH_TETGEN=ON and libtet1.5-dev)",
                     pp_tet_backend_name(b));
        return POSE_ERR_UNSUPPORTED;
    }
    double t0 = pp_now_s();
    pose_status s = b == PP_TET_TETGEN ? pp_tet_tetgen(vox, skin, opt, out, err, errlen)
                                       : pp_tet_lattice(vox, skin, opt, out, err, errlen);
    if (s != POSE_OK)
        return s;
    double secs = pp_now_s() - t0;
    pp_tet_quality local;
    pp_tet_quality *qq = q ? q : &local;
    pp_tet_quality_measure(out, qq);
    qq->seconds = secs;
    qq->labels_lost = lost_labels(vox, out);
    if (qq->inverted_count) {
        if (err && errlen)
            snprintf(err, errlen, "tetrahedralize (%s): %zu of %zu tets are inverted or flat",
                     pp_tet_backend_name(b), qq->inverted_count, out->tet_count);
        pp_tetmesh_free(out);
        return POSE_ERR_INVALID_DATA;
    }
    return POSE_OK;
}

#ifndef POSE_HAVE_TETGEN
/* Built without TetGen (POSE_WITH_TETGEN=OFF): the backend reports itself missing. */
pose_status pp_tet_tetgen(const pp_voxels *vox, const pp_mesh *skin, const pp_tet_options *opt,
                          pp_tetmesh *out, char *err, size_t errlen)
{
    (void)vox;
    (void)skin;
    (void)opt;
    if (out)
        memset(out, 0, sizeof *out);
    if (err && errlen)
        snprintf(err, errlen, "tetrahedralize: pose-bake was built without TetGen");
    return POSE_ERR_UNSUPPORTED;
}
#endif
