/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness: the BVH reader, then FK of every frame of what it accepts. */
#include <stdint.h>
#include <stdlib.h>

#include "mocap.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pb_clip *c;
    pb_error err;
    if (pb_bvh_parse((const char *)data, size, "fuzz.bvh", &c, &err) != POSE_OK)
        return 0;
    size_t n = (size_t)c->joint_count;
    double *scratch = malloc(n * 14 * sizeof *scratch);
    if (scratch) {
        for (size_t f = 0; f < c->frame_count && f < 64; f++)
            pb_clip_fk(c, pb_clip_frame(c, f), scratch, (double (*)[4])(scratch + 7 * n),
                       (double (*)[3])(scratch + 11 * n));
        free(scratch);
    }
    pb_clip_free(c);
    return 0;
}
