/* SPDX-License-Identifier: Apache-2.0
 * Reading mapping files (cJSON). Messages name the file and the JSON path of
 * the entry at fault ("map.json: channels[2].axis: expected x, y or z"). */
#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mapping.h"
#include "pb_math.h"
#include "pb_warn.h"

enum { MAP_MAX_FILE = 4u << 20, MAP_MAX_ENTRIES = 4096 };

static pb_mapping *mapping_alloc(void)
{
    pb_mapping *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    pb_quat_identity(m->axes_q);
    m->up[1] = 1.0;
    m->scale = 1.0;
    m->reference_frame = -1;
    m->align = 1;
    return m;
}

void pb_mapping_free(pb_mapping *m)
{
    if (!m)
        return;
    free(m->joints);
    free(m->channels);
    free(m->ranges);
    free(m);
}

pose_status pb_mapping_identity(pb_mapping **out, pb_error *err)
{
    *out = mapping_alloc();
    if (!*out)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    (*out)->identity = 1;
    (*out)->root_motion = PB_ROOT_FULL;
    snprintf((*out)->path, sizeof (*out)->path, "<same names>");
    return POSE_OK;
}

/* "+y" -> unit vector */
static int parse_dir(const cJSON *v, double d[3])
{
    if (!cJSON_IsString(v))
        return -1;
    const char *s = v->valuestring;
    double sign = 1.0;
    if (*s == '+' || *s == '-')
        sign = *s++ == '-' ? -1.0 : 1.0;
    char c = (char)(*s | 0x20);
    if (c < 'x' || c > 'z' || s[1] != '\0')
        return -1;
    d[0] = d[1] = d[2] = 0.0;
    d[c - 'x'] = sign;
    return 0;
}

/* Frame basis {forward, left = up x forward, up} as matrix columns. */
static int parse_axes(const cJSON *o, double m[3][3])
{
    double up[3], fw[3];
    if (!cJSON_IsObject(o) || parse_dir(cJSON_GetObjectItemCaseSensitive(o, "up"), up) ||
        parse_dir(cJSON_GetObjectItemCaseSensitive(o, "forward"), fw))
        return -1;
    if (fabs(up[0] * fw[0] + up[1] * fw[1] + up[2] * fw[2]) > 0.5)
        return -1;
    double left[3] = {up[1] * fw[2] - up[2] * fw[1], up[2] * fw[0] - up[0] * fw[2], up[0] * fw[1] - up[1] * fw[0]};
    for (int r = 0; r < 3; r++) {
        m[r][0] = fw[r];
        m[r][1] = left[r];
        m[r][2] = up[r];
    }
    return 0;
}

static void quat_from_matrix(const double m[3][3], double q[4])
{
    double tr = m[0][0] + m[1][1] + m[2][2];
    if (tr > 0) {
        double s = sqrt(tr + 1.0) * 2;
        q[3] = 0.25 * s;
        q[0] = (m[2][1] - m[1][2]) / s;
        q[1] = (m[0][2] - m[2][0]) / s;
        q[2] = (m[1][0] - m[0][1]) / s;
    } else if (m[0][0] > m[1][1] && m[0][0] > m[2][2]) {
        double s = sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2;
        q[3] = (m[2][1] - m[1][2]) / s;
        q[0] = 0.25 * s;
        q[1] = (m[0][1] + m[1][0]) / s;
        q[2] = (m[0][2] + m[2][0]) / s;
    } else if (m[1][1] > m[2][2]) {
        double s = sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2;
        q[3] = (m[0][2] - m[2][0]) / s;
        q[0] = (m[0][1] + m[1][0]) / s;
        q[1] = 0.25 * s;
        q[2] = (m[1][2] + m[2][1]) / s;
    } else {
        double s = sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2;
        q[3] = (m[1][0] - m[0][1]) / s;
        q[0] = (m[0][2] + m[2][0]) / s;
        q[1] = (m[1][2] + m[2][1]) / s;
        q[2] = 0.25 * s;
    }
    pb_quat_normalize(q);
}

static int finite_number(const cJSON *v, double *out)
{
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble))
        return -1;
    *out = v->valuedouble;
    return 0;
}

static pose_status parse_filter(const cJSON *o, const char *path, const char *where, pb_one_euro_params *f,
                                pb_error *err)
{
    if (!cJSON_IsObject(o))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: expected an object {min_cutoff, beta, d_cutoff}", path, where);
    memset(f, 0, sizeof *f);
    f->d_cutoff = 1.0;
    static const char *keys[3] = {"min_cutoff", "beta", "d_cutoff"};
    double *dst[3] = {&f->min_cutoff, &f->beta, &f->d_cutoff};
    for (int k = 0; k < 3; k++) {
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, keys[k]);
        if (!v)
            continue;
        if (finite_number(v, dst[k]) || *dst[k] < 0)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: %s.%s: expected a non-negative number", path, where, keys[k]);
    }
    if (f->min_cutoff <= 0 && cJSON_GetObjectItemCaseSensitive(o, "min_cutoff"))
        f->min_cutoff = 0; /* explicit 0: filter off */
    return POSE_OK;
}

static int copy_name(char dst[PB_NAME_MAX], const cJSON *v)
{
    if (!cJSON_IsString(v) || !v->valuestring[0] || strlen(v->valuestring) >= PB_NAME_MAX)
        return -1;
    memcpy(dst, v->valuestring, strlen(v->valuestring) + 1);
    return 0;
}

static pose_status parse_joints(pb_mapping *m, const cJSON *o, pb_error *err)
{
    if (!cJSON_IsObject(o))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: joints: expected an object {rig joint: clip joint}", m->path);
    int n = cJSON_GetArraySize(o);
    if (n > MAP_MAX_ENTRIES)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: joints: more than %d entries", m->path, MAP_MAX_ENTRIES);
    m->joints = calloc(n > 0 ? (size_t)n : 1, sizeof *m->joints);
    if (!m->joints)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    const cJSON *e;
    cJSON_ArrayForEach(e, o)
    {
        pb_map_joint *J = &m->joints[m->joint_count];
        J->align = -1;
        if (!e->string || strlen(e->string) == 0 || strlen(e->string) >= PB_NAME_MAX)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: joints: rig joint names must have 1..%d bytes", m->path,
                           PB_NAME_MAX - 1);
        memcpy(J->rig, e->string, strlen(e->string) + 1);
        for (int k = 0; k < m->joint_count; k++)
            if (strcmp(m->joints[k].rig, J->rig) == 0)
                return pb_fail(err, POSE_ERR_FORMAT, "%s: joints.%s: rig joint mapped twice", m->path, J->rig);
        const cJSON *src = e;
        if (cJSON_IsObject(e)) {
            src = cJSON_GetObjectItemCaseSensitive(e, "source");
            const cJSON *al = cJSON_GetObjectItemCaseSensitive(e, "align");
            if (al) {
                if (!cJSON_IsBool(al))
                    return pb_fail(err, POSE_ERR_FORMAT, "%s: joints.%s.align: expected true or false", m->path,
                                   J->rig);
                J->align = cJSON_IsTrue(al);
            }
            const cJSON *f = cJSON_GetObjectItemCaseSensitive(e, "filter");
            if (f) {
                char where[96];
                snprintf(where, sizeof where, "joints.%.60s.filter", J->rig);
                pose_status s = parse_filter(f, m->path, where, &J->filter, err);
                if (s)
                    return s;
                J->has_filter = 1;
            }
        }
        if (copy_name(J->source, src))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: joints.%s: expected a clip joint name (string, 1..%d bytes)",
                           m->path, J->rig, PB_NAME_MAX - 1);
        m->joint_count++;
    }
    return POSE_OK;
}

static int parse_order(const cJSON *v, pose_euler_order *o)
{
    static const char *names[6] = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"};
    if (!cJSON_IsString(v))
        return -1;
    for (int i = 0; i < 6; i++)
        if (strcmp(v->valuestring, names[i]) == 0) {
            *o = (pose_euler_order)i;
            return 0;
        }
    return -1;
}

static pose_status parse_pair(const cJSON *v, double out[2], const char *path, const char *where, pb_error *err)
{
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2 || finite_number(cJSON_GetArrayItem(v, 0), &out[0]) ||
        finite_number(cJSON_GetArrayItem(v, 1), &out[1]))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: expected [number, number]", path, where);
    return POSE_OK;
}

/* "ranges": {"<rig joint>": {"<angle>": [min, max], ...}, ...}; the angle
 * names are resolved against the rig when bound (mapping_ranges.c). */
static pose_status parse_ranges(pb_mapping *m, const cJSON *o, pb_error *err)
{
    if (!cJSON_IsObject(o))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: ranges: expected an object {rig joint: {angle: [min, max]}}",
                       m->path);
    int n = cJSON_GetArraySize(o);
    if (n > MAP_MAX_ENTRIES)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: ranges: more than %d entries", m->path, MAP_MAX_ENTRIES);
    m->ranges = calloc(n > 0 ? (size_t)n : 1, sizeof *m->ranges);
    if (!m->ranges)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    const cJSON *e;
    cJSON_ArrayForEach(e, o)
    {
        pb_map_range *R = &m->ranges[m->range_count];
        if (!e->string || strlen(e->string) == 0 || strlen(e->string) >= PB_NAME_MAX)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: ranges: rig joint names must have 1..%d bytes", m->path,
                           PB_NAME_MAX - 1);
        memcpy(R->joint, e->string, strlen(e->string) + 1);
        for (int k = 0; k < m->range_count; k++)
            if (strcmp(m->ranges[k].joint, R->joint) == 0)
                return pb_fail(err, POSE_ERR_FORMAT, "%s: ranges.%s: joint given twice", m->path, R->joint);
        if (!cJSON_IsObject(e) || cJSON_GetArraySize(e) < 1 || cJSON_GetArraySize(e) > 3)
            return pb_fail(err, POSE_ERR_FORMAT,
                           "%s: ranges.%s: expected an object of 1 to 3 angles {\"flexion\": [min, max], ...}",
                           m->path, R->joint);
        const cJSON *a;
        cJSON_ArrayForEach(a, e)
        {
            int k = R->angle_count;
            char where[PB_NAME_MAX + 48];
            if (!a->string || strlen(a->string) == 0 || strlen(a->string) >= sizeof R->angle[k])
                return pb_fail(err, POSE_ERR_FORMAT, "%s: ranges.%s: angle names must have 1..%zu bytes", m->path,
                               R->joint, sizeof R->angle[k] - 1);
            memcpy(R->angle[k], a->string, strlen(a->string) + 1);
            snprintf(where, sizeof where, "ranges.%s.%s", R->joint, R->angle[k]);
            double v[2];
            pose_status s = parse_pair(a, v, m->path, where, err);
            if (s)
                return s;
            if (v[0] > v[1])
                return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: min %g is above max %g", m->path, where, v[0], v[1]);
            R->min_deg[k] = v[0];
            R->max_deg[k] = v[1];
            R->angle_count++;
        }
        m->range_count++;
    }
    return POSE_OK;
}

static pose_status parse_channel(pb_mapping *m, const cJSON *e, int i, pb_error *err)
{
    pb_map_channel *C = &m->channels[i];
    char w[96];
    if (!cJSON_IsObject(e))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d]: expected an object", m->path, i);
    C->scale = 1.0;
    const cJSON *ch = cJSON_GetObjectItemCaseSensitive(e, "channel");
    const cJSON *us = cJSON_GetObjectItemCaseSensitive(e, "usage");
    if (ch) {
        if (copy_name(C->channel, ch))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].channel: expected a channel name", m->path, i);
    } else if (us) {
        double u;
        if (cJSON_IsString(us)) {
            char *e2;
            unsigned long v = strtoul(us->valuestring, &e2, 0);
            if (*e2 || e2 == us->valuestring || v > 0xFFFFFFFFul)
                return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].usage: expected \"0xPPPPUUUU\"", m->path, i);
            C->usage = (uint32_t)v;
        } else if (!finite_number(us, &u) && u >= 0 && u <= 4294967295.0) {
            C->usage = (uint32_t)u;
        } else {
            return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].usage: expected a HID usage", m->path, i);
        }
        const cJSON *ix = cJSON_GetObjectItemCaseSensitive(e, "index");
        double d = 0;
        if (ix && (finite_number(ix, &d) || d < 0 || d > 255 || d != (int)d))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].index: expected 0..255", m->path, i);
        C->usage_index = (int)d;
    } else {
        return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d]: needs \"channel\" or \"usage\"", m->path, i);
    }
    if (copy_name(C->joint, cJSON_GetObjectItemCaseSensitive(e, "joint")))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].joint: expected a rig joint name", m->path, i);
    const cJSON *ax = cJSON_GetObjectItemCaseSensitive(e, "axis");
    const cJSON *dof = cJSON_GetObjectItemCaseSensitive(e, "dof");
    if (ax && dof)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d]: \"axis\" and \"dof\" exclude each other", m->path, i);
    if (dof) {
        /* Clinical: resolved against the rig's names when bound (pb_chanmap_create). */
        if (!cJSON_IsString(dof) || !dof->valuestring[0] || strlen(dof->valuestring) >= sizeof C->dof)
            return pb_fail(err, POSE_ERR_FORMAT,
                           "%s: channels[%d].dof: expected \"flexion\", \"abduction\", \"rotation\" or a name "
                           "the rig gives the joint's angle", m->path, i);
        snprintf(C->dof, sizeof C->dof, "%s", dof->valuestring);
        C->axis = -1;
    } else {
        if (!ax)
            return pb_fail(err, POSE_ERR_FORMAT,
                           "%s: channels[%d]: needs \"dof\" (a clinical angle) or \"axis\" (a rest-frame Euler axis)",
                           m->path, i);
        if (!cJSON_IsString(ax) || strlen(ax->valuestring) != 1 || (ax->valuestring[0] | 0x20) < 'x' ||
            (ax->valuestring[0] | 0x20) > 'z')
            return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].axis: expected \"x\", \"y\" or \"z\"", m->path, i);
        C->axis = (ax->valuestring[0] | 0x20) - 'x';
    }
    C->order = POSE_EULER_XYZ;
    const cJSON *od = cJSON_GetObjectItemCaseSensitive(e, "order");
    if (od && parse_order(od, &C->order))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].order: expected XYZ, XZY, YXZ, YZX, ZXY or ZYX",
                       m->path, i);
    const cJSON *cal = cJSON_GetObjectItemCaseSensitive(e, "calibration");
    if (cal) {
        const cJSON *raw = cJSON_GetObjectItemCaseSensitive(cal, "raw");
        if (raw) {
            snprintf(w, sizeof w, "channels[%d].calibration.raw", i);
            pose_status s = parse_pair(raw, C->raw, m->path, w, err);
            snprintf(w, sizeof w, "channels[%d].calibration.deg", i);
            if (!s)
                s = parse_pair(cJSON_GetObjectItemCaseSensitive(cal, "deg"), C->deg, m->path, w, err);
            if (s)
                return s;
            if (C->raw[0] == C->raw[1])
                return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].calibration.raw: the two points are equal",
                               m->path, i);
            C->calib = PB_CALIB_TWO_POINT;
        } else {
            const cJSON *o = cJSON_GetObjectItemCaseSensitive(cal, "offset");
            const cJSON *s = cJSON_GetObjectItemCaseSensitive(cal, "scale");
            if ((o && finite_number(o, &C->offset)) || (s && finite_number(s, &C->scale)) || (!o && !s))
                return pb_fail(err, POSE_ERR_FORMAT,
                               "%s: channels[%d].calibration: expected {raw, deg} or {offset, scale} numbers",
                               m->path, i);
            C->calib = PB_CALIB_LINEAR;
        }
    }
    const cJSON *inv = cJSON_GetObjectItemCaseSensitive(e, "invert");
    if (inv && !cJSON_IsBool(inv))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].invert: expected true or false", m->path, i);
    C->invert = cJSON_IsTrue(inv);
    const cJSON *db = cJSON_GetObjectItemCaseSensitive(e, "deadband");
    if (db && (finite_number(db, &C->deadband) || C->deadband < 0))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].deadband: expected a non-negative number", m->path, i);
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(e, "filter");
    if (f) {
        snprintf(w, sizeof w, "channels[%d].filter", i);
        pose_status s = parse_filter(f, m->path, w, &C->filter, err);
        if (s)
            return s;
        C->has_filter = 1;
    }
    const cJSON *lim = cJSON_GetObjectItemCaseSensitive(e, "limits");
    if (lim) {
        snprintf(w, sizeof w, "channels[%d].limits", i);
        pose_status s = parse_pair(lim, C->limit, m->path, w, err);
        if (s)
            return s;
        if (C->limit[0] > C->limit[1])
            return pb_fail(err, POSE_ERR_FORMAT, "%s: channels[%d].limits: min is above max", m->path, i);
        C->has_limits = 1;
    }
    return POSE_OK;
}

static pose_status parse_root(pb_mapping *m, const cJSON *root, pb_error *err)
{
    if (!cJSON_IsObject(root))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: expected a JSON object at the top", m->path);
    const cJSON *sa = cJSON_GetObjectItemCaseSensitive(root, "source_axes");
    const cJSON *ra = cJSON_GetObjectItemCaseSensitive(root, "rig_axes");
    if (sa || ra) {
        double ms[3][3], mr[3][3];
        if (!sa || parse_axes(sa, ms))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: source_axes: expected {\"up\": \"+y\", \"forward\": \"+z\"} "
                           "with orthogonal axes", m->path);
        if (!ra || parse_axes(ra, mr))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: rig_axes: expected {\"up\": \"+z\", \"forward\": \"+x\"} "
                           "with orthogonal axes", m->path);
        double g[3][3]; /* G = Mr * Ms^T */
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                g[r][c] = mr[r][0] * ms[c][0] + mr[r][1] * ms[c][1] + mr[r][2] * ms[c][2];
        quat_from_matrix(g, m->axes_q);
        for (int r = 0; r < 3; r++)
            m->up[r] = mr[r][2];
    }
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(root, "scale");
    if (v && (finite_number(v, &m->scale) || !(m->scale > 0)))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: scale: expected a positive number", m->path);
    v = cJSON_GetObjectItemCaseSensitive(root, "root_motion");
    if (v) {
        const char *s = cJSON_IsString(v) ? v->valuestring : "";
        if (strcmp(s, "none") == 0)
            m->root_motion = PB_ROOT_NONE;
        else if (strcmp(s, "horizontal") == 0)
            m->root_motion = PB_ROOT_HORIZONTAL;
        else if (strcmp(s, "full") == 0)
            m->root_motion = PB_ROOT_FULL;
        else
            return pb_fail(err, POSE_ERR_FORMAT, "%s: root_motion: expected \"none\", \"horizontal\" or \"full\"",
                           m->path);
    }
    v = cJSON_GetObjectItemCaseSensitive(root, "root_origin");
    if (v) {
        const char *s = cJSON_IsString(v) ? v->valuestring : "";
        if (strcmp(s, "first_frame") == 0)
            m->root_from_first_frame = 1;
        else if (strcmp(s, "reference") != 0)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: root_origin: expected \"reference\" or \"first_frame\"",
                           m->path);
    }
    v = cJSON_GetObjectItemCaseSensitive(root, "reference");
    if (v) {
        double f;
        if (cJSON_IsString(v) && strcmp(v->valuestring, "zero") == 0)
            m->reference_frame = -1;
        else if (!finite_number(v, &f) && f >= 0 && f <= 1e9 && f == (long)f)
            m->reference_frame = (long)f;
        else
            return pb_fail(err, POSE_ERR_FORMAT, "%s: reference: expected \"zero\" or a frame number", m->path);
    }
    v = cJSON_GetObjectItemCaseSensitive(root, "align");
    if (v) {
        if (!cJSON_IsBool(v))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: align: expected true or false", m->path);
        m->align = cJSON_IsTrue(v);
    }
    v = cJSON_GetObjectItemCaseSensitive(root, "filter");
    if (v) {
        pose_status s = parse_filter(v, m->path, "filter", &m->filter, err);
        if (s)
            return s;
        m->has_filter = 1;
    }
    const cJSON *joints = cJSON_GetObjectItemCaseSensitive(root, "joints");
    if (joints) {
        pose_status s = parse_joints(m, joints, err);
        if (s)
            return s;
    }
    const cJSON *ranges = cJSON_GetObjectItemCaseSensitive(root, "ranges");
    if (ranges) {
        pose_status s = parse_ranges(m, ranges, err);
        if (s)
            return s;
    }
    const cJSON *chans = cJSON_GetObjectItemCaseSensitive(root, "channels");
    if (chans) {
        if (!cJSON_IsArray(chans))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: channels: expected an array", m->path);
        int n = cJSON_GetArraySize(chans);
        if (n > MAP_MAX_ENTRIES)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: channels: more than %d entries", m->path, MAP_MAX_ENTRIES);
        m->channels = calloc(n > 0 ? (size_t)n : 1, sizeof *m->channels);
        if (!m->channels)
            return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        int i = 0;
        const cJSON *e;
        cJSON_ArrayForEach(e, chans)
        {
            pose_status s = parse_channel(m, e, i, err);
            if (s)
                return s;
            m->channel_count = ++i;
        }
    }
    m->identity = !joints && !chans;
    return POSE_OK;
}

/* JSON allows a key twice in an object and cJSON keeps both, but every
 * lookup here takes the first: the second is ignored, which its author did
 * not mean. A warning names where ("channels[3]") and the key. */
static void warn_duplicate_keys(const cJSON *node, const char *file, char *path, size_t len, size_t cap)
{
    int i = 0;
    for (const cJSON *c = node->child; c; c = c->next, i++) {
        if (cJSON_IsObject(node) && c->string)
            for (const cJSON *k = node->child; k != c; k = k->next)
                if (k->string && strcmp(k->string, c->string) == 0) {
                    pb_warn("%s: %s: key \"%s\" appears again; the first one is used", file,
                            len ? path : "the top-level object", c->string);
                    break;
                }
        if (!c->child)
            continue;
        const int n = cJSON_IsObject(node) ? snprintf(path + len, cap - len, "%s%s", len ? "." : "", c->string)
                                           : snprintf(path + len, cap - len, "[%d]", i);
        warn_duplicate_keys(c, file, path, n > 0 && len + (size_t)n < cap ? len + (size_t)n : cap - 1, cap);
        path[len] = '\0';
    }
}

pose_status pb_mapping_parse(const char *json, size_t size, const char *name, pb_mapping **out, pb_error *err)
{
    if (!out || (!json && size))
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_mapping_parse: NULL argument");
    *out = NULL;
    pb_mapping *m = mapping_alloc();
    if (!m)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    snprintf(m->path, sizeof m->path, "%s", name ? name : "<memory>");
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(json ? json : "", size, &end, 0);
    if (!root) {
        long line = 1;
        size_t off = end && end >= json && end <= json + size ? (size_t)(end - json) : size;
        for (size_t i = 0; i < off; i++)
            line += json[i] == '\n';
        pose_status s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: invalid JSON near byte %zu", m->path, line, off);
        pb_mapping_free(m);
        return s;
    }
    char where[256] = "";
    warn_duplicate_keys(root, m->path, where, 0, sizeof where);
    pose_status s = parse_root(m, root, err);
    cJSON_Delete(root);
    if (s) {
        pb_mapping_free(m);
        return s;
    }
    *out = m;
    return POSE_OK;
}

pose_status pb_mapping_load(const char *path, pb_mapping **out, pb_error *err)
{
    char *data;
    size_t size;
    if (out)
        *out = NULL;
    if (!path || !out)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_mapping_load: NULL argument");
    pose_status s = pb_read_file(path, MAP_MAX_FILE, &data, &size, err);
    if (s)
        return s;
    s = pb_mapping_parse(data, size, path, out, err);
    free(data);
    return s;
}
