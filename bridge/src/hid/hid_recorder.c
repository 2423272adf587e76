/* SPDX-License-Identifier: Apache-2.0
 *
 * hid-recorder reader and writer. Hand-written: the format is a handful of
 * line types and hid-tools (its reference) is a Python tool, not a library.
 */
#include "hid_recorder.h"

#include <inttypes.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "pb_warn.h"
#include "timeline.h"

typedef struct reader {
    const char *name;
    pb_error *err;
    uint32_t line;
    pb_hid_recording *rec;
    size_t event_cap, data_cap;
    uint32_t current;     /* device that D: selected */
    size_t desc_expected; /* bytes an unfinished R: still waits for (0 = none) */
    pb_timeline timeline; /* jumps in the E: stamps taken out */
} reader;

static pose_status bad(reader *r, const char *what)
{
    return pb_fail(r->err, POSE_ERR_FORMAT, "%s:%u: %s", r->name, r->line, what);
}

static int hexval(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

static const char *skip_blanks(const char *p, const char *end)
{
    while (p < end && (*p == ' ' || *p == '\t'))
        p++;
    return p;
}

/* Unsigned decimal or hex word into *v; returns the end of the word or NULL. */
static const char *word_number(const char *p, const char *end, int base, uint64_t max, uint64_t *v)
{
    const char *s = p;
    uint64_t x = 0;
    while (p < end && *p != ' ' && *p != '\t') {
        int d = base == 16 ? hexval(*p) : (*p >= '0' && *p <= '9' ? *p - '0' : -1);
        if (d < 0 || x > (max - (uint64_t)d) / (uint64_t)base)
            return NULL;
        x = x * (uint64_t)base + (uint64_t)d;
        p++;
    }
    if (p == s)
        return NULL;
    *v = x;
    return p;
}

/* Two-digit hex bytes separated by blanks, appended to buf (at most cap); returns count or -1. */
static long hex_bytes(const char *p, const char *end, uint8_t *buf, size_t cap)
{
    size_t n = 0;
    for (p = skip_blanks(p, end); p < end; p = skip_blanks(p, end)) {
        if (end - p < 2 || hexval(p[0]) < 0 || hexval(p[1]) < 0 || (end - p > 2 && p[2] != ' ' && p[2] != '\t'))
            return -1;
        if (n >= cap)
            return -2;
        buf[n++] = (uint8_t)(hexval(p[0]) << 4 | hexval(p[1]));
        p += 2;
    }
    return (long)n;
}

static pose_status select_device(reader *r, uint64_t index)
{
    pb_hid_recording *rec = r->rec;
    if (index >= PB_HID_REC_MAX_DEVICES)
        return bad(r, "device index above 63");
    if (index >= rec->device_count) {
        if (index != rec->device_count)
            return bad(r, "devices must be introduced in order (D: 0, D: 1, ...)");
        pb_hid_rec_device *n = realloc(rec->devices, (rec->device_count + 1) * sizeof *n);
        if (!n)
            return pb_fail(r->err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", r->name);
        rec->devices = n;
        memset(&n[rec->device_count++], 0, sizeof *n);
    }
    r->current = (uint32_t)index;
    return POSE_OK;
}

static pose_status descriptor(reader *r, const char *p, const char *end)
{
    if (r->rec->device_count == 0 && select_device(r, 0) != POSE_OK)
        return POSE_ERR_FORMAT;
    pb_hid_rec_device *d = &r->rec->devices[r->current];
    if (d->desc)
        return bad(r, "a second R: line for the same device (missing D: line?)");
    uint64_t n;
    p = word_number(skip_blanks(p, end), end, 10, 65536, &n);
    if (!p || n == 0)
        return bad(r, "R: needs the descriptor length (1..65536) first");
    d->desc = malloc((size_t)n);
    if (!d->desc)
        return pb_fail(r->err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", r->name);
    long got = hex_bytes(p, end, d->desc, (size_t)n);
    if (got < 0)
        return bad(r, got == -2 ? "R: has more bytes than its length says" : "R: bytes must be two-digit hex");
    d->desc_len = (size_t)got;
    r->desc_expected = (size_t)n;
    return POSE_OK;
}

static pose_status descriptor_more(reader *r, const char *p, const char *end)
{
    pb_hid_rec_device *d = &r->rec->devices[r->current];
    long got = hex_bytes(p, end, d->desc + d->desc_len, r->desc_expected - d->desc_len);
    if (got < 0)
        return bad(r, got == -2 ? "descriptor has more bytes than its R: length says"
                                : "descriptor continuation must be two-digit hex bytes");
    d->desc_len += (size_t)got;
    return POSE_OK;
}

static pose_status info(reader *r, const char *p, const char *end)
{
    if (r->rec->device_count == 0 && select_device(r, 0) != POSE_OK)
        return POSE_ERR_FORMAT;
    pb_hid_rec_device *d = &r->rec->devices[r->current];
    uint64_t v[3];
    for (int i = 0; i < 3; i++) {
        p = word_number(skip_blanks(p, end), end, 16, i == 0 ? 0xFFFF : 0xFFFF, &v[i]);
        if (!p)
            return bad(r, "I: needs bus, vendor and product in hex");
    }
    if (skip_blanks(p, end) != end)
        return bad(r, "I: has more than three numbers");
    d->bus = (uint32_t)v[0];
    d->vendor = (uint32_t)v[1];
    d->product = (uint32_t)v[2];
    return POSE_OK;
}

static void text_field(char *dst, size_t size, const char *p, const char *end)
{
    p = skip_blanks(p, end);
    size_t n = (size_t)(end - p);
    if (n >= size)
        n = size - 1;
    memcpy(dst, p, n);
    dst[n] = '\0';
}

static pose_status event(reader *r, const char *p, const char *end)
{
    pb_hid_recording *rec = r->rec;
    if (rec->device_count == 0 || !rec->devices[r->current].desc)
        return bad(r, "E: before the device's R: descriptor");
    /* "sec.usec": seconds may be zero-padded or not; the fraction has 1..9 digits. */
    uint64_t sec, frac;
    p = skip_blanks(p, end);
    const char *dot = p;
    while (dot < end && *dot != '.' && *dot != ' ')
        dot++;
    if (dot == end || *dot != '.' || !word_number(p, dot, 10, 1000000000ull, &sec))
        return bad(r, "E: timestamp must be seconds.fraction");
    const char *fe = dot + 1;
    while (fe < end && *fe != ' ' && *fe != '\t')
        fe++;
    size_t digits = (size_t)(fe - dot - 1);
    if (digits == 0 || digits > 9 || !word_number(dot + 1, fe, 10, 999999999ull, &frac))
        return bad(r, "E: timestamp fraction must have 1 to 9 digits");
    for (size_t i = digits; i < 9; i++)
        frac *= 10;
    int64_t jump;
    const int64_t t = pb_timeline_map(&r->timeline, (int64_t)sec * 1000000000 + (int64_t)frac, &jump);
    if (jump) /* kept, so that seeking (by time) and replay stay in order */
        pb_warn("%s:%u: E: time stamp %s %.3f s: replayed one step after the report before", r->name, r->line,
                jump > 0 ? "jumps ahead" : "goes back", (double)(jump > 0 ? jump : -jump) * 1e-9);
    uint64_t n;
    p = word_number(skip_blanks(fe, end), end, 10, PB_HID_REC_MAX_EVENT_BYTES, &n);
    if (!p)
        return bad(r, "E: needs the report length (0..4097) after the timestamp");
    if (rec->event_count == r->event_cap) {
        size_t cap = r->event_cap ? r->event_cap * 2 : 256;
        pb_hid_rec_event *ev = realloc(rec->events, cap * sizeof *ev);
        if (!ev)
            return pb_fail(r->err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", r->name);
        rec->events = ev;
        r->event_cap = cap;
    }
    if (rec->data_len + n > r->data_cap || !rec->data) { /* allocated even for empty reports */
        size_t cap = r->data_cap ? r->data_cap * 2 : 4096;
        while (cap < rec->data_len + n)
            cap *= 2;
        uint8_t *nd = realloc(rec->data, cap);
        if (!nd)
            return pb_fail(r->err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", r->name);
        rec->data = nd;
        r->data_cap = cap;
    }
    long got = hex_bytes(p, end, rec->data + rec->data_len, (size_t)n);
    if (got == -2)
        return bad(r, "E: has more bytes than its length says");
    if (got < 0)
        return bad(r, "E: bytes must be two-digit hex");
    if ((uint64_t)got != n)
        return bad(r, "E: has fewer bytes than its length says");
    rec->events[rec->event_count++] = (pb_hid_rec_event){t, r->current, r->line, rec->data_len, (uint32_t)n};
    rec->data_len += n;
    rec->devices[r->current].event_count++;
    return POSE_OK;
}

static pose_status line(reader *r, const char *p, const char *end)
{
    if (p == end || *p == '#')
        return POSE_OK;
    if (r->desc_expected) {
        pb_hid_rec_device *d = &r->rec->devices[r->current];
        if (d->desc_len < r->desc_expected) {
            if (end - p >= 2 && p[1] == ':')
                return bad(r, "descriptor shorter than its R: length");
            return descriptor_more(r, p, end);
        }
        r->desc_expected = 0;
    }
    if (end - p < 2 || p[1] != ':')
        return bad(r, "expected a line of the form 'X: ...' (X one of D R N P I E)");
    const char *rest = p + 2;
    uint64_t v;
    switch (p[0]) {
    case 'D': {
        const char *e = word_number(skip_blanks(rest, end), end, 10, 1000, &v);
        if (!e || skip_blanks(e, end) != end)
            return bad(r, "D: needs a device index");
        return select_device(r, v);
    }
    case 'R':
        return descriptor(r, rest, end);
    case 'N':
    case 'P':
        if (r->rec->device_count == 0 && select_device(r, 0) != POSE_OK)
            return POSE_ERR_FORMAT;
        text_field(p[0] == 'N' ? r->rec->devices[r->current].name : r->rec->devices[r->current].phys,
                   sizeof r->rec->devices[0].name, rest, end);
        return POSE_OK;
    case 'I':
        return info(r, rest, end);
    case 'E':
        return event(r, rest, end);
    default:
        return bad(r, "unknown line type (expected D, R, N, P, I or E)");
    }
}

static bool has_nul(const char *p, const char *end)
{
    for (; p < end; p++)
        if (*p == '\0')
            return true;
    return false;
}

pose_status pb_hid_recording_parse(const char *text, size_t len, const char *name, pb_hid_recording **out,
                                   pb_error *err)
{
    *out = NULL;
    pb_error local;
    reader r = {.name = name ? name : "hid recording", .err = err ? err : &local};
    pb_timeline_init(&r.timeline, 0);
    r.rec = calloc(1, sizeof *r.rec);
    if (!r.rec)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: out of memory", r.name);
    pose_status st = POSE_OK;
    const char *p = text, *end = text + len;
    while (p < end && st == POSE_OK) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const char *le = nl ? nl : end;
        const char *te = le;
        while (te > p && (te[-1] == '\r' || te[-1] == ' ' || te[-1] == '\t'))
            te--;
        r.line++;
        const char *b = skip_blanks(p, te);
        if (has_nul(p, te))
            st = bad(&r, "NUL byte in a text file");
        else
            st = line(&r, b, te);
        /* A recorder killed while writing leaves a last E: line without its
         * newline, its bytes cut short: report it, keep the reports before. */
        if (st == POSE_ERR_FORMAT && !nl && te - b >= 2 && b[0] == 'E' && b[1] == ':') {
            pb_warn("%s; the last line is cut (no newline at the end of the file): skipped", r.err->message);
            st = POSE_OK;
        }
        p = nl ? nl + 1 : end;
    }
    for (size_t i = 0; st == POSE_OK && i < r.rec->device_count; i++) {
        const pb_hid_rec_device *d = &r.rec->devices[i];
        if (!d->desc)
            st = pb_fail(err, POSE_ERR_FORMAT, "%s: device %zu has no R: descriptor", r.name, i);
        else if (r.desc_expected && d->desc_len < r.desc_expected && i == r.current)
            st = pb_fail(err, POSE_ERR_FORMAT, "%s:%u: descriptor ends early: %zu of %zu bytes", r.name,
                         r.line, d->desc_len, r.desc_expected);
    }
    if (st == POSE_OK && r.rec->device_count == 0)
        st = pb_fail(err, POSE_ERR_FORMAT, "%s: no device (no R: line)", r.name);
    if (st != POSE_OK) {
        pb_hid_recording_free(r.rec);
        return st;
    }
    *out = r.rec;
    return POSE_OK;
}

pose_status pb_hid_recording_load(const char *path, pb_hid_recording **out, pb_error *err)
{
    char *text;
    size_t size;
    *out = NULL;
    pose_status st = pb_read_file(path, (size_t)256 << 20, &text, &size, err);
    if (st != POSE_OK)
        return st;
    st = pb_hid_recording_parse(text, size, path, out, err);
    free(text);
    return st;
}

void pb_hid_recording_free(pb_hid_recording *rec)
{
    if (!rec)
        return;
    for (size_t i = 0; i < rec->device_count; i++)
        free(rec->devices[i].desc);
    free(rec->devices);
    free(rec->events);
    free(rec->data);
    free(rec);
}

/* " xx" per byte and the newline, formatted in chunks (fprintf per byte is 5x slower). */
static int write_bytes(FILE *f, const uint8_t *b, size_t n)
{
    static const char hex[] = "0123456789abcdef";
    char buf[3 * 256 + 1];
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        buf[k++] = ' ';
        buf[k++] = hex[b[i] >> 4];
        buf[k++] = hex[b[i] & 15];
        if (k == 3 * 256) {
            if (fwrite(buf, 1, k, f) != k)
                return -1;
            k = 0;
        }
    }
    buf[k++] = '\n';
    return fwrite(buf, 1, k, f) == k ? 0 : -1;
}

int pb_hid_recorder_write_device(FILE *f, int index, const pb_hid_rec_device *dev)
{
    if (index >= 0 && fprintf(f, "D: %d\n", index) < 0)
        return -1;
    if (fprintf(f, "R: %zu", dev->desc_len) < 0 || write_bytes(f, dev->desc, dev->desc_len) != 0)
        return -1;
    if (fprintf(f, "N: %s\nP: %s\nI: %x %04x %04x\n", dev->name, dev->phys, dev->bus, dev->vendor,
                dev->product) < 0)
        return -1;
    return 0;
}

int pb_hid_recorder_write_event(FILE *f, int64_t t_ns, const uint8_t *report, size_t len)
{
    if (t_ns < 0)
        t_ns = 0;
    if (fprintf(f, "E: %06" PRId64 ".%06" PRId64 " %zu", t_ns / 1000000000, (t_ns % 1000000000) / 1000, len) < 0)
        return -1;
    return write_bytes(f, report, len);
}
