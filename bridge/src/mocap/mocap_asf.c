/* SPDX-License-Identifier: Apache-2.0
 * Acclaim ASF skeleton reader. Hand-written for the same reason as the BVH
 * reader (no packaged C library; a small keyword grammar).
 *
 * Mapping onto pb_clip: joint 0 is `root` (channels in `:root order`), then
 * one joint per bone at the bone's start (its parent's tip), offset by the
 * parent's direction * length, axis frame C from `axis`, channels from `dof`
 * applied in dof order; each leaf bone also gets an end site at its tip.
 * ASF directions and axes are given in the global frame, and C R C^-1 keeps
 * every joint's frame aligned with it at rest, so offsets need no change. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mocap.h"
#include "pb_math.h"
#include "pb_text.h"

enum { ASF_MAX_FILE = 16u << 20 };

typedef struct asf_bone {
    char name[PB_NAME_MAX];
    double dir[3], length;
    double axis_q[4];
    int dof_count;
    uint8_t dof[7];
    int has_limits;
    double lmin[7], lmax[7];
    int parent;   /* bone index, -1 = root */
    int joint;    /* index in the clip */
    long line;
} asf_bone;

typedef struct asf_parser {
    pb_text t;
    pb_error *err;
    double angle_scale; /* to degrees */
    double length_unit;
    uint8_t root_order[6];
    int root_chans;
    double root_pos[3], root_orient[3];
    int root_axes[3];
    asf_bone *bones;
    int bone_count, bone_cap;
} asf_parser;

static pose_status asf_expected(asf_parser *P, pb_token tk, const char *what)
{
    char buf[48];
    if (tk.n == 0)
        return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: expected %s, found end of line or file", P->t.name,
                       tk.line ? tk.line : P->t.line, what);
    return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: expected %s, found '%s'", P->t.name, tk.line, what,
                   pb_token_str(tk, buf, sizeof buf));
}

static pose_status asf_number(asf_parser *P, double *v, const char *what)
{
    pb_token tk = pb_text_next(&P->t, 1);
    int rc = pb_token_double(tk, v);
    if (rc == -2)
        return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: %s is not finite", P->t.name, tk.line, what);
    return rc == 0 ? POSE_OK : asf_expected(P, tk, what);
}

/* "XYZ" -> axes {0,1,2} */
static int parse_axis_order(pb_token tk, int axes[3])
{
    if (tk.n != 3)
        return -1;
    int seen = 0;
    for (int i = 0; i < 3; i++) {
        char c = tk.s[i] | 0x20;
        if (c < 'x' || c > 'z' || (seen & (1 << (c - 'x'))))
            return -1;
        seen |= 1 << (c - 'x');
        axes[i] = c - 'x';
    }
    return 0;
}

/* extrinsic composition: first listed applied first */
static void euler_extrinsic(const double deg[3], const int axes[3], double q[4])
{
    double r[4];
    pb_quat_identity(q);
    for (int i = 0; i < 3; i++) {
        pb_quat_axis_deg(axes[i], deg[axes[i]], r);
        pb_quat_mul(r, q, q);
    }
}

/* "rx" "TY" "l" -> pb_chan_kind */
static int dof_kind(pb_token tk)
{
    if (tk.n == 1 && (tk.s[0] | 0x20) == 'l')
        return PB_CH_LENGTH;
    if (tk.n != 2)
        return -1;
    char a = tk.s[0] | 0x20, b = tk.s[1] | 0x20;
    if (b < 'x' || b > 'z')
        return -1;
    if (a == 't')
        return PB_CH_XPOS + (b - 'x');
    if (a == 'r')
        return PB_CH_XROT + (b - 'x');
    return -1;
}

static pose_status parse_units(asf_parser *P)
{
    for (;;) {
        pb_text save = P->t;
        pb_token key = pb_text_next(&P->t, 1);
        if (key.n == 0 || key.s[0] == ':') {
            P->t = save;
            return POSE_OK;
        }
        pb_token val = pb_text_next_in_line(&P->t);
        if (pb_token_is(key, "angle")) {
            if (pb_token_is_nocase(val, "deg"))
                P->angle_scale = 1.0;
            else if (pb_token_is_nocase(val, "rad"))
                P->angle_scale = PB_RAD2DEG;
            else
                return asf_expected(P, val, "'deg' or 'rad' after 'angle'");
        } else if (pb_token_is(key, "length")) {
            double v;
            if (pb_token_double(val, &v) != 0 || !(v > 0))
                return asf_expected(P, val, "a positive length unit");
            P->length_unit = v;
        } else {
            double v; /* mass and unknown units: a value, ignored */
            if (pb_token_double(val, &v) != 0 && val.n == 0)
                return asf_expected(P, val, "a unit value");
        }
    }
}

static pose_status parse_root(asf_parser *P)
{
    for (;;) {
        pb_text save = P->t;
        pb_token key = pb_text_next(&P->t, 1);
        if (key.n == 0 || key.s[0] == ':') {
            P->t = save;
            return POSE_OK;
        }
        if (pb_token_is(key, "order")) {
            P->root_chans = 0;
            for (;;) {
                pb_token d = pb_text_next_in_line(&P->t);
                if (d.n == 0)
                    break;
                int k = dof_kind(d);
                if (k < 0 || k == PB_CH_LENGTH || P->root_chans == 6)
                    return asf_expected(P, d, "TX TY TZ RX RY RZ in some order");
                P->root_order[P->root_chans++] = (uint8_t)k;
            }
        } else if (pb_token_is(key, "axis")) {
            pb_token a = pb_text_next_in_line(&P->t);
            if (parse_axis_order(a, P->root_axes) != 0)
                return asf_expected(P, a, "an axis order such as XYZ");
        } else if (pb_token_is(key, "position") || pb_token_is(key, "orientation")) {
            double *v = key.s[0] == 'p' ? P->root_pos : P->root_orient;
            for (int i = 0; i < 3; i++) {
                pose_status s = asf_number(P, &v[i], "a root coordinate");
                if (s)
                    return s;
            }
        } else {
            return asf_expected(P, key, "order, axis, position or orientation in :root");
        }
    }
}

static int find_bone(const asf_parser *P, pb_token tk)
{
    for (int b = 0; b < P->bone_count; b++)
        if (strlen(P->bones[b].name) == tk.n && memcmp(P->bones[b].name, tk.s, tk.n) == 0)
            return b;
    return -1;
}

static pose_status parse_limits(asf_parser *P, asf_bone *B)
{
    for (int d = 0; d < B->dof_count; d++) {
        double v[2];
        pb_text_skip_space(&P->t, 1);
        if (*P->t.p != '(')
            return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: expected '(' opening limit %d of %d for bone %s",
                           P->t.name, P->t.line, d + 1, B->dof_count, B->name);
        P->t.p++;
        for (int i = 0; i < 2; i++) {
            pb_text_skip_space(&P->t, 0);
            char *e;
            v[i] = strtod(P->t.p, &e);
            if (e == P->t.p || e > P->t.end || v[i] != v[i])
                return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: expected a limit value for bone %s",
                               P->t.name, P->t.line, B->name);
            P->t.p = e;
        }
        pb_text_skip_space(&P->t, 0);
        if (*P->t.p != ')')
            return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: expected ')' closing limit %d for bone %s",
                           P->t.name, P->t.line, d + 1, B->name);
        P->t.p++;
        double s = B->dof[d] >= PB_CH_XROT && B->dof[d] <= PB_CH_ZROT ? P->angle_scale : 1.0;
        B->lmin[d] = v[0] * s;
        B->lmax[d] = v[1] * s;
    }
    B->has_limits = 1;
    return POSE_OK;
}

static pose_status parse_bone(asf_parser *P)
{
    if (P->bone_count == P->bone_cap) {
        int cap = P->bone_cap ? P->bone_cap * 2 : 32;
        if (cap > PB_MAX_JOINTS / 2)
            return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: too many bones", P->t.name, P->t.line);
        asf_bone *nb = realloc(P->bones, (size_t)cap * sizeof *nb);
        if (!nb)
            return pb_fail(P->err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", P->t.name);
        P->bones = nb;
        P->bone_cap = cap;
    }
    asf_bone *B = &P->bones[P->bone_count];
    memset(B, 0, sizeof *B);
    pb_quat_identity(B->axis_q);
    B->line = P->t.line;
    int have_dir = 0, have_len = 0;
    for (;;) {
        pb_token key = pb_text_next(&P->t, 1);
        if (pb_token_is(key, "end"))
            break;
        pose_status s = POSE_OK;
        if (pb_token_is(key, "id")) {
            pb_text_next_in_line(&P->t);
        } else if (pb_token_is(key, "name")) {
            pb_token n = pb_text_next_in_line(&P->t);
            if (n.n == 0 || n.n >= PB_NAME_MAX - 5)
                return asf_expected(P, n, "a bone name (1..58 characters)");
            if (find_bone(P, n) >= 0 || pb_token_is(n, "root"))
                return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: bone name '%.*s' used twice", P->t.name,
                               n.line, (int)n.n, n.s);
            pb_token_str(n, B->name, sizeof B->name);
        } else if (pb_token_is(key, "direction")) {
            for (int i = 0; i < 3 && !s; i++)
                s = asf_number(P, &B->dir[i], "a direction component");
            have_dir = 1;
        } else if (pb_token_is(key, "length")) {
            s = asf_number(P, &B->length, "a bone length");
            if (!s && B->length < 0)
                return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: negative bone length", P->t.name, P->t.line);
            have_len = 1;
        } else if (pb_token_is(key, "axis")) {
            double a[3];
            int axes[3];
            for (int i = 0; i < 3 && !s; i++)
                s = asf_number(P, &a[i], "an axis angle");
            if (s)
                return s;
            pb_token o = pb_text_next_in_line(&P->t);
            if (parse_axis_order(o, axes) != 0)
                return asf_expected(P, o, "an axis order such as XYZ");
            for (int i = 0; i < 3; i++)
                a[i] *= P->angle_scale;
            euler_extrinsic(a, axes, B->axis_q);
        } else if (pb_token_is(key, "dof")) {
            for (;;) {
                pb_token d = pb_text_next_in_line(&P->t);
                if (d.n == 0)
                    break;
                int k = dof_kind(d);
                if (k < 0 || B->dof_count == 7)
                    return asf_expected(P, d, "a dof (rx ry rz tx ty tz l), at most 7");
                B->dof[B->dof_count++] = (uint8_t)k;
            }
        } else if (pb_token_is(key, "limits")) {
            s = parse_limits(P, B);
        } else if (pb_token_is(key, "bodymass") || pb_token_is(key, "cofmass")) {
            pb_text_skip_line(&P->t);
        } else {
            return asf_expected(P, key, "a bone field (id, name, direction, length, axis, dof, limits) or 'end'");
        }
        if (s)
            return s;
    }
    if (!B->name[0] || !have_dir || !have_len)
        return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: bone block lacks %s", P->t.name, B->line,
                       !B->name[0] ? "a name" : !have_dir ? "a direction" : "a length");
    double l = pb_vec_len(B->dir);
    if (l < 1e-12 && B->length > 0)
        return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: bone %s has a zero direction", P->t.name, B->line, B->name);
    B->parent = -2; /* not yet placed by :hierarchy */
    P->bone_count++;
    return POSE_OK;
}

static pose_status parse_hierarchy(asf_parser *P)
{
    pb_token tk = pb_text_next(&P->t, 1);
    if (!pb_token_is(tk, "begin"))
        return asf_expected(P, tk, "'begin' after :hierarchy");
    for (;;) {
        pb_token par = pb_text_next(&P->t, 1);
        if (pb_token_is(par, "end"))
            return POSE_OK;
        if (par.n == 0)
            return asf_expected(P, par, "'end' closing :hierarchy");
        int pb = -1;
        if (!pb_token_is(par, "root")) {
            pb = find_bone(P, par);
            if (pb < 0)
                return asf_expected(P, par, "a bone defined in :bonedata (parent)");
            if (P->bones[pb].parent == -2)
                return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: bone %s is used as a parent before it is attached",
                               P->t.name, par.line, P->bones[pb].name);
        }
        for (;;) {
            pb_token ch = pb_text_next_in_line(&P->t);
            if (ch.n == 0)
                break;
            int cb = find_bone(P, ch);
            if (cb < 0)
                return asf_expected(P, ch, "a bone defined in :bonedata (child)");
            if (P->bones[cb].parent != -2)
                return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: bone %s has two parents", P->t.name, ch.line,
                               P->bones[cb].name);
            P->bones[cb].parent = pb;
        }
    }
}

/* Depth-first order so parents precede children in the clip. */
static void add_bone_joints(const asf_parser *P, pb_clip *c, int parent_bone, int parent_joint)
{
    for (int b = 0; b < P->bone_count; b++) {
        const asf_bone *B = &P->bones[b];
        if (B->parent != parent_bone)
            continue;
        pb_clip_joint *J = &c->joints[c->joint_count];
        int j = c->joint_count++;
        snprintf(J->name, sizeof J->name, "%.63s", B->name);
        J->parent = parent_joint;
        if (parent_bone >= 0) {
            const asf_bone *Pb = &P->bones[parent_bone];
            for (int i = 0; i < 3; i++)
                J->offset[i] = Pb->dir[i] * Pb->length;
        }
        pb_quat_copy(J->axis_q, B->axis_q);
        J->extrinsic = 1;
        J->chan_first = c->channel_count;
        J->chan_count = B->dof_count;
        memcpy(J->chan, B->dof, sizeof J->chan);
        J->has_limits = B->has_limits;
        memcpy(J->limit_min, B->lmin, sizeof J->limit_min);
        memcpy(J->limit_max, B->lmax, sizeof J->limit_max);
        c->channel_count += B->dof_count;
        ((asf_bone *)B)->joint = j;
        int children = 0;
        for (int k = 0; k < P->bone_count; k++)
            children += P->bones[k].parent == b;
        if (children) {
            add_bone_joints(P, c, b, j);
        } else {
            pb_clip_joint *E = &c->joints[c->joint_count++];
            snprintf(E->name, sizeof E->name, "%.58s_end", B->name);
            E->parent = j;
            E->is_end = 1;
            pb_quat_identity(E->axis_q);
            E->chan_first = c->channel_count;
            for (int i = 0; i < 3; i++)
                E->offset[i] = B->dir[i] * B->length;
        }
    }
}

static pose_status build_clip(asf_parser *P, pb_clip **out)
{
    for (int b = 0; b < P->bone_count; b++)
        if (P->bones[b].parent == -2)
            return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: bone %s is not attached in :hierarchy", P->t.name,
                           P->bones[b].line, P->bones[b].name);
    pb_clip *c = pb_clip_alloc(1 + 2 * P->bone_count);
    if (!c)
        return pb_fail(P->err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", P->t.name);
    snprintf(c->format, sizeof c->format, "asf-amc");
    snprintf(c->path, sizeof c->path, "%s", P->t.name);
    c->length_unit = P->length_unit;
    pb_clip_joint *R = &c->joints[0];
    snprintf(R->name, sizeof R->name, "root");
    R->parent = -1;
    R->extrinsic = 1;
    memcpy(R->offset, P->root_pos, sizeof R->offset);
    double o[3] = {P->root_orient[0] * P->angle_scale, P->root_orient[1] * P->angle_scale,
                   P->root_orient[2] * P->angle_scale};
    euler_extrinsic(o, P->root_axes, R->axis_q);
    R->chan_count = P->root_chans;
    memcpy(R->chan, P->root_order, 6);
    c->channel_count = P->root_chans;
    c->joint_count = 1;
    add_bone_joints(P, c, -1, 0);
    *out = c;
    return POSE_OK;
}

static pose_status parse_asf(asf_parser *P, pb_clip **out)
{
    int have_root = 0, have_bones = 0, have_hier = 0;
    for (;;) {
        pb_token sec = pb_text_next(&P->t, 1);
        if (sec.n == 0)
            break;
        if (sec.s[0] != ':')
            return asf_expected(P, sec, "a section keyword (:version, :units, :root, :bonedata, :hierarchy ...)");
        pose_status s = POSE_OK;
        if (pb_token_is(sec, ":units")) {
            s = parse_units(P);
        } else if (pb_token_is(sec, ":root")) {
            s = parse_root(P);
            have_root = 1;
        } else if (pb_token_is(sec, ":bonedata")) {
            have_bones = 1;
            for (;;) {
                pb_text save = P->t;
                pb_token b = pb_text_next(&P->t, 1);
                if (b.n == 0 || b.s[0] == ':') {
                    P->t = save;
                    break;
                }
                if (!pb_token_is(b, "begin"))
                    return asf_expected(P, b, "'begin' opening a bone");
                if ((s = parse_bone(P)) != POSE_OK)
                    return s;
            }
        } else if (pb_token_is(sec, ":hierarchy")) {
            s = parse_hierarchy(P);
            have_hier = 1;
        } else {
            /* :version, :name, :documentation and unknown sections: skip
             * lines until the next line that starts with ':' */
            pb_text_skip_line(&P->t);
            for (;;) {
                pb_text_skip_space(&P->t, 1);
                if (P->t.p >= P->t.end || *P->t.p == ':')
                    break;
                pb_text_skip_line(&P->t);
            }
        }
        if (s)
            return s;
    }
    if (!have_root || !have_bones || !have_hier)
        return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: missing section %s", P->t.name, P->t.line,
                       !have_root ? ":root" : !have_bones ? ":bonedata" : ":hierarchy");
    return build_clip(P, out);
}

pose_status pb_asf_parse(const char *text, size_t size, const char *name, pb_clip **out, pb_error *err)
{
    if (!out || (!text && size))
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_asf_parse: NULL argument");
    *out = NULL;
    char *copy = malloc(size + 1);
    if (!copy)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    if (size)
        memcpy(copy, text, size);
    copy[size] = '\0';
    asf_parser P = {.err = err, .angle_scale = 1.0, .length_unit = 1.0, .root_axes = {0, 1, 2}};
    pb_text_init(&P.t, copy, size, name);
    pose_status s = parse_asf(&P, out);
    free(P.bones);
    free(copy);
    return s;
}

pose_status pb_asf_load(const char *path, pb_clip **out, pb_error *err)
{
    char *data;
    size_t size;
    if (out)
        *out = NULL;
    if (!path || !out)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_asf_load: NULL argument");
    pose_status s = pb_read_file(path, ASF_MAX_FILE, &data, &size, err);
    if (s)
        return s;
    s = pb_asf_parse(data, size, path, out, err);
    free(data);
    return s;
}
