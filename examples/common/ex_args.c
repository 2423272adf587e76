/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

int ex_parse_long(const char *opt, const char *s, long lo, long hi, long *out, char *err, size_t err_size)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (end == s || *end || errno || v < lo || v > hi) {
        snprintf(err, err_size, "%s: expected an integer in [%ld, %ld], got '%s'", opt, lo, hi, s);
        return -1;
    }
    *out = v;
    return 0;
}

int ex_parse_double(const char *opt, const char *s, double lo, double hi, double *out, char *err,
                    size_t err_size)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno || !isfinite(v) || v < lo || v > hi) {
        snprintf(err, err_size, "%s: expected a number in [%g, %g], got '%s'", opt, lo, hi, s);
        return -1;
    }
    *out = v;
    return 0;
}

int ex_parse_size(const char *opt, const char *s, int *w, int *h, char *err, size_t err_size)
{
    char *end;
    long a = strtol(s, &end, 10);
    if (end == s || (*end != 'x' && *end != 'X'))
        goto bad;
    const char *rest = end + 1;
    long b = strtol(rest, &end, 10);
    if (end == rest || *end || a < 16 || b < 16 || a > 8192 || b > 8192)
        goto bad;
    *w = (int)a;
    *h = (int)b;
    return 0;
bad:
    snprintf(err, err_size, "%s: expected WIDTHxHEIGHT with sides in [16, 8192], got '%s'", opt, s);
    return -1;
}

static int ex_push(long **frames, size_t *count, size_t *cap, long v)
{
    if (*count == *cap) {
        size_t nc = *cap ? 2 * *cap : 16;
        long *nf = realloc(*frames, nc * sizeof *nf);
        if (!nf)
            return -1;
        *frames = nf;
        *cap = nc;
    }
    (*frames)[(*count)++] = v;
    return 0;
}

int ex_parse_frames(const char *opt, const char *s, long **frames, size_t *count, char *err, size_t err_size)
{
    size_t cap = 0;
    *frames = NULL;
    *count = 0;
    const char *p = s;
    for (;;) {
        char *end;
        errno = 0;
        long first = strtol(p, &end, 10), last = first, step = 1;
        if (end == p || first < 0 || errno)
            goto bad;
        p = end;
        if (*p == '-') {
            last = strtol(p + 1, &end, 10);
            if (end == p + 1 || last < first || errno)
                goto bad;
            p = end;
            if (*p == ':') {
                step = strtol(p + 1, &end, 10);
                if (end == p + 1 || step < 1 || errno)
                    goto bad;
                p = end;
            }
        }
        if ((last - first) / step >= 100000) {
            snprintf(err, err_size, "%s: '%s' asks for more than 100000 frames", opt, s);
            free(*frames);
            *frames = NULL;
            return -1;
        }
        for (long f = first; f <= last; f += step)
            if (ex_push(frames, count, &cap, f) < 0) {
                snprintf(err, err_size, "%s: out of memory", opt);
                free(*frames);
                *frames = NULL;
                return -1;
            }
        if (*p == '\0')
            return 0;
        if (*p != ',')
            goto bad;
        p++;
    }
bad:
    free(*frames);
    *frames = NULL;
    *count = 0;
    snprintf(err, err_size, "%s: expected frames as 0,30,60 or 0-90:10, got '%s'", opt, s);
    return -1;
}

int ex_parse_times(const char *opt, const char *s, double **times, size_t *count, char *err, size_t err_size)
{
    size_t cap = 0;
    *times = NULL;
    *count = 0;
    const char *p = s;
    for (;;) {
        char *end;
        double first = strtod(p, &end), last = first, step = 1.0;
        if (end == p || !isfinite(first) || first < 0.0)
            goto bad;
        p = end;
        if (*p == '-') {
            last = strtod(p + 1, &end);
            if (end == p + 1 || !isfinite(last) || last < first)
                goto bad;
            p = end;
            if (*p == ':') { /* else every second */
                step = strtod(p + 1, &end);
                if (end == p + 1 || !isfinite(step) || step <= 0.0)
                    goto bad;
                p = end;
            }
        }
        double n = floor((last - first) / step + 1e-9) + 1.0; /* 0-5:0.5 takes 5 despite rounding */
        if (n + (double)*count > 100000.0) {
            snprintf(err, err_size, "%s: '%s' asks for more than 100000 times", opt, s);
            goto fail;
        }
        if (*count + (size_t)n > cap) {
            size_t nc = 2 * (*count + (size_t)n);
            double *nt = realloc(*times, nc * sizeof *nt);
            if (!nt) {
                snprintf(err, err_size, "%s: out of memory", opt);
                goto fail;
            }
            *times = nt;
            cap = nc;
        }
        for (size_t k = 0; k < (size_t)n; k++)
            (*times)[(*count)++] = first + (double)k * step;
        if (*p == '\0')
            return 0;
        if (*p != ',')
            goto bad;
        p++;
    }
bad:
    snprintf(err, err_size, "%s: expected seconds as 0,2.5,5 or 0-10:0.5 (first-last:step; step 1 s by default), "
                            "got '%s'", opt, s);
fail:
    free(*times);
    *times = NULL;
    *count = 0;
    return -1;
}

void ex_json_string(void *file, const char *s)
{
    FILE *f = file;
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}
