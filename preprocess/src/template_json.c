/* SPDX-License-Identifier: Apache-2.0
 *
 * Skeleton template reader. cJSON does the JSON; this file checks the
 * meaning: every key known, names unique and short, parents before children,
 * each bone in one segment only, numbers finite and in range. Errors name the
 * file, the line (of the JSON error, or of the offending joint's name) and
 * the field.
 */
#include "template_json.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct parse_ctx {
    const char *text;
    size_t size;
    const char *source;
    char *err;
    size_t err_size;
} parse_ctx;

static int line_of_offset(const char *text, size_t offset)
{
    int line = 1;
    for (size_t i = 0; i < offset; i++)
        line += text[i] == '\n';
    return line;
}

/* Line where a joint is declared: the first occurrence of its quoted name
 * after "name". cJSON keeps no positions, and naming the line saves the
 * user a search in a 300-line file. 0 if not found. */
static int line_of_joint(const parse_ctx *c, const char *name)
{
    char needle[PP_NAME_MAX + 3];
    snprintf(needle, sizeof needle, "\"%s\"", name);
    size_t n = strlen(needle);
    for (size_t i = 0; i + n <= c->size; i++)
        if (memcmp(c->text + i, needle, n) == 0)
            return line_of_offset(c->text, i);
    return 0;
}

#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static int fail_at(const parse_ctx *c, int status, const char *joint, const char *fmt, ...)
{
    char what[384];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    int line = joint ? line_of_joint(c, joint) : 0;
    if (!c->err || !c->err_size)
        return status;
    if (joint && line > 0)
        snprintf(c->err, c->err_size, "%s:%d: joint '%s': %s", c->source, line, joint, what);
    else if (joint)
        snprintf(c->err, c->err_size, "%s: joint '%s': %s", c->source, joint, what);
    else
        snprintf(c->err, c->err_size, "%s: %s", c->source, what);
    return status;
}

const char *pp_fit_rule_name(pp_fit_rule rule)
{
    switch (rule) {
    case PP_FIT_ROOT: return "root";
    case PP_FIT_BALL: return "ball";
    case PP_FIT_HINGE: return "hinge";
    case PP_FIT_SPINE: return "spine";
    case PP_FIT_FIXED: return "fixed";
    }
    return "?";
}

static int parse_rule(const char *s, pp_fit_rule *out)
{
    static const pp_fit_rule all[] = {PP_FIT_ROOT, PP_FIT_BALL, PP_FIT_HINGE, PP_FIT_SPINE,
                                      PP_FIT_FIXED};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        if (strcmp(s, pp_fit_rule_name(all[i])) == 0) {
            *out = all[i];
            return 1;
        }
    return 0;
}

static int parse_order(const char *s, pose_euler_order *out)
{
    static const char *names[] = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"};
    for (int i = 0; i < 6; i++)
        if (strcmp(s, names[i]) == 0) {
            *out = (pose_euler_order)i;
            return 1;
        }
    return 0;
}

/* A JSON array of exactly n finite numbers. */
static int read_vec(const cJSON *item, float *out, int n)
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != n)
        return 0;
    int i = 0;
    for (const cJSON *e = item->child; e; e = e->next, i++) {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1e6)
            return 0;
        out[i] = (float)e->valuedouble;
    }
    return 1;
}

static int read_unit_vec(const cJSON *item, float out[3])
{
    if (!read_vec(item, out, 3))
        return 0;
    float n = sqrtf(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
    if (!(n > 1e-6f))
        return 0;
    for (int k = 0; k < 3; k++)
        out[k] /= n;
    return 1;
}

static int valid_name(const char *s)
{
    size_t n = strlen(s);
    return n >= 1 && n < PP_NAME_MAX;
}

/* An array of mesh names into a fresh array (count may be 0). */
static int read_names(const parse_ctx *c, const char *joint, const char *field, const cJSON *arr,
                      char (**out)[PP_NAME_MAX], size_t *count)
{
    *out = NULL;
    *count = 0;
    if (!cJSON_IsArray(arr))
        return fail_at(c, POSE_ERR_FORMAT, joint, "'%s' must be an array of mesh names", field);
    int n = cJSON_GetArraySize(arr);
    if (n == 0)
        return POSE_OK;
    *out = calloc((size_t)n, sizeof **out);
    if (!*out)
        return fail_at(c, POSE_ERR_OUT_OF_MEMORY, joint, "out of memory");
    for (const cJSON *e = arr->child; e; e = e->next) {
        if (!cJSON_IsString(e) || !valid_name(e->valuestring))
            return fail_at(c, POSE_ERR_FORMAT, joint,
                           "'%s' entry %zu must be a mesh name of 1..63 bytes", field, *count);
        for (size_t k = 0; k < *count; k++)
            if (strcmp((*out)[k], e->valuestring) == 0)
                return fail_at(c, POSE_ERR_INVALID_DATA, joint, "'%s' lists '%s' twice", field,
                               e->valuestring);
        strcpy((*out)[(*count)++], e->valuestring);
    }
    return POSE_OK;
}

/* cJSON keeps repeated keys; a repeated key is almost always a paste error. */
static const char *repeated_key(const cJSON *obj)
{
    for (const cJSON *e = obj->child; e; e = e->next)
        for (const cJSON *f = e->next; f; f = f->next)
            if (strcmp(e->string, f->string) == 0)
                return e->string;
    return NULL;
}

static int in_list(char (*list)[PP_NAME_MAX], size_t n, const char *s)
{
    for (size_t i = 0; i < n; i++)
        if (strcmp(list[i], s) == 0)
            return 1;
    return 0;
}

static int parse_limits(const parse_ctx *c, const char *joint, const cJSON *lim,
                        pp_template_joint *j)
{
    if (!cJSON_IsObject(lim))
        return fail_at(c, POSE_ERR_FORMAT, joint, "'limits' must be an object");
    if (repeated_key(lim))
        return fail_at(c, POSE_ERR_FORMAT, joint, "key 'limits.%s' appears twice", repeated_key(lim));
    static const char *axes[3] = {"x", "y", "z"};
    for (const cJSON *e = lim->child; e; e = e->next) {
        if (strcmp(e->string, "order") == 0) {
            if (!cJSON_IsString(e) || !parse_order(e->valuestring, &j->limit_order))
                return fail_at(c, POSE_ERR_FORMAT, joint,
                               "'limits.order' must be one of XYZ XZY YXZ YZX ZXY ZYX");
            continue;
        }
        int a = -1;
        for (int k = 0; k < 3; k++)
            if (strcmp(e->string, axes[k]) == 0)
                a = k;
        if (a < 0)
            return fail_at(c, POSE_ERR_FORMAT, joint, "unknown key 'limits.%s' (expected order, x, y, z)",
                           e->string);
        float mm[2];
        if (!read_vec(e, mm, 2) || mm[0] > mm[1] || mm[0] < -180.0f || mm[1] > 180.0f)
            return fail_at(c, POSE_ERR_FORMAT, joint,
                           "'limits.%s' must be [min, max] degrees with -180 <= min <= max <= 180",
                           e->string);
        j->limit_flags |= 1u << a;
        j->limit_min_deg[a] = mm[0];
        j->limit_max_deg[a] = mm[1];
    }
    return POSE_OK;
}

static double angle_deg(const float a[3], const float b[3])
{
    double d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
    return acos(fmax(-1.0, fmin(1.0, d))) * 57.29577951308232; /* degrees per radian */
}

/* Nominal directions that are not roughly perpendicular are a typo (a sign
 * or an axis swapped): the bake could not tell which way was meant. */
static int check_perpendicular(const parse_ctx *c, const char *joint, const char *ka, const float *a,
                               const char *kb, const float *b)
{
    double deg = angle_deg(a, b);
    if (deg < 60.0 || deg > 120.0)
        return fail_at(c, POSE_ERR_INVALID_DATA, joint,
                       "'clinical.%s' and 'clinical.%s' are %.0f degrees apart; they must be roughly "
                       "perpendicular (60..120)",
                       ka, kb, deg);
    return POSE_OK;
}

static int parse_clinical_limits(const parse_ctx *c, const char *joint, const cJSON *lim,
                                 pp_template_clinical *k)
{
    static const char *keys[3] = {"flexion", "abduction", "rotation"};
    if (!cJSON_IsObject(lim))
        return fail_at(c, POSE_ERR_FORMAT, joint, "'clinical.limits' must be an object");
    if (repeated_key(lim))
        return fail_at(c, POSE_ERR_FORMAT, joint, "key 'clinical.limits.%s' appears twice",
                       repeated_key(lim));
    for (const cJSON *e = lim->child; e; e = e->next) {
        int a = -1;
        for (int i = 0; i < 3; i++)
            if (strcmp(e->string, keys[i]) == 0)
                a = i;
        if (a < 0)
            return fail_at(c, POSE_ERR_FORMAT, joint,
                           "unknown key 'clinical.limits.%s' (expected flexion, abduction, rotation)",
                           e->string);
        float mm[2];
        if (!read_vec(e, mm, 2) || mm[0] > mm[1] || mm[0] < -180.0f || mm[1] > 180.0f)
            return fail_at(c, POSE_ERR_FORMAT, joint,
                           "'clinical.limits.%s' must be [min, max] degrees with -180 <= min <= max <= 180",
                           e->string);
        k->limit_flags |= 1u << a;
        k->limit_min_deg[a] = mm[0];
        k->limit_max_deg[a] = mm[1];
    }
    return POSE_OK;
}

static int parse_clinical(const parse_ctx *c, const char *joint, const cJSON *obj,
                          pp_template_clinical *k)
{
    if (!cJSON_IsObject(obj))
        return fail_at(c, POSE_ERR_FORMAT, joint, "'clinical' must be an object");
    if (repeated_key(obj))
        return fail_at(c, POSE_ERR_FORMAT, joint, "key 'clinical.%s' appears twice", repeated_key(obj));
    int have_flex = 0, have_abd = 0;
    for (const cJSON *e = obj->child; e; e = e->next) {
        const char *key = e->string;
        if (strcmp(key, "neutral") == 0) {
            if (!read_unit_vec(e, k->neutral))
                return fail_at(c, POSE_ERR_FORMAT, joint, "'clinical.neutral' must be a non-zero [x, y, z]");
            k->has_neutral = 1;
        } else if (strcmp(key, "flexion") == 0 || strcmp(key, "abduction") == 0) {
            int flex = key[0] == 'f';
            if (!read_unit_vec(e, flex ? k->flexion : k->abduction))
                return fail_at(c, POSE_ERR_FORMAT, joint, "'clinical.%s' must be a non-zero [x, y, z]", key);
            have_flex |= flex;
            have_abd |= !flex;
        } else if (strcmp(key, "rotation") == 0) {
            if (!cJSON_IsNumber(e) || (e->valuedouble != 1.0 && e->valuedouble != -1.0))
                return fail_at(c, POSE_ERR_FORMAT, joint,
                               "'clinical.rotation' must be 1 (positive rotation right-handed about "
                               "the distal direction) or -1 (about the proximal one)");
            k->rotation_sign = (int)e->valuedouble;
        } else if (strcmp(key, "names") == 0) {
            if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != 3)
                return fail_at(c, POSE_ERR_FORMAT, joint,
                               "'clinical.names' must be 3 names (flexion, abduction, rotation)");
            int i = 0;
            for (const cJSON *n = e->child; n; n = n->next, i++) {
                if (!cJSON_IsString(n) || strlen(n->valuestring) < 1 ||
                    strlen(n->valuestring) >= PP_CLINICAL_NAME_MAX)
                    return fail_at(c, POSE_ERR_FORMAT, joint,
                                   "'clinical.names' entry %d must be a string of 1..%d bytes", i,
                                   PP_CLINICAL_NAME_MAX - 1);
                strcpy(k->names[i], n->valuestring);
            }
        } else if (strcmp(key, "limits") == 0) {
            int rc = parse_clinical_limits(c, joint, e, k);
            if (rc < 0)
                return rc;
        } else if (strcmp(key, "comment") != 0) {
            return fail_at(c, POSE_ERR_FORMAT, joint, "unknown key 'clinical.%s'", key);
        }
    }
    if (!have_flex || !have_abd || k->rotation_sign == 0)
        return fail_at(c, POSE_ERR_FORMAT, joint, "'clinical' needs 'flexion', 'abduction' and 'rotation'");
    int rc = check_perpendicular(c, joint, "flexion", k->flexion, "abduction", k->abduction);
    if (rc >= 0 && k->has_neutral)
        rc = check_perpendicular(c, joint, "neutral", k->neutral, "flexion", k->flexion);
    if (rc >= 0 && k->has_neutral)
        rc = check_perpendicular(c, joint, "neutral", k->neutral, "abduction", k->abduction);
    if (rc < 0)
        return rc;
    k->defined = 1;
    return POSE_OK;
}

static int parse_joint(const parse_ctx *c, const cJSON *obj, size_t index, pp_template *t,
                       float default_contact_mm)
{
    pp_template_joint *j = &t->joints[index];
    char label[PP_NAME_MAX + 16];
    snprintf(label, sizeof label, "#%zu", index);
    if (!cJSON_IsObject(obj))
        return fail_at(c, POSE_ERR_FORMAT, NULL, "joints[%zu] must be an object", index);
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(obj, "name");
    if (!cJSON_IsString(name) || !valid_name(name->valuestring))
        return fail_at(c, POSE_ERR_FORMAT, NULL, "joints[%zu]: 'name' must be a string of 1..63 bytes",
                       index);
    strcpy(j->name, name->valuestring);
    const char *jn = j->name;
    for (size_t k = 0; k < index; k++)
        if (strcmp(t->joints[k].name, jn) == 0)
            return fail_at(c, POSE_ERR_INVALID_DATA, jn, "name used twice");

    const char *dup = repeated_key(obj);
    if (dup)
        return fail_at(c, POSE_ERR_FORMAT, jn, "key '%s' appears twice", dup);
    j->parent = -1;
    j->contact_mm = default_contact_mm;
    j->axis[1] = 1.0f;
    j->up[2] = 1.0f;
    j->limit_order = POSE_EULER_XYZ;
    int have_rule = 0, have_bones = 0;
    for (const cJSON *e = obj->child; e; e = e->next) {
        const char *key = e->string;
        int rc = POSE_OK;
        if (strcmp(key, "name") == 0) {
            continue;
        } else if (strcmp(key, "parent") == 0) {
            if (cJSON_IsNull(e))
                continue;
            if (!cJSON_IsString(e))
                return fail_at(c, POSE_ERR_FORMAT, jn, "'parent' must be a joint name or null");
            for (size_t k = 0; k < index; k++)
                if (strcmp(t->joints[k].name, e->valuestring) == 0)
                    j->parent = (int)k;
            if (j->parent < 0)
                return fail_at(c, POSE_ERR_INVALID_DATA, jn,
                               "parent '%s' is not a joint listed before this one", e->valuestring);
        } else if (strcmp(key, "rule") == 0) {
            if (!cJSON_IsString(e) || !parse_rule(e->valuestring, &j->rule))
                return fail_at(c, POSE_ERR_FORMAT, jn,
                               "'rule' must be one of root, ball, hinge, spine, fixed");
            have_rule = 1;
        } else if (strcmp(key, "bones") == 0) {
            rc = read_names(c, jn, key, e, &j->bones, &j->bone_count);
            have_bones = 1;
        } else if (strcmp(key, "contact") == 0) {
            rc = read_names(c, jn, key, e, &j->contact, &j->contact_count);
        } else if (strcmp(key, "parent_contact") == 0) {
            rc = read_names(c, jn, key, e, &j->parent_contact, &j->parent_contact_count);
        } else if (strcmp(key, "fit") == 0) {
            if (cJSON_IsString(e) && strcmp(e->valuestring, "child") == 0)
                j->side = PP_SIDE_CHILD;
            else if (cJSON_IsString(e) && strcmp(e->valuestring, "parent") == 0)
                j->side = PP_SIDE_PARENT;
            else if (cJSON_IsString(e) && strcmp(e->valuestring, "both") == 0)
                j->side = PP_SIDE_BOTH;
            else
                return fail_at(c, POSE_ERR_FORMAT, jn, "'fit' must be child, parent or both");
        } else if (strcmp(key, "contact_mm") == 0) {
            if (!cJSON_IsNumber(e) || !(e->valuedouble > 0.0 && e->valuedouble <= 100.0))
                return fail_at(c, POSE_ERR_FORMAT, jn, "'contact_mm' must be a number in (0, 100]");
            j->contact_mm = (float)e->valuedouble;
        } else if (strcmp(key, "grow_mm") == 0) {
            if (!cJSON_IsNumber(e) || !(e->valuedouble > 0.0 && e->valuedouble <= 200.0))
                return fail_at(c, POSE_ERR_FORMAT, jn, "'grow_mm' must be a number in (0, 200]");
            j->grow_mm = (float)e->valuedouble;
        } else if (strcmp(key, "axis") == 0) {
            if (!read_unit_vec(e, j->axis))
                return fail_at(c, POSE_ERR_FORMAT, jn, "'axis' must be a non-zero [x, y, z]");
        } else if (strcmp(key, "up") == 0) {
            if (!read_unit_vec(e, j->up))
                return fail_at(c, POSE_ERR_FORMAT, jn, "'up' must be a non-zero [x, y, z]");
        } else if (strcmp(key, "at") == 0) {
            if (!read_vec(e, j->at, 3))
                return fail_at(c, POSE_ERR_FORMAT, jn, "'at' must be [x, y, z] in metres");
            j->has_at = 1;
        } else if (strcmp(key, "limits") == 0) {
            rc = parse_limits(c, jn, e, j);
        } else if (strcmp(key, "clinical") == 0) {
            rc = parse_clinical(c, jn, e, &j->clinical);
        } else if (strcmp(key, "comment") == 0) {
            continue;
        } else {
            return fail_at(c, POSE_ERR_FORMAT, jn, "unknown key '%s'", key);
        }
        if (rc < 0)
            return rc;
    }
    if (!have_rule)
        return fail_at(c, POSE_ERR_FORMAT, jn, "missing 'rule'");
    if (!have_bones || j->bone_count == 0)
        return fail_at(c, POSE_ERR_FORMAT, jn, "missing or empty 'bones' (the segment's meshes)");
    if ((j->rule == PP_FIT_ROOT) != (j->parent < 0))
        return fail_at(c, POSE_ERR_INVALID_DATA, jn,
                       j->parent < 0 ? "a joint without parent must have rule 'root'"
                                     : "rule 'root' is only for a joint without parent");
    if (j->parent < 0 && j->clinical.defined)
        return fail_at(c, POSE_ERR_INVALID_DATA, jn,
                       "the root has no clinical angles ('clinical'); pose_set_root places the body");
    if (j->rule == PP_FIT_FIXED && !j->has_at)
        return fail_at(c, POSE_ERR_FORMAT, jn, "rule 'fixed' needs 'at'");
    for (size_t k = 0; k < j->contact_count; k++)
        if (!in_list(j->bones, j->bone_count, j->contact[k]))
            return fail_at(c, POSE_ERR_INVALID_DATA, jn, "'contact' names '%s', which is not in 'bones'",
                           j->contact[k]);
    if (j->parent >= 0) {
        const pp_template_joint *p = &t->joints[j->parent];
        for (size_t k = 0; k < j->parent_contact_count; k++)
            if (!in_list(p->bones, p->bone_count, j->parent_contact[k]))
                return fail_at(c, POSE_ERR_INVALID_DATA, jn,
                               "'parent_contact' names '%s', which is not in parent '%s' bones",
                               j->parent_contact[k], p->name);
    }
    for (size_t b = 0; b < j->bone_count; b++)
        for (size_t k = 0; k < index; k++)
            if (in_list(t->joints[k].bones, t->joints[k].bone_count, j->bones[b]))
                return fail_at(c, POSE_ERR_INVALID_DATA, jn, "bone '%s' is already in joint '%s'",
                               j->bones[b], t->joints[k].name);
    return POSE_OK;
}

/* One "couplings" entry (after the joints: it names them or their bones). */
static int parse_coupling(const parse_ctx *c, const cJSON *obj, size_t index, pp_template *t)
{
    pp_template_coupling *k = &t->couplings[index];
    if (!cJSON_IsObject(obj))
        return fail_at(c, POSE_ERR_FORMAT, NULL, "couplings[%zu] must be an object", index);
    if (repeated_key(obj))
        return fail_at(c, POSE_ERR_FORMAT, NULL, "couplings[%zu]: key '%s' appears twice", index,
                       repeated_key(obj));
    k->joint = -1;
    k->stiffness = PP_COUPLING_STIFFNESS;
    int have_reach = 0, named = 0, soft = 0;
    for (const cJSON *e = obj->child; e; e = e->next) {
        const char *key = e->string;
        if (strcmp(key, "tissue") == 0 || strcmp(key, "to") == 0) {
            soft |= key[1] == 'i' ? 1 : 2;
            if (!cJSON_IsString(e) || !valid_name(e->valuestring))
                return fail_at(c, POSE_ERR_FORMAT, NULL,
                               "couplings[%zu]: '%s' must be a tissue name of 1..63 bytes", index,
                               key);
            strcpy(key[1] == 'i' ? k->tissue : k->to, e->valuestring);
        } else if (strcmp(key, "bone") == 0 || strcmp(key, "joint") == 0) {
            const int bone = key[0] == 'b';
            if (named++)
                return fail_at(c, POSE_ERR_FORMAT, NULL,
                               "couplings[%zu]: give either 'bone' or 'joint', not both", index);
            if (!cJSON_IsString(e) || !valid_name(e->valuestring))
                return fail_at(c, POSE_ERR_FORMAT, NULL,
                               "couplings[%zu]: '%s' must be a name of 1..63 bytes", index, key);
            k->joint = bone ? pp_template_joint_of_bone(t, e->valuestring)
                            : pp_template_find_joint(t, e->valuestring);
            if (k->joint < 0)
                return fail_at(c, POSE_ERR_INVALID_DATA, NULL,
                               bone ? "couplings[%zu]: bone '%s' is in no joint's 'bones'"
                                    : "couplings[%zu]: joint '%s' is not in 'joints'",
                               index, e->valuestring);
            if (bone)
                strcpy(k->bone, e->valuestring);
        } else if (strcmp(key, "reach_mm") == 0) {
            if (!cJSON_IsNumber(e) || !(e->valuedouble > 0.0 && e->valuedouble <= 100.0))
                return fail_at(c, POSE_ERR_FORMAT, NULL,
                               "couplings[%zu]: 'reach_mm' must be a number in (0, 100]", index);
            k->reach_mm = (float)e->valuedouble;
            have_reach = 1;
        } else if (strcmp(key, "stiffness") == 0) {
            if (!cJSON_IsNumber(e) || !(e->valuedouble > 0.0 && e->valuedouble <= 1e6))
                return fail_at(c, POSE_ERR_FORMAT, NULL,
                               "couplings[%zu]: 'stiffness' must be a number in (0, 1e6] (a "
                               "multiple of the node's own elastic stiffness)", index);
            k->stiffness = (float)e->valuedouble;
        } else if (strcmp(key, "comment") != 0) {
            return fail_at(c, POSE_ERR_FORMAT, NULL,
                           "couplings[%zu]: unknown key '%s' (expected bone or joint, or tissue and "
                           "to; reach_mm, stiffness, comment)", index, key);
        }
    }
    if (soft) { /* soft-soft: tissue and to, reach at most 10 mm (the spring spans it at rest) */
        if (named || soft != 3 || !have_reach)
            return fail_at(c, POSE_ERR_FORMAT, NULL,
                           "couplings[%zu]: a soft-soft coupling needs 'tissue', 'to' and "
                           "'reach_mm', and no 'bone' or 'joint'", index);
        if (strcmp(k->tissue, k->to) == 0)
            return fail_at(c, POSE_ERR_INVALID_DATA, NULL,
                           "couplings[%zu]: 'tissue' and 'to' are both '%s'", index, k->to);
        if (k->reach_mm > 10.0f)
            return fail_at(c, POSE_ERR_FORMAT, NULL,
                           "couplings[%zu]: a soft-soft 'reach_mm' must be in (0, 10] (the "
                           "spring pulls the gap shut)", index);
        for (size_t i = 0; i < index; i++)
            if (strcmp(t->couplings[i].tissue, k->tissue) == 0 &&
                strcmp(t->couplings[i].to, k->to) == 0)
                return fail_at(c, POSE_ERR_INVALID_DATA, NULL,
                               "couplings[%zu]: the same tissues '%s' and '%s' as couplings[%zu]",
                               index, k->tissue, k->to, i);
        return POSE_OK;
    }
    if (!named || !have_reach)
        return fail_at(c, POSE_ERR_FORMAT, NULL, "couplings[%zu]: needs 'bone' or 'joint', and 'reach_mm'",
                       index);
    for (size_t i = 0; i < index; i++)
        if (t->couplings[i].joint == k->joint && strcmp(t->couplings[i].bone, k->bone) == 0)
            return fail_at(c, POSE_ERR_INVALID_DATA, NULL,
                           "couplings[%zu]: the same %s '%s' as couplings[%zu]", index,
                           k->bone[0] ? "bone" : "joint",
                           k->bone[0] ? k->bone : t->joints[k->joint].name, i);
    return POSE_OK;
}

int pp_template_parse(const char *text, size_t size, const char *source, pp_template *out,
                      char *err, size_t err_size)
{
    parse_ctx c = {text, size, source ? source : "<template>", err, err_size};
    memset(out, 0, sizeof *out);
    if (err && err_size)
        err[0] = '\0';
    if (!text)
        return fail_at(&c, POSE_ERR_INVALID_ARGUMENT, NULL, "no text");
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, size, &end, 0);
    if (!root) {
        size_t off = end && end >= text && end <= text + size ? (size_t)(end - text) : 0;
        return fail_at(&c, POSE_ERR_FORMAT, NULL, "line %d (offset %zu): not valid JSON",
                       line_of_offset(text, off), off);
    }
    int rc = POSE_OK;
    if (!cJSON_IsObject(root)) {
        rc = fail_at(&c, POSE_ERR_FORMAT, NULL, "the top level must be an object");
        goto done;
    }
    if (repeated_key(root)) {
        rc = fail_at(&c, POSE_ERR_FORMAT, NULL, "top-level key '%s' appears twice", repeated_key(root));
        goto done;
    }
    const cJSON *fmt = cJSON_GetObjectItemCaseSensitive(root, "format");
    if (!cJSON_IsString(fmt) || strcmp(fmt->valuestring, "pose-skeleton-template") != 0) {
        rc = fail_at(&c, POSE_ERR_FORMAT, NULL,
                     "'format' must be \"pose-skeleton-template\" (is this a skeleton template?)");
        goto done;
    }
    const cJSON *ver = cJSON_GetObjectItemCaseSensitive(root, "version");
    if (!cJSON_IsNumber(ver) || ver->valuedouble != 1.0) {
        rc = fail_at(&c, POSE_ERR_VERSION, NULL, "'version' must be 1 (this pose-bake reads version 1)");
        goto done;
    }
    float contact_mm = 4.0f;
    const cJSON *joints = NULL, *couplings = NULL;
    for (const cJSON *e = root->child; e; e = e->next) {
        if (strcmp(e->string, "format") == 0 || strcmp(e->string, "version") == 0 ||
            strcmp(e->string, "comment") == 0 || strcmp(e->string, "description") == 0) {
            continue;
        } else if (strcmp(e->string, "name") == 0) {
            if (!cJSON_IsString(e) || !valid_name(e->valuestring)) {
                rc = fail_at(&c, POSE_ERR_FORMAT, NULL, "'name' must be a string of 1..63 bytes");
                goto done;
            }
            strcpy(out->name, e->valuestring);
        } else if (strcmp(e->string, "contact_mm") == 0) {
            if (!cJSON_IsNumber(e) || !(e->valuedouble > 0.0 && e->valuedouble <= 100.0)) {
                rc = fail_at(&c, POSE_ERR_FORMAT, NULL, "'contact_mm' must be a number in (0, 100]");
                goto done;
            }
            contact_mm = (float)e->valuedouble;
        } else if (strcmp(e->string, "joints") == 0) {
            joints = e;
        } else if (strcmp(e->string, "couplings") == 0) {
            couplings = e;
        } else {
            rc = fail_at(&c, POSE_ERR_FORMAT, NULL, "unknown top-level key '%s'", e->string);
            goto done;
        }
    }
    if (!cJSON_IsArray(joints) || cJSON_GetArraySize(joints) < 1) {
        rc = fail_at(&c, POSE_ERR_FORMAT, NULL, "'joints' must be a non-empty array");
        goto done;
    }
    size_t n = (size_t)cJSON_GetArraySize(joints);
    if (n > 1024) {
        rc = fail_at(&c, POSE_ERR_FORMAT, NULL, "%zu joints; at most 1024", n);
        goto done;
    }
    out->joints = calloc(n, sizeof *out->joints);
    if (!out->joints) {
        rc = fail_at(&c, POSE_ERR_OUT_OF_MEMORY, NULL, "out of memory");
        goto done;
    }
    size_t i = 0;
    for (const cJSON *e = joints->child; e; e = e->next, i++) {
        out->joint_count = i + 1; /* so pp_template_free releases a partly read joint */
        rc = parse_joint(&c, e, i, out, contact_mm);
        if (rc < 0)
            goto done;
    }
    if (couplings) {
        const size_t nc = cJSON_IsArray(couplings) ? (size_t)cJSON_GetArraySize(couplings) : 0;
        if (!cJSON_IsArray(couplings) || nc > 1024) {
            rc = fail_at(&c, POSE_ERR_FORMAT, NULL, "'couplings' must be an array of at most 1024 "
                         "entries");
            goto done;
        }
        out->couplings = calloc(nc ? nc : 1, sizeof *out->couplings);
        if (!out->couplings) {
            rc = fail_at(&c, POSE_ERR_OUT_OF_MEMORY, NULL, "out of memory");
            goto done;
        }
        i = 0;
        for (const cJSON *e = couplings->child; e; e = e->next, i++) {
            rc = parse_coupling(&c, e, i, out);
            if (rc < 0)
                goto done;
            out->coupling_count = i + 1;
        }
    }
done:
    cJSON_Delete(root);
    if (rc < 0)
        pp_template_free(out);
    return rc;
}

int pp_template_load(const char *path, pp_template *out, char *err, size_t err_size)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, err_size, "%s: cannot open: %s", path, strerror(errno));
        return POSE_ERR_IO;
    }
    /* Templates are small; 4 MiB is far beyond any real one and bounds memory. */
    const size_t cap = 4u << 20;
    char *buf = malloc(cap + 1);
    if (!buf) {
        fclose(f);
        snprintf(err, err_size, "%s: out of memory", path);
        return POSE_ERR_OUT_OF_MEMORY;
    }
    size_t n = fread(buf, 1, cap + 1, f);
    int bad = ferror(f);
    fclose(f);
    if (bad || n > cap) {
        free(buf);
        snprintf(err, err_size, bad ? "%s: read error" : "%s: larger than 4 MiB; not a template", path);
        return POSE_ERR_IO;
    }
    int rc = pp_template_parse(buf, n, path, out, err, err_size);
    free(buf);
    return rc;
}

void pp_template_free(pp_template *t)
{
    if (!t)
        return;
    for (size_t i = 0; i < t->joint_count; i++) {
        free(t->joints[i].bones);
        free(t->joints[i].contact);
        free(t->joints[i].parent_contact);
    }
    free(t->joints);
    free(t->couplings);
    memset(t, 0, sizeof *t);
}

int pp_template_find_joint(const pp_template *t, const char *name)
{
    for (size_t i = 0; i < t->joint_count; i++)
        if (strcmp(t->joints[i].name, name) == 0)
            return (int)i;
    return -1;
}

int pp_template_joint_of_bone(const pp_template *t, const char *bone)
{
    for (size_t i = 0; i < t->joint_count; i++)
        if (in_list(t->joints[i].bones, t->joints[i].bone_count, bone))
            return (int)i;
    return -1;
}
