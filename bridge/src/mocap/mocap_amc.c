/* SPDX-License-Identifier: Apache-2.0
 * Acclaim AMC motion reader (fully specified: every bone with dofs appears
 * once per frame, values in its dof order; the root in `:root order`). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mocap.h"
#include "pb_math.h"
#include "pb_text.h"
#include "pb_warn.h"

enum { AMC_MAX_FILE = 1u << 30 };

static int joint_by_token(const pb_clip *c, pb_token tk)
{
    for (int j = 0; j < c->joint_count; j++)
        if (!c->joints[j].is_end && strlen(c->joints[j].name) == tk.n && memcmp(c->joints[j].name, tk.s, tk.n) == 0)
            return j;
    return -1;
}

static int is_integer(pb_token tk)
{
    if (tk.n == 0)
        return 0;
    for (size_t i = 0; i < tk.n; i++)
        if (tk.s[i] < '0' || tk.s[i] > '9')
            return 0;
    return 1;
}

pose_status pb_amc_parse(pb_clip *clip, const char *text, size_t size, const char *name, pb_error *err)
{
    if (!clip || (!text && size))
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_amc_parse: NULL argument");
    char *copy = malloc(size + 1);
    if (!copy)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    if (size)
        memcpy(copy, text, size);
    copy[size] = '\0';
    pb_text T;
    pb_text_init(&T, copy, size, name);
    const size_t per = (size_t)clip->channel_count;
    double angle_scale = 1.0;
    double *frames = NULL;
    size_t count = 0, cap = 0;
    long first_number = -1;
    size_t absurd = 0; /* values beyond PB_MOCAP_VALUE_MAX; the first one's place and value: */
    long absurd_line = 0;
    double absurd_value = 0;
    const char *absurd_bone = "";
    unsigned char *seen = calloc((size_t)clip->joint_count + 1, 1);
    pose_status s = seen ? POSE_OK : pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    char buf[64];
    while (!s) {
        pb_text_skip_space(&T, 1);
        if (T.p >= T.end)
            break;
        pb_token tk = pb_text_next_in_line(&T);
        if (tk.s[0] == ':') {
            if (pb_token_is_nocase(tk, ":RADIANS"))
                angle_scale = PB_RAD2DEG;
            else if (pb_token_is_nocase(tk, ":DEGREES"))
                angle_scale = 1.0;
            pb_text_skip_line(&T);
            continue;
        }
        if (is_integer(tk)) {
            long n = 0;
            if (pb_token_count(tk, 1000000000L, &n) != 0) {
                s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: frame number out of range", T.name, tk.line);
                break;
            }
            if (count > 0) { /* the previous frame must be complete */
                for (int j = 0; j < clip->joint_count; j++)
                    if (clip->joints[j].chan_count > 0 && !seen[j]) {
                        s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: frame %ld lacks bone %s", T.name, tk.line,
                                    first_number + (long)count - 1, clip->joints[j].name);
                        break;
                    }
                if (s)
                    break;
            }
            if (first_number < 0)
                first_number = n;
            else if (n != first_number + (long)count) {
                s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: expected frame number %ld, found %ld", T.name,
                            tk.line, first_number + (long)count, n);
                break;
            }
            if (count == cap) {
                size_t nc = cap ? cap * 2 : 256;
                /* each frame takes at least 2 bytes per value: a bound the file size gives */
                if (per && nc > size / 2 / per + 2)
                    nc = size / 2 / per + 2;
                if (nc <= count) {
                    s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: more frames than the file can hold", T.name, tk.line);
                    break;
                }
                double *nf = realloc(frames, nc * (per ? per : 1) * sizeof *nf);
                if (!nf) {
                    s = pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory at frame %ld", T.name, n);
                    break;
                }
                frames = nf;
                cap = nc;
            }
            memset(frames + count * per, 0, per * sizeof *frames);
            memset(seen, 0, (size_t)clip->joint_count);
            count++;
            if (pb_text_next_in_line(&T).n != 0) {
                s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: expected only a frame number on this line", T.name,
                            tk.line);
                break;
            }
            continue;
        }
        if (count == 0) {
            s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: expected a frame number before '%s'", T.name, tk.line,
                        pb_token_str(tk, buf, sizeof buf));
            break;
        }
        int j = joint_by_token(clip, tk);
        if (j < 0) {
            s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: expected a bone of the skeleton, found '%s'", T.name, tk.line,
                        pb_token_str(tk, buf, sizeof buf));
            break;
        }
        if (seen[j]) {
            s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: bone %s appears twice in frame %ld", T.name, tk.line,
                        clip->joints[j].name, first_number + (long)count - 1);
            break;
        }
        seen[j] = 1;
        const pb_clip_joint *J = &clip->joints[j];
        double *v = frames + (count - 1) * per + J->chan_first;
        for (int c = 0; c < J->chan_count && !s; c++) {
            pb_token n = pb_text_next_in_line(&T);
            int rc = pb_token_double(n, &v[c]);
            if (rc != 0)
                s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: bone %s: expected %d %svalues, %s", T.name, tk.line,
                            J->name, J->chan_count, rc == -2 ? "finite " : "",
                            n.n ? "found a non-number" : "found fewer");
            else {
                if (J->chan[c] >= PB_CH_XROT && J->chan[c] <= PB_CH_ZROT)
                    v[c] *= angle_scale;
                if (!isfinite(v[c])) /* finite radians, too many degrees */
                    s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: bone %s: value %d is not finite in degrees", T.name,
                                tk.line, J->name, c);
                else if (fabs(v[c]) > PB_MOCAP_VALUE_MAX && !absurd++) {
                    absurd_line = tk.line;
                    absurd_value = v[c];
                    absurd_bone = J->name;
                }
            }
        }
        if (!s && pb_text_next_in_line(&T).n != 0)
            s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: bone %s: more than %d values", T.name, tk.line, J->name,
                        J->chan_count);
    }
    if (!s && count > 0)
        for (int j = 0; j < clip->joint_count; j++)
            if (clip->joints[j].chan_count > 0 && !seen[j]) {
                s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: last frame %ld lacks bone %s", T.name, T.line,
                            first_number + (long)count - 1, clip->joints[j].name);
                break;
            }
    if (!s && count == 0)
        s = pb_fail(err, POSE_ERR_FORMAT, "%s:%ld: no frames", T.name, T.line);
    if (!s && absurd)
        pb_warn("%s:%ld: bone %s value %g is beyond +-%g (degrees or length units): kept; %zu such values in the "
                "file",
                T.name, absurd_line, absurd_bone, absurd_value, PB_MOCAP_VALUE_MAX, absurd);
    free(seen);
    free(copy);
    if (s) {
        free(frames);
        return s;
    }
    free(clip->frames);
    clip->frames = frames;
    clip->frame_count = count;
    snprintf(clip->path, sizeof clip->path, "%s", name ? name : "<memory>");
    return POSE_OK;
}

pose_status pb_amc_load(pb_clip *clip, const char *path, pb_error *err)
{
    char *data;
    size_t size;
    if (!path || !clip)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_amc_load: NULL argument");
    pose_status s = pb_read_file(path, AMC_MAX_FILE, &data, &size, err);
    if (s)
        return s;
    s = pb_amc_parse(clip, data, size, path, err);
    free(data);
    return s;
}

static int has_suffix(const char *s, const char *suf)
{
    size_t n = strlen(s), m = strlen(suf);
    if (n < m)
        return 0;
    for (size_t i = 0; i < m; i++)
        if ((s[n - m + i] | 0x20) != suf[i])
            return 0;
    return 1;
}

/* CMU naming: "dir/01_01.amc" -> "dir/01.asf" (the subject's skeleton) */
static int sibling_asf(const char *amc, char *out, size_t size)
{
    int n = snprintf(out, size, "%s", amc);
    if (n < 0 || (size_t)n >= size)
        return -1;
    char *slash = strrchr(out, '/');
    char *us = strchr(slash ? slash + 1 : out, '_');
    if (!us || (size_t)(us - out) + 5 > size)
        return -1;
    memcpy(us, ".asf", 5);
    FILE *f = fopen(out, "rb");
    if (!f)
        return -1;
    fclose(f);
    return 0;
}

pose_status pb_clip_load(const char *path, const char *skeleton, pb_clip **out, pb_error *err)
{
    if (!out || !path)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_clip_load: NULL argument");
    *out = NULL;
    char found[1024];
    if (has_suffix(path, ".amc") && !skeleton && sibling_asf(path, found, sizeof found) == 0)
        skeleton = found;
    if (has_suffix(path, ".amc") || skeleton) {
        if (!skeleton)
            return pb_fail(err, POSE_ERR_INVALID_ARGUMENT,
                           "%s: an AMC file needs its ASF skeleton (--skeleton; none found beside it)", path);
        pb_clip *c;
        pose_status s = pb_asf_load(skeleton, &c, err);
        if (s)
            return s;
        if ((s = pb_amc_load(c, path, err)) != POSE_OK) {
            pb_clip_free(c);
            return s;
        }
        *out = c;
        return POSE_OK;
    }
    if (has_suffix(path, ".asf"))
        return pb_asf_load(path, out, err);
    return pb_bvh_load(path, out, err);
}
