/* SPDX-License-Identifier: Apache-2.0 */
/* pose_rig_tissue_embedding: the tet and barycentric coordinates of every
 * tissue vertex, as stored in the rig. */
#include "error.h"
#include "rig_internal.h"

pose_status pose_rig_tissue_embedding(const pose_rig *rig, int tissue, const uint32_t **tet, const float **bary)
{
    pose__clear_error();
    if (!rig || !tet || !bary || tissue < 0 || (size_t)tissue >= rig->tissue_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_rig_tissue_embedding: tissue %d out of range "
                          "(%zu tissues) or NULL argument", tissue, rig ? rig->tissue_count : 0);
    *tet = rig->tissues[tissue].tet;
    *bary = rig->tissues[tissue].bary;
    return POSE_OK;
}
