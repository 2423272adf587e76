/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for the calibration rewrite (hid-calibrate and
 * can-calibrate, bridge/src/core/calibrate.c): the input is a mapping file.
 * A two-point calibration of entry 0 and the neutral offsets of every entry
 * are written into it; what the rewrite produces must be JSON that gives the
 * entry back, and a mapping the parser accepted must stay one it accepts. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "calibrate.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char *scratch_path(void)
{
    static char path[512];
    if (!path[0]) {
        const char *dir = getenv("TMPDIR");
        snprintf(path, sizeof path, "%s/pose_fuzz_calibrate_%ld.json", dir && *dir ? dir : "/tmp", (long)getpid());
    }
    return path;
}

static int write_file(const char *path, const uint8_t *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    const int ok = fwrite(data, 1, size, f) == size;
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* The rewritten file is JSON whose "channels" entry 0 holds the calibration written. */
static void check_two_point(const char *path, const double raw[2], const double deg[2])
{
    char *text;
    size_t n;
    pb_error err;
    if (pb_read_file(path, (size_t)16 << 20, &text, &n, &err) != POSE_OK)
        abort();
    cJSON *root = cJSON_ParseWithLength(text, n);
    if (!root)
        abort();
    const cJSON *e = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, "channels"), 0);
    const cJSON *cal = cJSON_GetObjectItemCaseSensitive(e, "calibration");
    const cJSON *r = cJSON_GetObjectItemCaseSensitive(cal, "raw"), *d = cJSON_GetObjectItemCaseSensitive(cal, "deg");
    if (cJSON_GetArraySize(r) != 2 || cJSON_GetArraySize(d) != 2 ||
        cJSON_GetArrayItem(r, 0)->valuedouble != raw[0] || cJSON_GetArrayItem(r, 1)->valuedouble != raw[1] ||
        cJSON_GetArrayItem(d, 0)->valuedouble != deg[0] || cJSON_GetArrayItem(d, 1)->valuedouble != deg[1])
        abort();
    cJSON_Delete(root);
    free(text);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = scratch_path();
    pb_error err;
    if (write_file(path, data, size) != 0)
        return 0;
    char channel[64];
    uint32_t usage;
    int usage_index;
    (void)pb_calibrate_entry(path, NULL, 0, channel, sizeof channel, &usage, &usage_index, &err);
    const double raw[2] = {512, 3584}, deg[2] = {0, 150};
    if (pb_calibrate_write(path, NULL, 0, raw, deg, &err) == POSE_OK)
        check_two_point(path, raw, deg);

    pb_mapping *m = NULL;
    if (pb_mapping_parse((const char *)data, size, "fuzz.json", &m, &err) == POSE_OK && m->channel_count > 0 &&
        write_file(path, data, size) == 0) {
        double *neutral = malloc((size_t)m->channel_count * sizeof *neutral);
        if (neutral) {
            for (int i = 0; i < m->channel_count; i++)
                neutral[i] = 100.0 * i - 1000.0;
            int written = 0;
            if (pb_calibrate_write_neutral(path, m, neutral, &written, &err) == POSE_OK) {
                pb_mapping *again = NULL;
                if (pb_mapping_load(path, &again, &err) != POSE_OK) {
                    fprintf(stderr, "calibrated mapping refused: %s\n", err.message);
                    abort();
                }
                pb_mapping_free(again);
            }
            free(neutral);
        }
    }
    pb_mapping_free(m);
    remove(path);
    return 0;
}
