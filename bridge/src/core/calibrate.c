/* SPDX-License-Identifier: Apache-2.0 */
#include "calibrate.h"

#include <cjson/cJSON.h>
#include <math.h>
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
    /* The file is rewritten from what is parsed: text after the first JSON
     * value would be lost, so it is an error like any other. */
    const char *end = NULL;
    *root = cJSON_ParseWithLengthOpts(text, size, &end, 0);
    while (*root && end < text + size && (*end == ' ' || *end == '\t' || *end == '\r' || *end == '\n'))
        end++;
    if (!*root || end != text + size) {
        const int trailing = *root != NULL;
        const char *at = trailing ? end : cJSON_GetErrorPtr();
        long off = at && at >= text && at <= text + size ? (long)(at - text) : -1;
        cJSON_Delete(*root);
        free(text);
        return pb_fail(err, POSE_ERR_FORMAT, "%s: invalid JSON near byte %ld%s", path, off,
                       trailing ? " (text after the JSON value)" : "");
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
            if (!cJSON_IsObject(e)) { /* a calibration set on it would not be written */
                cJSON_Delete(*root);
                return pb_fail(err, POSE_ERR_FORMAT, "%s: \"channels\" entry %d is not an object", path, i);
            }
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

/* The JSON object {"raw": [r0, r1], "deg": [d0, d1]}, or NULL (out of memory). */
static cJSON *two_point(const double raw[2], const double deg[2])
{
    cJSON *cal = cJSON_CreateObject();
    cJSON *r = cJSON_CreateDoubleArray(raw, 2), *d = cJSON_CreateDoubleArray(deg, 2);
    if (!cal || !r || !d) {
        cJSON_Delete(cal);
        cJSON_Delete(r);
        cJSON_Delete(d);
        return NULL;
    }
    cJSON_AddItemToObject(cal, "raw", r);
    cJSON_AddItemToObject(cal, "deg", d);
    return cal;
}

static void set_calibration(cJSON *entry, cJSON *cal)
{
    if (cJSON_GetObjectItemCaseSensitive(entry, "calibration"))
        cJSON_ReplaceItemInObjectCaseSensitive(entry, "calibration", cal);
    else
        cJSON_AddItemToObject(entry, "calibration", cal);
}

/* Replace the file with root's text, atomically (rename); frees root. */
static pose_status save_json(const char *map_path, cJSON *root, pb_error *err)
{
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
    cJSON *cal = two_point(raw, deg);
    if (!cal) {
        cJSON_Delete(root);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "calibration: out of memory");
    }
    set_calibration(e, cal);
    return save_json(map_path, root, err);
}

/* Source channel an entry binds (as pb_chanmap_create does), or -1. */
static long entry_channel(const pb_source *src, const pb_map_channel *m)
{
    int seen = 0;
    for (size_t k = 0; k < src->channel_count; k++) {
        if (m->channel[0] ? strncmp(src->channels[k].name, m->channel, sizeof src->channels[k].name) == 0
                          : src->channels[k].usage == m->usage && seen++ == m->usage_index)
            return (long)k;
    }
    return -1;
}

pose_status pb_calibrate_measure_entries(pb_source *src, const pb_mapping *map, int samples, int timeout_ms,
                                         double *means, pb_error *err)
{
    if (!src || !map || !means || samples < 1)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_calibrate_measure_entries: bad argument");
    const int n = map->channel_count;
    long *ch = calloc(n > 0 ? (size_t)n : 1, sizeof *ch);
    int *count = calloc(n > 0 ? (size_t)n : 1, sizeof *count);
    if (!ch || !count) {
        free(ch);
        free(count);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "calibration: out of memory");
    }
    int missing = 0;
    for (int i = 0; i < n; i++) {
        ch[i] = entry_channel(src, &map->channels[i]);
        means[i] = ch[i] < 0 ? NAN : 0.0;
        missing += ch[i] >= 0;
    }
    pose_status st = POSE_OK;
    while (missing > 0) {
        pb_update u;
        int r = pb_source_read(src, &u, timeout_ms);
        if (r <= 0) {
            st = pb_fail(err, POSE_ERR_IO, "calibration: %s (%s)",
                         r < 0 ? "the source stopped" : "no sample in time", src->message);
            break;
        }
        for (size_t k = 0; k < u.count; k++)
            for (int i = 0; i < n; i++)
                if (ch[i] == (long)u.channels[k] && count[i] < samples) {
                    means[i] += u.values[k];
                    if (++count[i] == samples)
                        missing--;
                }
    }
    for (int i = 0; i < n; i++)
        if (ch[i] >= 0)
            means[i] = count[i] ? means[i] / count[i] : NAN;
    free(ch);
    free(count);
    return st;
}

/* Degrees per raw unit of an entry's calibration (before inversion). */
static double entry_gain(const pb_map_channel *m)
{
    if (m->calib == PB_CALIB_TWO_POINT)
        return (m->deg[1] - m->deg[0]) / (m->raw[1] - m->raw[0]);
    if (m->calib == PB_CALIB_LINEAR)
        return m->scale;
    return 1.0;
}

pose_status pb_calibrate_write_neutral(const char *map_path, const pb_mapping *map, const double *neutral_raw,
                                       int *written, pb_error *err)
{
    cJSON *root, *first;
    pose_status st = load_json(map_path, &root, &first, NULL, 0, err);
    if (st != POSE_OK)
        return st;
    cJSON *chans = cJSON_GetObjectItemCaseSensitive(root, "channels");
    int i = 0, n = 0;
    cJSON *e;
    cJSON_ArrayForEach(e, chans)
    {
        if (i >= map->channel_count)
            break;
        const pb_map_channel *m = &map->channels[i];
        const double g = entry_gain(m);
        if (cJSON_IsObject(e) && isfinite(neutral_raw[i]) && isfinite(g) && g != 0.0) {
            /* The neutral reading becomes 0 degrees; 90 degrees stays 90 / gain raw units away. */
            const double raw[2] = {neutral_raw[i], neutral_raw[i] + 90.0 / g}, deg[2] = {0.0, 90.0};
            cJSON *cal = two_point(raw, deg);
            if (!cal) {
                cJSON_Delete(root);
                return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "calibration: out of memory");
            }
            set_calibration(e, cal);
            n++;
        }
        i++;
    }
    if (written)
        *written = n;
    return save_json(map_path, root, err);
}
