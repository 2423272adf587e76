/* SPDX-License-Identifier: Apache-2.0
 * pose-export built without libnifti: --nifti is refused with the reason. */
#include "ex_volume_nifti.h"

#include <stdio.h>

int ex_volume_nifti_available(void)
{
    return 0;
}

int ex_volume_write_nifti(const pose_state *state, const char *prefix, int pad, int *written,
                          char *err, size_t n)
{
    (void)state, (void)prefix, (void)pad;
    *written = 0;
    snprintf(err, n, "--nifti: this build writes no NIfTI (apt-get install libnifti2-dev)");
    return -1;
}
