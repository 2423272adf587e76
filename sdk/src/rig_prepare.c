/* SPDX-License-Identifier: Apache-2.0 */
/* Runtime-derived rig data. Stub: the runtime replaces this file. */
#include "rig_internal.h"

pose_status pose__rig_prepare(pose_rig *rig)
{
    rig->rt = NULL;
    return POSE_OK;
}

void pose__rig_release(pose_rig *rig)
{
    rig->rt = NULL;
}
