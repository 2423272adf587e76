/* SPDX-License-Identifier: Apache-2.0 */
#include "pb_text.h"

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

void pb_text_init(pb_text *t, const char *data, size_t size, const char *name)
{
    t->p = data;
    t->end = data + size;
    t->name = name ? name : "<memory>";
    t->line = 1;
}

static int is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

void pb_text_skip_blanks(pb_text *t)
{
    while (t->p < t->end && is_blank(*t->p))
        t->p++;
}

void pb_text_skip_line(pb_text *t)
{
    while (t->p < t->end && *t->p != '\n')
        t->p++;
    if (t->p < t->end) {
        t->p++;
        t->line++;
    }
}

void pb_text_skip_space(pb_text *t, int comments)
{
    while (t->p < t->end) {
        char c = *t->p;
        if (c == '\n') {
            t->line++;
            t->p++;
        } else if (is_blank(c) || c == '\0') {
            t->p++;
        } else if (comments && c == '#') {
            pb_text_skip_line(t);
        } else {
            break;
        }
    }
}

static pb_token take(pb_text *t)
{
    pb_token tk = {t->p, 0, t->line};
    while (t->p < t->end && !is_blank(*t->p) && *t->p != '\n' && *t->p != '\0')
        t->p++;
    tk.n = (size_t)(t->p - tk.s);
    return tk;
}

pb_token pb_text_next(pb_text *t, int comments)
{
    pb_text_skip_space(t, comments);
    return take(t);
}

pb_token pb_text_next_in_line(pb_text *t)
{
    pb_text_skip_blanks(t);
    return take(t);
}

int pb_token_is(pb_token tk, const char *word)
{
    size_t n = strlen(word);
    return tk.n == n && memcmp(tk.s, word, n) == 0;
}

int pb_token_is_nocase(pb_token tk, const char *word)
{
    size_t n = strlen(word);
    if (tk.n != n)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (tolower((unsigned char)tk.s[i]) != tolower((unsigned char)word[i]))
            return 0;
    return 1;
}

/* Fast path for plain decimals ("-12.3456"): with at most 15 significant
 * digits the mantissa and 10^k (k <= 22) are exact doubles, so one division
 * rounds correctly (Clinger 1990). Anything else goes to strtod. */
static int fast_decimal(const char *s, size_t n, double *out)
{
    static const double pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                     1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    size_t i = 0;
    int neg = 0;
    if (s[0] == '-' || s[0] == '+')
        neg = s[i++] == '-';
    uint64_t m = 0;
    int digits = 0, frac = 0, dot = 0, any = 0;
    for (; i < n; i++) {
        char c = s[i];
        if (c >= '0' && c <= '9') {
            any = 1;
            if (m == 0 && c == '0' && !dot)
                continue; /* leading zeros */
            if (++digits > 15)
                return -1;
            m = m * 10 + (uint64_t)(c - '0');
            frac += dot;
        } else if (c == '.' && !dot) {
            dot = 1;
        } else {
            return -1;
        }
    }
    if (!any)
        return -1;
    double v = (double)m / pow10[frac];
    *out = neg ? -v : v;
    return 0;
}

int pb_token_double(pb_token tk, double *out)
{
    if (tk.n == 0 || tk.n > 64)
        return -1;
    if (fast_decimal(tk.s, tk.n, out) == 0)
        return 0;
    /* strtod stops at the token's end because tokens end at whitespace or
     * the buffer's terminating NUL. */
    char *e;
    double v = strtod(tk.s, &e);
    if (e != tk.s + tk.n)
        return -1;
    if (!isfinite(v))
        return -2;
    *out = v;
    return 0;
}

int pb_token_count(pb_token tk, long max, long *out)
{
    if (tk.n == 0 || tk.n > 19)
        return -1;
    long v = 0;
    for (size_t i = 0; i < tk.n; i++) {
        if (!isdigit((unsigned char)tk.s[i]))
            return -1;
        v = v * 10 + (tk.s[i] - '0');
        if (v > max)
            return -1;
    }
    *out = v;
    return 0;
}

const char *pb_token_str(pb_token tk, char *buf, size_t size)
{
    size_t n = tk.n < size - 1 ? tk.n : size - 1;
    memcpy(buf, tk.s, n);
    buf[n] = '\0';
    return buf;
}
