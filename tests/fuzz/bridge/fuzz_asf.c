/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness: the ASF reader, then FK of its reference pose. */
#include <stdint.h>
#include <stdlib.h>

#include "mocap.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pb_clip *c;
    pb_error err;
    if (pb_asf_parse((const char *)data, size, "fuzz.asf", &c, &err) != POSE_OK)
        return 0;
    size_t n = (size_t)c->joint_count;
    double *scratch = malloc(n * 14 * sizeof *scratch);
    if (scratch) {
        pb_clip_fk(c, NULL, scratch, (double (*)[4])(scratch + 7 * n), (double (*)[3])(scratch + 11 * n));
        free(scratch);
    }
    pb_clip_free(c);
    return 0;
}
