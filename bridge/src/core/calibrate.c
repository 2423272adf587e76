/* SPDX-License-Identifier: Apache-2.0 */
#include "hid_calibrate.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

pose_status pb_calibrate_measure(pb_source *src, uint32_t channel, int samples, int timeout_ms, double *mean,
                                 pb_error *err)
{
    double sum = 0;
    int n = 0;
    while (n < samples) {
        pb_update u;
        int r = pb_source_read(src, &u, timeout_ms);
        if (r < 0)
            return pb_fail(err, POSE_ERR_IO, "calibration: source stopped: %s", src->message);
        if (r == 0)
            return pb_fail(err, POSE_ERR_IO, "calibration: no report within %d ms (%s)", timeout_ms, src->message);
        for (size_t i = 0; i < u.count; i++)
            if (u.channels[i] == channel) {
                sum += u.values[i];
                n++;
            }
    }
    *mean = samples > 0 ? sum / samples : 0.0;
    return POSE_OK;
}

static pose_status load_json(const char *path, cJSON **root, cJSON **entry, const char *name, int index,
                             pb_error *err)
{
    char *text;
    size_t size;
    pose_status st = pb_read_file(path, (size_t)16 << 20, &text, &size, err);
    if (st != POSE_OK)
        return st;
    *root = cJSON_ParseWithLength(text, size);
    if (!*root) {
        const char *at = cJSON_GetErrorPtr();
        long off = at && at >= text && at <= text + size ? (long)(at - text) : -1;
        free(text);
        return pb_fail(err, POSE_ERR_FORMAT, "%s: invalid JSON near byte %ld", path, off);
    }
    free(text);
    cJSON *chans = cJSON_GetObjectItemCaseSensitive(*root, "channels");
    if (!cJSON_IsArray(chans)) {
        cJSON_Delete(*root);
        return pb_fail(err, POSE_ERR_FORMAT, "%s: no \"channels\" array", path);
    }
    int i = 0;
    cJSON *e;
    cJSON_ArrayForEach(e, chans)
    {
        cJSON *c = cJSON_GetObjectItemCaseSensitive(e, "channel");
        if (name ? (cJSON_IsString(c) && strcmp(c->valuestring, name) == 0) : i == index) {
            *entry = e;
            return POSE_OK;
        }
        i++;
    }
    cJSON_Delete(*root);
    if (name)
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no \"channels\" entry for channel \"%s\"", path, name);
    return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no \"channels\" entry %d (there are %d)", path, index, i);
}

pose_status pb_calibrate_entry(const char *map_path, const char *name, int index, char *channel, size_t size,
                               uint32_t *usage, int *usage_index, pb_error *err)
{
    cJSON *root, *e;
    pose_status st = load_json(map_path, &root, &e, name, index, err);
    if (st != POSE_OK)
        return st;
    cJSON *c = cJSON_GetObjectItemCaseSensitive(e, "channel");
    cJSON *u = cJSON_GetObjectItemCaseSensitive(e, "usage");
    cJSON *ui = cJSON_GetObjectItemCaseSensitive(e, "index");
    channel[0] = '\0';
    *usage = 0;
    *usage_index = cJSON_IsNumber(ui) ? ui->valueint : 0;
    if (cJSON_IsString(c))
        snprintf(channel, size, "%s", c->valuestring);
    else if (cJSON_IsString(u))
        *usage = (uint32_t)strtoul(u->valuestring, NULL, 0);
    else if (cJSON_IsNumber(u))
        *usage = (uint32_t)u->valuedouble;
    else
        st = pb_fail(err, POSE_ERR_FORMAT, "%s: entry has neither \"channel\" nor \"usage\"", map_path);
    cJSON_Delete(root);
    return st;
}

pose_status pb_calibrate_write(const char *map_path, const char *name, int index, const double raw[2],
                               const double deg[2], pb_error *err)
{
    if (raw[0] == raw[1])
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT,
                       "calibration: both positions read %g; the channel does not follow the joint", raw[0]);
    cJSON *root, *e;
    pose_status st = load_json(map_path, &root, &e, name, index, err);
    if (st != POSE_OK)
        return st;
    cJSON *cal = cJSON_CreateObject();
    cJSON *r = cJSON_CreateDoubleArray(raw, 2), *d = cJSON_CreateDoubleArray(deg, 2);
    if (!cal || !r || !d) {
        cJSON_Delete(cal);
        cJSON_Delete(r);
        cJSON_Delete(d);
        cJSON_Delete(root);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "calibration: out of memory");
    }
    cJSON_AddItemToObject(cal, "raw", r);
    cJSON_AddItemToObject(cal, "deg", d);
    if (cJSON_GetObjectItemCaseSensitive(e, "calibration"))
        cJSON_ReplaceItemInObjectCaseSensitive(e, "calibration", cal);
    else
        cJSON_AddItemToObject(e, "calibration", cal);
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    if (!text)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "calibration: out of memory");
    char tmp[1100];
    snprintf(tmp, sizeof tmp, "%s.tmp", map_path);
    FILE *f = fopen(tmp, "w");
    int bad = !f || fputs(text, f) == EOF || fputc('\n', f) == EOF;
    if (f)
        bad |= fclose(f) != 0;
    free(text);
    if (bad || rename(tmp, map_path) != 0) {
        remove(tmp);
        return pb_fail(err, POSE_ERR_IO, "%s: cannot write the updated mapping", map_path);
    }
    return POSE_OK;
}
