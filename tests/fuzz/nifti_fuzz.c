/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for the tools' NIfTI reader (volume/: header checks,
 * then nifticlib). The input is written to a scratch file (.nii, or
 * .nii.gz when it starts with the gzip magic) and read back. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "vol_nifti.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char path[256];
    const int gz = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
    const char *dir = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/pose_fuzz_nifti_%ld.%s", dir ? dir : "/tmp", (long)getpid(),
             gz ? "nii.gz" : "nii");
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    if (size && fwrite(data, 1, size, f) != size) {
        fclose(f);
        return 0;
    }
    fclose(f);
    pv_image img;
    char err[512] = "";
    if (pv_nifti_read(path, &img, err, sizeof err) == 0) {
        size_t n = pv_image_voxels(&img);
        if (n == 0 || !img.data)
            __builtin_trap();
        volatile float sum = 0;
        for (size_t i = 0; i < n; i++)
            sum += img.data[i];
        (void)sum;
        pv_image_free(&img);
    } else if (!strstr(err, path)) {
        __builtin_trap(); /* every failure names the file */
    }
    unlink(path);
    return 0;
}
