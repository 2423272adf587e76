/* SPDX-License-Identifier: Apache-2.0 */
/* The `fem` section (soft tissue's material for POSE_FEM): what a record
 * must satisfy, and the queries. */
#include <math.h>
#include <string.h>

#include "error.h"
#include "rig_io.h"
#include "rig_runtime.h"

pose_status pose__fem_validate(const pose_rig *rig, const pose__source *src)
{
    const pose__fem_record *r = rig->fem;
    if (!r)
        return POSE_OK;
    if (!isfinite(r->young) || !(r->young > 0.0f))
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, "fem", &r->young,
                                 "Young's modulus %g (finite and > 0)", (double)r->young);
    if (!(r->poisson >= 0.0f && r->poisson < 0.5f))
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, "fem", &r->poisson,
                                 "Poisson's ratio %g (in [0, 0.5))", (double)r->poisson);
    if (!isfinite(r->density) || !(r->density >= 0.0f))
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, "fem", &r->density,
                                 "density %g (finite and >= 0)", (double)r->density);
    if (r->flags != 0)
        return pose__source_fail(src, POSE_ERR_INVALID_DATA, "fem", &r->flags,
                                 "unknown flags 0x%x", (unsigned)r->flags);
    for (size_t i = 0; i < sizeof r->reserved; i++)
        if (r->reserved[i])
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, "fem", &r->reserved[i],
                                     "reserved bytes are not zero");
    return POSE_OK;
}

int pose_rig_has_fem(const pose_rig *rig)
{
    return rig && rig->fem && rig->rt && rig->rt->fem_size; /* the mesh itself is built on first use */
}

pose_status pose_rig_fem_material(const pose_rig *rig, pose_fem_material *out)
{
    pose__clear_error();
    if (!rig || !out)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_rig_fem_material: rig and out are required");
    if (!rig->fem)
        return pose__fail(POSE_ERR_UNSUPPORTED, "the rig has no fem section (bake it with "
                                                "pose-bake's defaults or give pose_rig_desc.fem)");
    out->young_modulus = rig->fem->young;
    out->poisson_ratio = rig->fem->poisson;
    out->density = rig->fem->density;
    return POSE_OK;
}
