/* SPDX-License-Identifier: Apache-2.0 */
#include "can_bus.h"

#include <cjson/cJSON.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct pb_can_bus {
    pb_dbc *dbc;
    pb_canopen_node_config *canopen;
    size_t canopen_count;
    pb_j1939_sensor_config *j1939;
    size_t j1939_count;
    char **channels;
    size_t channel_count;
    uint32_t timeout_ms;
    pb_can_config cfg;
};

static void refresh(pb_can_bus *b)
{
    b->cfg.dbc = b->dbc;
    b->cfg.canopen = b->canopen;
    b->cfg.canopen_count = b->canopen_count;
    b->cfg.j1939 = b->j1939;
    b->cfg.j1939_count = b->j1939_count;
    b->cfg.channels = b->channel_count ? (const char *const *)b->channels : NULL;
    b->cfg.channel_count = b->channel_count;
    b->cfg.timeout_ms = b->timeout_ms;
}

pose_status pb_can_bus_create(const char *dbc_path, pb_can_bus **out, pb_error *err)
{
    *out = NULL;
    pb_can_bus *b = calloc(1, sizeof *b);
    if (!b)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "CAN: out of memory");
    if (dbc_path) {
        pb_dbc_error de;
        if (pb_dbc_load(dbc_path, &b->dbc, &de) != 0) {
            free(b);
            return pb_fail(err, POSE_ERR_FORMAT, "%s", de.message);
        }
    }
    refresh(b);
    *out = b;
    return POSE_OK;
}

void pb_can_bus_free(pb_can_bus *b)
{
    if (!b)
        return;
    pb_dbc_free(b->dbc);
    for (size_t i = 0; i < b->canopen_count; i++)
        free((char *)b->canopen[i].name);
    free(b->canopen);
    for (size_t i = 0; i < b->j1939_count; i++)
        free((char *)b->j1939[i].name);
    free(b->j1939);
    for (size_t i = 0; i < b->channel_count; i++)
        free(b->channels[i]);
    free(b->channels);
    free(b);
}

pose_status pb_can_bus_add_canopen(pb_can_bus *b, const pb_canopen_node_config *node)
{
    pb_canopen_node_config *n = realloc(b->canopen, (b->canopen_count + 1) * sizeof *n);
    if (!n)
        return POSE_ERR_OUT_OF_MEMORY;
    b->canopen = n;
    n[b->canopen_count] = *node;
    n[b->canopen_count].name = node->name ? strdup(node->name) : NULL;
    if (node->name && !n[b->canopen_count].name)
        return POSE_ERR_OUT_OF_MEMORY;
    b->canopen_count++;
    refresh(b);
    return POSE_OK;
}

pose_status pb_can_bus_add_j1939(pb_can_bus *b, const pb_j1939_sensor_config *sensor)
{
    pb_j1939_sensor_config *n = realloc(b->j1939, (b->j1939_count + 1) * sizeof *n);
    if (!n)
        return POSE_ERR_OUT_OF_MEMORY;
    b->j1939 = n;
    n[b->j1939_count] = *sensor;
    n[b->j1939_count].name = sensor->name ? strdup(sensor->name) : NULL;
    if (sensor->name && !n[b->j1939_count].name)
        return POSE_ERR_OUT_OF_MEMORY;
    b->j1939_count++;
    refresh(b);
    return POSE_OK;
}

pose_status pb_can_bus_select(pb_can_bus *b, const char *const *channels, size_t count)
{
    for (size_t i = 0; i < b->channel_count; i++)
        free(b->channels[i]);
    free(b->channels);
    b->channels = NULL;
    b->channel_count = 0;
    if (count) {
        b->channels = calloc(count, sizeof *b->channels);
        if (!b->channels)
            return POSE_ERR_OUT_OF_MEMORY;
        for (size_t i = 0; i < count; i++) {
            b->channels[i] = strdup(channels[i]);
            if (!b->channels[i]) {
                b->channel_count = i;
                refresh(b);
                return POSE_ERR_OUT_OF_MEMORY;
            }
        }
        b->channel_count = count;
    }
    refresh(b);
    return POSE_OK;
}

void pb_can_bus_set_timeout(pb_can_bus *b, uint32_t timeout_ms)
{
    b->timeout_ms = timeout_ms;
    refresh(b);
}

const pb_can_config *pb_can_bus_config(pb_can_bus *b) { return &b->cfg; }
const pb_dbc *pb_can_bus_dbc(const pb_can_bus *b) { return b->dbc; }

/* A non-negative integer member no larger than max; absent gives def. */
static int json_uint(const cJSON *obj, const char *key, double max, uint32_t def, uint32_t *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        *out = def;
        return 1;
    }
    if (!cJSON_IsNumber(v) || v->valuedouble < 0 || v->valuedouble > max ||
        v->valuedouble != (double)(uint32_t)v->valuedouble)
        return 0;
    *out = (uint32_t)v->valuedouble;
    return 1;
}

static const char *json_name(const cJSON *obj)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, "name");
    return cJSON_IsString(v) && v->valuestring[0] ? v->valuestring : NULL;
}

pose_status pb_can_bus_parse(const char *json, size_t len, const char *name, const char *base_dir,
                             pb_can_bus **out, pb_error *err)
{
    *out = NULL;
    cJSON *root = cJSON_ParseWithLength(json, len);
    if (!root) {
        const char *at = cJSON_GetErrorPtr();
        size_t off = at && at >= json && at <= json + len ? (size_t)(at - json) : 0;
        return pb_fail(err, POSE_ERR_FORMAT, "%s: offset %zu: not valid JSON", name, off);
    }
    const cJSON *can = cJSON_GetObjectItemCaseSensitive(root, "can");
    if (!can)
        can = root;
    pose_status st = POSE_OK;
    pb_can_bus *b = NULL;
    if (!cJSON_IsObject(can)) {
        st = pb_fail(err, POSE_ERR_FORMAT, "%s: \"can\" must be an object", name);
        goto done;
    }
    const cJSON *dbc = cJSON_GetObjectItemCaseSensitive(can, "dbc");
    char path[4096];
    if (dbc) {
        if (!cJSON_IsString(dbc)) {
            st = pb_fail(err, POSE_ERR_FORMAT, "%s: can.dbc must be a file name", name);
            goto done;
        }
        if (dbc->valuestring[0] == '/' || !base_dir || !base_dir[0])
            snprintf(path, sizeof path, "%s", dbc->valuestring);
        else
            snprintf(path, sizeof path, "%s/%s", base_dir, dbc->valuestring);
    }
    st = pb_can_bus_create(dbc ? path : NULL, &b, err);
    if (st != POSE_OK)
        goto done;
    if (!json_uint(can, "timeout_ms", 600000, 0, &b->timeout_ms)) {
        st = pb_fail(err, POSE_ERR_FORMAT, "%s: can.timeout_ms must be 0..600000", name);
        goto done;
    }
    const cJSON *item;
    const cJSON *co = cJSON_GetObjectItemCaseSensitive(can, "canopen");
    if (co && !cJSON_IsArray(co)) {
        st = pb_fail(err, POSE_ERR_FORMAT, "%s: can.canopen must be an array", name);
        goto done;
    }
    size_t i = 0;
    cJSON_ArrayForEach(item, co)
    {
        pb_canopen_node_config c = {0};
        uint32_t node, profile, steps, hb;
        const cJSON *res = cJSON_GetObjectItemCaseSensitive(item, "resolution_deg");
        if (!cJSON_IsObject(item) || !json_uint(item, "node", 127, 0, &node) || node < 1 ||
            !json_uint(item, "profile", 1000, 406, &profile) ||
            !json_uint(item, "steps_per_rev", (double)UINT32_MAX, 0, &steps) ||
            !json_uint(item, "heartbeat_ms", 65535, 0, &hb) || (res && (!cJSON_IsNumber(res) || res->valuedouble <= 0))) {
            st = pb_fail(err, POSE_ERR_FORMAT,
                         "%s: can.canopen[%zu]: needs \"node\" 1..127 and optional \"profile\" 406|410, "
                         "\"steps_per_rev\", \"heartbeat_ms\" 0..65535, \"resolution_deg\" > 0",
                         name, i);
            goto done;
        }
        c.node = (uint8_t)node;
        c.profile = (uint16_t)profile;
        c.steps_per_rev = steps;
        c.heartbeat_ms = hb;
        c.resolution_deg = res ? res->valuedouble : 0;
        c.name = json_name(item);
        if ((st = pb_can_bus_add_canopen(b, &c)) != POSE_OK)
            goto done;
        i++;
    }
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(can, "j1939");
    if (j && !cJSON_IsArray(j)) {
        st = pb_fail(err, POSE_ERR_FORMAT, "%s: can.j1939 must be an array", name);
        goto done;
    }
    i = 0;
    cJSON_ArrayForEach(item, j)
    {
        pb_j1939_sensor_config c = {0};
        uint32_t addr, cycle;
        if (!cJSON_IsObject(item) || !cJSON_GetObjectItemCaseSensitive(item, "address") ||
            !json_uint(item, "address", 253, 0, &addr) || !json_uint(item, "cycle_ms", 65535, 0, &cycle)) {
            st = pb_fail(err, POSE_ERR_FORMAT,
                         "%s: can.j1939[%zu]: needs \"address\" 0..253 and optional \"cycle_ms\"", name, i);
            goto done;
        }
        c.address = (uint8_t)addr;
        c.cycle_ms = cycle;
        c.name = json_name(item);
        if ((st = pb_can_bus_add_j1939(b, &c)) != POSE_OK)
            goto done;
        i++;
    }
    const cJSON *ch = cJSON_GetObjectItemCaseSensitive(can, "channels");
    if (ch) {
        int n = cJSON_GetArraySize(ch);
        const char **names = calloc((size_t)n + 1, sizeof *names);
        if (!names) {
            st = POSE_ERR_OUT_OF_MEMORY;
            goto done;
        }
        int k = 0;
        cJSON_ArrayForEach(item, ch)
        {
            if (!cJSON_IsString(item)) {
                free(names);
                st = pb_fail(err, POSE_ERR_FORMAT, "%s: can.channels[%d] must be a string", name, k);
                goto done;
            }
            names[k++] = item->valuestring;
        }
        st = pb_can_bus_select(b, names, (size_t)k);
        free(names);
        if (st != POSE_OK)
            goto done;
    }
    refresh(b);
done:
    cJSON_Delete(root);
    if (st != POSE_OK) {
        pb_can_bus_free(b);
        return st;
    }
    *out = b;
    return POSE_OK;
}

pose_status pb_can_bus_load(const char *json_path, pb_can_bus **out, pb_error *err)
{
    *out = NULL;
    char *text;
    size_t n;
    pose_status st = pb_read_file(json_path, 16u << 20, &text, &n, err);
    if (st != POSE_OK)
        return st;
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", json_path);
    char *slash = strrchr(dir, '/');
    if (slash)
        *slash = '\0';
    else
        snprintf(dir, sizeof dir, ".");
    st = pb_can_bus_parse(text, n, json_path, dir, out, err);
    free(text);
    return st;
}
