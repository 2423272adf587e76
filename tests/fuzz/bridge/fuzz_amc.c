/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness: AMC frames against the CMU subject 01 skeleton (an
 * excerpt of data/mocap/cmu-asf-amc/01.asf compiled in, so the fuzzer
 * mutates only the motion). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mocap.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char ASF[] =
    ":version 1.10\n:name VICON\n:units\n  mass 1.0\n  length 0.45\n  angle deg\n"
    ":root\n   order TX TY TZ RX RY RZ\n   axis XYZ\n   position 0 0 0\n   orientation 0 0 0\n"
    ":bonedata\n"
    "  begin\n id 1\n name lhipjoint\n direction 0.566809 -0.746272 0.349008\n length 2.40479\n axis 0 0 0 XYZ\n end\n"
    "  begin\n id 2\n name lfemur\n direction 0.34202 -0.939693 0\n length 7.1578\n axis 0 0 20 XYZ\n"
    "  dof rx ry rz\n limits (-160.0 20.0)\n (-70.0 70.0)\n (-60.0 70.0)\n end\n"
    "  begin\n id 3\n name ltibia\n direction 0.34202 -0.939693 0\n length 7.49137\n axis 0 0 20 XYZ\n"
    "  dof rx\n limits (-10.0 170.0)\n end\n"
    "  begin\n id 4\n name lowerback\n direction 0.0 1 0\n length 2.0\n axis 0 0 0 XYZ\n"
    "  dof rx ry rz\n limits (-20 45)\n (-30 30)\n (-30 30)\n end\n"
    ":hierarchy\n  begin\n    root lhipjoint lowerback\n    lhipjoint lfemur\n    lfemur ltibia\n  end\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static pb_clip *skel;
    pb_error err;
    if (!skel && pb_asf_parse(ASF, strlen(ASF), "fuzz.asf", &skel, &err) != POSE_OK)
        abort(); /* the built-in skeleton must parse */
    if (pb_amc_parse(skel, (const char *)data, size, "fuzz.amc", &err) != POSE_OK)
        return 0;
    size_t n = (size_t)skel->joint_count;
    double *scratch = malloc(n * 14 * sizeof *scratch);
    if (scratch) {
        for (size_t f = 0; f < skel->frame_count && f < 64; f++)
            pb_clip_fk(skel, pb_clip_frame(skel, f), scratch, (double (*)[4])(scratch + 7 * n),
                       (double (*)[3])(scratch + 11 * n));
        free(scratch);
    }
    return 0;
}
