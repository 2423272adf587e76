/* SPDX-License-Identifier: Apache-2.0 */
#include "usbmon.h"

#include <errno.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_LINE = 1 << 16, MAX_EVENTS = 1 << 26 };

typedef struct lexer {
    const char *line, *end, *p; /* the line and the cursor */
    const char *word;           /* the current word */
    size_t wlen;
} lexer;

static int next_word(lexer *lx)
{
    while (lx->p < lx->end && (*lx->p == ' ' || *lx->p == '\t'))
        lx->p++;
    lx->word = lx->p;
    while (lx->p < lx->end && *lx->p != ' ' && *lx->p != '\t')
        lx->p++;
    lx->wlen = (size_t)(lx->p - lx->word);
    return lx->wlen > 0;
}

/* Decimal integer in [lo, hi] from s[0..n); 0 or -1. */
static int dec(const char *s, size_t n, int64_t lo, int64_t hi, int64_t *out)
{
    size_t i = 0;
    int neg = 0;
    if (i < n && (s[i] == '-' || s[i] == '+'))
        neg = s[i++] == '-';
    if (i == n || n - i > 18)
        return -1;
    int64_t v = 0;
    for (; i < n; i++) {
        if (s[i] < '0' || s[i] > '9')
            return -1;
        v = v * 10 + (s[i] - '0');
    }
    v = neg ? -v : v;
    if (v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

static int hexval(char c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

typedef struct builder {
    pb_usbmon_capture *c;
    size_t ev_cap, data_cap;
} builder;

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t n = *cap ? *cap : 64;
    while (n < need)
        n *= 2;
    void *q = realloc(*p, n * elem);
    if (!q)
        return -1;
    *p = q;
    *cap = n;
    return 0;
}

#define FAIL_AT(what, ...)                                                                                             \
    pb_fail(err, POSE_ERR_FORMAT, "%s:%u: byte %zu: " what, name, lineno, (size_t)(lx.word - lx.line), __VA_ARGS__)

static pose_status parse_line(builder *b, const char *line, size_t n, const char *name, uint32_t lineno,
                              pb_error *err)
{
    lexer lx = {line, line + n, line, line, 0};
    pb_usbmon_event e;
    memset(&e, 0, sizeof e);
    e.line = lineno;
    e.interval = -1;
    int64_t v;
    /* URB tag: any word (normally a kernel address in hex) */
    if (!next_word(&lx))
        return POSE_OK;
    if (lx.word[0] == '#')
        return b->c->comment_lines++, POSE_OK;
    if (!next_word(&lx) || dec(lx.word, lx.wlen, 0, INT64_MAX / 1000, &v) != 0)
        return FAIL_AT("expected the time stamp in microseconds (a decimal number), found '%.*s'", (int)(lx.wlen > 40 ? 40 : lx.wlen), lx.word);
    e.t_us = v;
    if (!next_word(&lx) || lx.wlen != 1 || !strchr("SCE", lx.word[0]))
        return FAIL_AT("expected the event type S, C or E, found '%.*s'", (int)(lx.wlen > 40 ? 40 : lx.wlen), lx.word);
    e.event = lx.word[0];
    /* address: Xd:BUS:DEV:EP or Xd:DEV:EP */
    if (!next_word(&lx) || lx.wlen < 6 || !strchr("CZIB", lx.word[0]) || (lx.word[1] != 'i' && lx.word[1] != 'o') ||
        lx.word[2] != ':')
        return FAIL_AT("expected an address such as Ii:1:005:1, found '%.*s'", (int)(lx.wlen > 40 ? 40 : lx.wlen), lx.word);
    e.xfer = lx.word[0];
    e.in = lx.word[1] == 'i';
    {
        const char *s = lx.word + 3, *end = lx.word + lx.wlen;
        int64_t part[3];
        int np = 0;
        while (np < 3) {
            const char *c = memchr(s, ':', (size_t)(end - s));
            const char *stop = c ? c : end;
            if (dec(s, (size_t)(stop - s), 0, 65535, &part[np]) != 0 || stop == s || s[0] == '-' || s[0] == '+')
                return FAIL_AT("address '%.*s': bus, device and endpoint are decimal numbers", (int)lx.wlen, lx.word);
            np++;
            if (!c)
                break;
            s = c + 1;
        }
        if (np < 2 || (np == 3 && s + 0 < end && memchr(s, ':', (size_t)(end - s))))
            return FAIL_AT("address '%.*s' is not Xd:BUS:DEV:EP or Xd:DEV:EP", (int)lx.wlen, lx.word);
        int64_t bus = np == 3 ? part[0] : 0, dev = part[np - 2], ep = part[np - 1];
        if (dev > 127 || ep > 15)
            return FAIL_AT("address '%.*s': device above 127 or endpoint above 15", (int)lx.wlen, lx.word);
        e.bus = (uint16_t)bus;
        e.dev = (uint16_t)dev;
        e.ep = (uint8_t)ep;
    }
    /* status word, or a setup tag and the setup packet */
    if (!next_word(&lx))
        return FAIL_AT("%s", "the line ends before the status word");
    int64_t iso_words = 0;
    if (lx.wlen == 1 && !(lx.word[0] >= '0' && lx.word[0] <= '9')) {
        if (e.xfer != 'C' || e.event != 'S')
            return FAIL_AT("setup tag '%c' on an event that is not a control submission", lx.word[0]);
        for (int k = 0; k < 5; k++) {
            static const size_t width[5] = {2, 2, 4, 4, 4};
            if (!next_word(&lx) || lx.wlen != width[k])
                return FAIL_AT("setup packet word %d should have %zu hex digits", k + 1, width[k]);
            for (size_t i = 0; i < lx.wlen; i++)
                if (hexval(lx.word[i]) < 0)
                    return FAIL_AT("setup packet word '%.*s' is not hex", (int)lx.wlen, lx.word);
        }
    } else {
        const char *s = lx.word, *end = lx.word + lx.wlen, *c = memchr(s, ':', lx.wlen);
        if (dec(s, (size_t)((c ? c : end) - s), -100000, 100000, &v) != 0)
            return FAIL_AT("expected the URB status (a decimal number), found '%.*s'", (int)(lx.wlen > 40 ? 40 : lx.wlen), lx.word);
        e.status = (int)v;
        if (c) {
            if (e.xfer != 'I' && e.xfer != 'Z')
                return FAIL_AT("status '%.*s' has an interval, but only interrupt and isochronous transfers have one", (int)lx.wlen, lx.word);
            s = c + 1;
            c = memchr(s, ':', (size_t)(end - s));
            if (dec(s, (size_t)((c ? c : end) - s), 0, 1 << 24, &v) != 0)
                return FAIL_AT("status '%.*s': the interval is not a decimal number", (int)lx.wlen, lx.word);
            e.interval = (int)v;
            if (c) {
                if (e.xfer != 'Z' || dec(c + 1, (size_t)(end - c - 1), -(1 << 30), 1 << 30, &v) != 0)
                    return FAIL_AT("status '%.*s': only isochronous transfers have a start frame", (int)lx.wlen, lx.word);
            }
        }
        if (e.xfer == 'Z')
            iso_words = 1;
    }
    if (!next_word(&lx)) {
        if (e.event != 'E') /* a submission error may end after its status */
            return FAIL_AT("%s", "the line ends before the data length");
    } else {
        if (iso_words) {
            /* error count, descriptor count, descriptors (up to 5 shown) */
            int64_t ndesc;
            if (dec(lx.word, lx.wlen, 0, 1 << 20, &v) != 0 || !next_word(&lx) ||
                dec(lx.word, lx.wlen, 0, 1 << 20, &ndesc) != 0)
                return FAIL_AT("%s", "isochronous event: expected the error count and the descriptor count");
            for (int64_t k = 0; k < (ndesc < 5 ? ndesc : 5); k++) {
                if (!next_word(&lx) || !memchr(lx.word, ':', lx.wlen))
                    return FAIL_AT("isochronous descriptor %" PRId64 " should be status:offset:length", k + 1);
            }
            if (!next_word(&lx))
                return FAIL_AT("%s", "the line ends before the data length");
        }
        if (dec(lx.word, lx.wlen, 0, UINT32_MAX, &v) != 0)
            return FAIL_AT("expected the data length (a decimal number), found '%.*s'", (int)(lx.wlen > 40 ? 40 : lx.wlen), lx.word);
        e.length = (uint32_t)v;
        if (next_word(&lx)) {
            if (lx.wlen != 1)
                return FAIL_AT("expected the data tag ('=', '<', '>' ...), found '%.*s'", (int)(lx.wlen > 40 ? 40 : lx.wlen), lx.word);
            if (lx.word[0] == '=') {
                e.offset = b->c->data_len;
                while (next_word(&lx)) {
                    if (lx.wlen % 2 || lx.wlen > 8)
                        return FAIL_AT("data word '%.*s' is not one to four bytes of hex", (int)(lx.wlen > 40 ? 40 : lx.wlen), lx.word);
                    if (grow((void **)&b->c->data, &b->data_cap, b->c->data_len + lx.wlen / 2, 1) != 0)
                        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s:%u: out of memory", name, lineno);
                    for (size_t i = 0; i < lx.wlen; i += 2) {
                        int hi = hexval(lx.word[i]), lo = hexval(lx.word[i + 1]);
                        if (hi < 0 || lo < 0)
                            return FAIL_AT("data word '%.*s' is not hex", (int)lx.wlen, lx.word);
                        b->c->data[b->c->data_len++] = (uint8_t)(hi << 4 | lo);
                    }
                    if (b->c->data_len - e.offset > (size_t)e.length + 64 * 1024)
                        return FAIL_AT("%s", "more data words than the data length allows");
                }
                e.captured = (uint32_t)(b->c->data_len - e.offset);
                if (e.captured > e.length && e.xfer != 'Z')
                    return pb_fail(err, POSE_ERR_FORMAT, "%s:%u: %u data bytes on a line whose data length is %u", name,
                                   lineno, e.captured, e.length);
            } else if (next_word(&lx)) {
                return FAIL_AT("text after the data tag '%c', which says no data follows", lx.line[lx.word - lx.line - 2]);
            }
        }
    }
    if (b->c->count >= MAX_EVENTS)
        return pb_fail(err, POSE_ERR_FORMAT, "%s:%u: more than %d events", name, lineno, MAX_EVENTS);
    if (grow((void **)&b->c->events, &b->ev_cap, b->c->count + 1, sizeof e) != 0)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s:%u: out of memory", name, lineno);
    b->c->events[b->c->count++] = e;
    return POSE_OK;
}

pose_status pb_usbmon_parse(const char *text, size_t len, const char *name, pb_usbmon_capture **out, pb_error *err)
{
    *out = NULL;
    builder b = {calloc(1, sizeof *b.c), 0, 0};
    if (!b.c)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    const char *p = text, *end = text + len;
    uint32_t lineno = 0;
    pose_status st = POSE_OK;
    while (p < end && st == POSE_OK) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const char *stop = nl ? nl : end;
        lineno++;
        size_t n = (size_t)(stop - p);
        if (n && p[n - 1] == '\r')
            n--;
        if (n > MAX_LINE)
            st = pb_fail(err, POSE_ERR_FORMAT, "%s:%u: line of %zu bytes (at most %d)", name, lineno, n, MAX_LINE);
        else if (memchr(p, '\0', n))
            st = pb_fail(err, POSE_ERR_FORMAT, "%s:%u: byte %zu: a NUL byte in the text", name, lineno,
                         (size_t)((const char *)memchr(p, '\0', n) - p));
        else
            st = parse_line(&b, p, n, name, lineno, err);
        p = nl ? nl + 1 : end;
    }
    /* data is never NULL, so that data + offset is a pointer even for a capture without data words */
    if (st == POSE_OK && !b.c->data && grow((void **)&b.c->data, &b.data_cap, 1, 1) != 0)
        st = pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    if (st != POSE_OK) {
        pb_usbmon_capture_free(b.c);
        return st;
    }
    *out = b.c;
    return POSE_OK;
}

pose_status pb_usbmon_load(const char *path, pb_usbmon_capture **out, pb_error *err)
{
    char *text;
    size_t n;
    *out = NULL;
    pose_status st = pb_read_file(path, (size_t)1 << 30, &text, &n, err);
    if (st != POSE_OK)
        return st;
    st = pb_usbmon_parse(text, n, path, out, err);
    free(text);
    return st;
}

void pb_usbmon_capture_free(pb_usbmon_capture *c)
{
    if (!c)
        return;
    free(c->events);
    free(c->data);
    free(c);
}

int pb_usbmon_write(FILE *f, uint64_t tag, const pb_usbmon_event *e, const uint8_t *data)
{
    char status[32];
    if (e->interval >= 0)
        snprintf(status, sizeof status, "%d:%d", e->status, e->interval);
    else
        snprintf(status, sizeof status, "%d", e->status);
    if (fprintf(f, "%016" PRIx64 " %" PRId64 " %c %c%c:%u:%03u:%u %s %u", tag, e->t_us, e->event, e->xfer,
                e->in ? 'i' : 'o', e->bus, e->dev, e->ep, status, e->length) < 0)
        return -1;
    if (data && e->captured) {
        if (fputs(" =", f) < 0)
            return -1;
        for (uint32_t i = 0; i < e->captured; i++)
            if (fprintf(f, "%s%02x", i % 4 ? "" : " ", data[i]) < 0)
                return -1;
    } else if (fputs(e->in ? " <" : " >", f) < 0) {
        return -1;
    }
    return fputc('\n', f) == EOF ? -1 : 0;
}
