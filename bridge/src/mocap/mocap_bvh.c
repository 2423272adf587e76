/* SPDX-License-Identifier: Apache-2.0
 * BVH reader. Hand-written: there is no maintained C BVH library in Debian,
 * and the format is a small token grammar. Accepts any number (0..6) and
 * order of channels per joint, any rotation order, End Sites, CRLF, tabs and
 * trailing blanks. Every error names file, line and what was expected. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mocap.h"
#include "pb_math.h"
#include "pb_text.h"
#include "pb_warn.h"
#include "timeline.h"

enum { BVH_MAX_DEPTH = 256, BVH_MAX_FILE = 1u << 30 };

typedef struct bvh_parser {
    pb_text t;
    pb_clip *clip;
    int cap;
    pb_error *err;
} bvh_parser;

static pose_status expected(bvh_parser *P, pb_token tk, const char *what)
{
    char buf[48];
    if (tk.n == 0)
        return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: expected %s, found end of file", P->t.name,
                       P->t.line, what);
    return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: expected %s, found '%s'", P->t.name, tk.line, what,
                   pb_token_str(tk, buf, sizeof buf));
}

static pose_status read_number(bvh_parser *P, double *v, const char *what)
{
    pb_token tk = pb_text_next(&P->t, 0);
    int rc = pb_token_double(tk, v);
    if (rc == -2) {
        char buf[48];
        return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: %s is not finite ('%s')", P->t.name, tk.line, what,
                       pb_token_str(tk, buf, sizeof buf));
    }
    return rc == 0 ? POSE_OK : expected(P, tk, what);
}

static int new_joint(bvh_parser *P, int parent, pb_token name, int is_end)
{
    pb_clip *c = P->clip;
    if (c->joint_count >= PB_MAX_JOINTS)
        return -1;
    if (c->joint_count == P->cap) {
        int cap = P->cap * 2;
        pb_clip_joint *j = realloc(c->joints, (size_t)cap * sizeof *j);
        if (!j)
            return -2;
        c->joints = j;
        P->cap = cap;
    }
    pb_clip_joint *J = &c->joints[c->joint_count];
    memset(J, 0, sizeof *J);
    J->parent = parent;
    J->is_end = is_end;
    pb_quat_identity(J->axis_q);
    J->chan_first = c->channel_count;
    if (is_end)
        snprintf(J->name, sizeof J->name, "%.*s_end", PB_NAME_MAX - 5, c->joints[parent].name);
    else
        pb_token_str(name, J->name, sizeof J->name);
    return c->joint_count++;
}

static int channel_kind(pb_token tk)
{
    static const char *names[6] = {"Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"};
    for (int k = 0; k < 6; k++)
        if (pb_token_is_nocase(tk, names[k]))
            return k;
    return -1;
}

/* Body of a joint after its name: { OFFSET x y z [CHANNELS n ...] children } */
static pose_status parse_hierarchy(bvh_parser *P)
{
    int stack[BVH_MAX_DEPTH];
    int depth = 0;
    pb_token tk = pb_text_next(&P->t, 0);
    if (!pb_token_is(tk, "ROOT"))
        return expected(P, tk, "ROOT");
    int parent = -1, is_end = 0;
    for (;;) {
        /* at a joint header: name already in tk's successor unless End Site */
        pb_token name = {0};
        if (!is_end) {
            name = pb_text_next(&P->t, 0);
            if (name.n == 0 || pb_token_is(name, "{"))
                return expected(P, name, "a joint name");
        }
        int j = new_joint(P, parent, name, is_end);
        if (j == -1)
            return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: more than %d joints", P->t.name, P->t.line,
                           PB_MAX_JOINTS);
        if (j < 0)
            return pb_fail(P->err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", P->t.name);
        pb_clip_joint *J = &P->clip->joints[j];
        tk = pb_text_next(&P->t, 0);
        if (!pb_token_is(tk, "{"))
            return expected(P, tk, "'{'");
        if (depth >= BVH_MAX_DEPTH)
            return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: hierarchy deeper than %d", P->t.name, tk.line,
                           BVH_MAX_DEPTH);
        stack[depth++] = j;
        tk = pb_text_next(&P->t, 0);
        if (!pb_token_is(tk, "OFFSET"))
            return expected(P, tk, "OFFSET");
        for (int a = 0; a < 3; a++) {
            pose_status s = read_number(P, &J->offset[a], "an OFFSET coordinate");
            if (s)
                return s;
        }
        tk = pb_text_next(&P->t, 0);
        if (!is_end && pb_token_is(tk, "CHANNELS")) {
            long n;
            pb_token cn = pb_text_next(&P->t, 0);
            if (pb_token_count(cn, 6, &n) != 0)
                return expected(P, cn, "a channel count from 0 to 6");
            for (long c = 0; c < n; c++) {
                pb_token ct = pb_text_next(&P->t, 0);
                int k = channel_kind(ct);
                if (k < 0)
                    return expected(P, ct, "a channel name (Xposition ... Zrotation)");
                J->chan[c] = (uint8_t)k;
            }
            J->chan_count = (int)n;
            P->clip->channel_count += (int)n;
            tk = pb_text_next(&P->t, 0);
        }
        /* children, then '}' closing this joint (and possibly its ancestors) */
        for (;;) {
            if (pb_token_is(tk, "JOINT") && !is_end) {
                parent = j;
                is_end = 0;
                break;
            }
            if (pb_token_is(tk, "End") && !is_end) {
                pb_token site = pb_text_next(&P->t, 0);
                if (!pb_token_is(site, "Site"))
                    return expected(P, site, "'Site' after 'End'");
                parent = j;
                is_end = 1;
                break;
            }
            if (!pb_token_is(tk, "}"))
                return expected(P, tk, is_end ? "'}' closing the End Site" : "JOINT, End Site or '}'");
            depth--;
            if (depth == 0)
                return POSE_OK;
            j = stack[depth - 1];
            is_end = 0;
            tk = pb_text_next(&P->t, 0);
        }
    }
}

static pose_status parse_motion(bvh_parser *P)
{
    pb_clip *c = P->clip;
    pb_token tk = pb_text_next(&P->t, 0);
    if (pb_token_is(tk, "ROOT"))
        return pb_fail(P->err, POSE_ERR_UNSUPPORTED, "%s:%ld: more than one ROOT is not supported",
                       P->t.name, tk.line);
    if (!pb_token_is(tk, "MOTION"))
        return expected(P, tk, "MOTION");
    tk = pb_text_next(&P->t, 0);
    if (!pb_token_is(tk, "Frames:"))
        return expected(P, tk, "'Frames:'");
    long frames;
    tk = pb_text_next(&P->t, 0);
    if (pb_token_count(tk, 1000000000L, &frames) != 0)
        return expected(P, tk, "a frame count");
    pb_token f1 = pb_text_next(&P->t, 0), f2 = pb_text_next(&P->t, 0);
    if (!pb_token_is(f1, "Frame") || !pb_token_is(f2, "Time:"))
        return expected(P, pb_token_is(f1, "Frame") ? f2 : f1, "'Frame Time:'");
    double ft;
    pose_status s = read_number(P, &ft, "a frame time in seconds");
    if (s)
        return s;
    if (!(ft > 0.0) || ft > 3600.0)
        return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: frame time %g s is not in (0, 3600]", P->t.name,
                       P->t.line, ft);
    c->frame_time = ft;
    /* Frames are evenly spaced, so this is the one time a clip can jump: a
     * real-time replay waits a frame time between frames. */
    if ((double)ft * 1e9 > (double)PB_TIMELINE_MAX_GAP_NS)
        pb_warn("%s:%ld: frame time %g s: a real-time replay waits that long between frames", P->t.name,
                P->t.line, ft);
    /* Each value takes at least two bytes ("0 "): refuse counts the file
     * cannot hold before allocating anything. */
    size_t remain = (size_t)(P->t.end - P->t.p);
    size_t per = (size_t)c->channel_count;
    if (per > 0 && (size_t)frames > (remain / 2 + 1) / per)
        return pb_fail(P->err, POSE_ERR_FORMAT,
                       "%s:%ld: 'Frames: %ld' with %zu channels needs more data than the %zu bytes left",
                       P->t.name, tk.line, frames, per, remain);
    c->frame_count = (size_t)frames;
    if (per > 0 && frames > 0) {
        c->frames = malloc((size_t)frames * per * sizeof *c->frames);
        if (!c->frames)
            return pb_fail(P->err, POSE_ERR_OUT_OF_MEMORY, "%s: cannot allocate %ld frames", P->t.name, frames);
    }
    pb_text_skip_line(&P->t); /* rest of the Frame Time line */
    double *v = c->frames;
    size_t absurd = 0; /* values beyond PB_MOCAP_VALUE_MAX; the first one's place and value: */
    long absurd_line = 0, absurd_frame = 0;
    size_t absurd_index = 0;
    double absurd_value = 0;
    for (long f = 0; f < frames; f++) {
        pb_text_skip_space(&P->t, 0);
        long line = P->t.line;
        for (size_t k = 0; k < per; k++) {
            pb_token n = pb_text_next_in_line(&P->t);
            if (n.n == 0)
                return pb_fail(P->err, POSE_ERR_FORMAT,
                               "%s:%ld: frame %ld has %zu values, expected %zu (one per channel)%s", P->t.name,
                               line, f, k, per, P->t.p >= P->t.end ? "; file ends early" : "");
            int rc = pb_token_double(n, v);
            if (rc != 0) {
                char buf[48];
                return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: frame %ld value %zu: expected a %snumber, found '%s'",
                               P->t.name, line, f, k, rc == -2 ? "finite " : "", pb_token_str(n, buf, sizeof buf));
            }
            if (fabs(*v) > PB_MOCAP_VALUE_MAX && !absurd++) {
                absurd_line = line;
                absurd_frame = f;
                absurd_index = k;
                absurd_value = *v;
            }
            v++;
        }
        pb_token extra = pb_text_next_in_line(&P->t);
        if (extra.n != 0)
            return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: frame %ld has more than %zu values", P->t.name, line,
                           f, per);
    }
    pb_token rest = pb_text_next(&P->t, 0);
    if (rest.n != 0)
        return pb_fail(P->err, POSE_ERR_FORMAT, "%s:%ld: data after the %ld frames that 'Frames:' announced",
                       P->t.name, rest.line, frames);
    if (absurd)
        pb_warn("%s:%ld: frame %ld value %zu is %g, beyond +-%g (degrees or length units): kept; %zu such values "
                "in the file",
                P->t.name, absurd_line, absurd_frame, absurd_index, absurd_value, PB_MOCAP_VALUE_MAX, absurd);
    return POSE_OK;
}

/* Parse a NUL-terminated buffer of `size` bytes (text[size] == '\0'). */
static pose_status parse_terminated(const char *text, size_t size, const char *name, pb_clip **out, pb_error *err)
{
    bvh_parser P = {.cap = 64, .err = err};
    pb_text_init(&P.t, text, size, name);
    P.clip = pb_clip_alloc(P.cap);
    if (!P.clip)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", P.t.name);
    snprintf(P.clip->format, sizeof P.clip->format, "bvh");
    snprintf(P.clip->path, sizeof P.clip->path, "%s", P.t.name);
    pose_status s;
    pb_token tk = pb_text_next(&P.t, 0);
    if (!pb_token_is(tk, "HIERARCHY"))
        s = expected(&P, tk, "HIERARCHY");
    else if ((s = parse_hierarchy(&P)) == POSE_OK)
        s = parse_motion(&P);
    if (s != POSE_OK) {
        pb_clip_free(P.clip);
        return s;
    }
    *out = P.clip;
    return POSE_OK;
}

pose_status pb_bvh_parse(const char *text, size_t size, const char *name, pb_clip **out, pb_error *err)
{
    if (!out || (!text && size))
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_bvh_parse: NULL argument");
    *out = NULL;
    /* the tokenizer relies on a terminating NUL (number parsing stops there) */
    char *copy = malloc(size + 1);
    if (!copy)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", name ? name : "<memory>");
    if (size)
        memcpy(copy, text, size);
    copy[size] = '\0';
    pose_status s = parse_terminated(copy, size, name, out, err);
    free(copy);
    return s;
}

pose_status pb_bvh_load(const char *path, pb_clip **out, pb_error *err)
{
    char *data;
    size_t size;
    if (out)
        *out = NULL;
    if (!path || !out)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_bvh_load: NULL argument");
    pose_status s = pb_read_file(path, BVH_MAX_FILE, &data, &size, err);
    if (s)
        return s;
    s = parse_terminated(data, size, path, out, err); /* pb_read_file terminates the buffer */
    free(data);
    return s;
}
