/* SPDX-License-Identifier: Apache-2.0
 *
 * candump -l line parser, writer and file reader. Hand-written because the
 * format is one line of fixed syntax (can-utils has no library); integers
 * only, so 9-decimal stamps keep their nanoseconds.
 */
#include "candump_log.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "pb_warn.h"

#define PB_STR_(x) #x
#define PB_STR(x) PB_STR_(x)

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

static int is_space(char c) { return c == ' ' || c == '\t'; }

int pb_candump_parse_line(const char *line, size_t len, pb_can_frame *f, char *iface,
                          size_t iface_size, const char **why)
{
    const char *p = line, *end = line + len;
    while (end > p && (end[-1] == '\n' || end[-1] == '\r' || is_space(end[-1])))
        end--;
    while (p < end && is_space(*p))
        p++;
    if (p == end || *p == '#')
        return 0;
    memset(f, 0, sizeof *f);
    *why = "expected '(' and a time stamp";
    if (*p++ != '(')
        return -1;
    /* seconds . fraction (6 or 9 digits; others are scaled too) */
    uint64_t sec = 0;
    int digits = 0;
    while (p < end && *p >= '0' && *p <= '9') {
        sec = sec * 10 + (uint64_t)(*p++ - '0');
        if (sec > (uint64_t)(INT64_MAX / 1000000000 - 1)) { /* t_ns must fit int64_t */
            *why = "time stamp too large";
            return -1;
        }
        digits++;
    }
    if (!digits || p >= end || *p++ != '.') {
        *why = "time stamp is not seconds.fraction";
        return -1;
    }
    uint64_t frac = 0;
    int fd = 0;
    while (p < end && *p >= '0' && *p <= '9') {
        if (fd < 9)
            frac = frac * 10 + (uint64_t)(*p - '0');
        fd++;
        p++;
    }
    if (fd == 0 || p >= end || *p++ != ')') {
        *why = "time stamp is not closed by ')'";
        return -1;
    }
    for (int i = fd; i < 9; i++)
        frac *= 10;
    f->t_ns = (int64_t)(sec * 1000000000u + frac);

    if (p >= end || !is_space(*p)) {
        *why = "expected a space after the time stamp";
        return -1;
    }
    while (p < end && is_space(*p))
        p++;
    const char *ifs = p;
    while (p < end && !is_space(*p)) {
        if (*p < '!' || *p > '~') { /* interface names are printable: the writer must give them back */
            *why = "interface name with a control or non-ASCII character";
            return -1;
        }
        p++;
    }
    if (p == ifs || p >= end) {
        *why = "expected an interface name and a frame";
        return -1;
    }
    if (iface_size) {
        size_t n = (size_t)(p - ifs) < iface_size - 1 ? (size_t)(p - ifs) : iface_size - 1;
        memcpy(iface, ifs, n);
        iface[n] = '\0';
    }
    while (p < end && is_space(*p))
        p++;

    /* identifier: 3 hex digits (standard) or 8 (extended or error) */
    const char *ids = p;
    uint32_t id = 0;
    while (p < end && hexval(*p) >= 0 && p - ids < 9)
        id = id << 4 | (uint32_t)hexval(*p++);
    const size_t idlen = (size_t)(p - ids);
    if (p >= end || *p != '#') {
        *why = "expected '#' after a 3- or 8-digit identifier";
        return -1;
    }
    p++;
    if (idlen == 3) {
        if (id > 0x7ff) {
            *why = "standard identifier above 0x7FF";
            return -1;
        }
        f->id = id;
    } else if (idlen == 8) {
        if (id & 0xc0000000u) { /* the EFF and RTR flag bits are never written as id digits */
            *why = "identifier above 0x3FFFFFFF";
            return -1;
        }
        if (id & PB_CANDUMP_ERR_FLAG) {
            f->flags |= PB_CAN_ERR;
            f->id = id & 0x1fffffffu;
        } else {
            f->flags |= PB_CAN_EXT;
            f->id = id;
        }
    } else {
        *why = "identifier must have 3 or 8 hex digits";
        return -1;
    }

    size_t max = 8;
    if (p < end && *p == '#') { /* FD: ##<flags nibble><data> */
        p++;
        int fl = p < end ? hexval(*p) : -1;
        if (fl < 0) {
            *why = "FD frame without a flags digit after '##'";
            return -1;
        }
        p++;
        f->flags |= PB_CAN_FD;
        if (fl & 1)
            f->flags |= PB_CAN_BRS;
        if (fl & 2)
            f->flags |= PB_CAN_ESI;
        max = 64;
        if (f->flags & PB_CAN_ERR) {
            *why = "error frames cannot be FD frames";
            return -1;
        }
    } else if (p < end && (*p == 'R' || *p == 'r')) {
        p++;
        f->flags |= PB_CAN_RTR;
        if (p < end && *p >= '0' && *p <= '8')
            f->len = (uint8_t)(*p++ - '0');
        f->dlc = f->len;
        if (p < end && *p == '_') { /* R_<dlc> for len8_dlc remote frames */
            int d = p + 1 < end ? hexval(p[1]) : -1;
            if (d < 9 || f->len != 8) {
                *why = "bad '_' length code";
                return -1;
            }
            f->dlc = (uint8_t)d;
            p += 2;
        }
        goto trailer;
    }
    while (p < end && !is_space(*p) && *p != '_') {
        if (*p == '.') { /* optional byte separators */
            p++;
            continue;
        }
        int hi = hexval(*p), lo = p + 1 < end ? hexval(p[1]) : -1;
        if (hi < 0 || lo < 0) {
            *why = "data is not pairs of hex digits";
            return -1;
        }
        if (f->len >= max) {
            *why = max == 8 ? "more than 8 data bytes in a classic frame"
                            : "more than 64 data bytes in an FD frame";
            return -1;
        }
        f->data[f->len++] = (uint8_t)(hi << 4 | lo);
        p += 2;
    }
    f->dlc = f->len;
    if (p < end && *p == '_') {
        int d = p + 1 < end ? hexval(p[1]) : -1;
        if ((f->flags & PB_CAN_FD) || f->len != 8 || d < 9) {
            *why = "bad '_' length code (only classic 8-byte frames, 9..F)";
            return -1;
        }
        f->dlc = (uint8_t)d;
        p += 2;
    }
    if ((f->flags & PB_CAN_FD) && !pb_can_fd_len_valid(f->len)) {
        *why = "FD frame length is not one a DLC can encode";
        return -1;
    }
trailer:
    while (p < end && is_space(*p))
        p++;
    /* candump -l -x appends a direction flag; nothing else may follow. */
    if (p < end && (*p == 'R' || *p == 'T') && p + 1 == end)
        p++;
    if (p != end) {
        *why = "unexpected text after the frame";
        return -1;
    }
    return 1;
}

int pb_candump_format(const pb_can_frame *f, const char *iface, char *buf, size_t size)
{
    static const char hex[] = "0123456789ABCDEF";
    const int64_t t = f->t_ns < 0 ? 0 : f->t_ns;
    int n;
    if (f->flags & PB_CAN_ERR)
        n = snprintf(buf, size, "(%010lld.%06lld) %s %08X#", (long long)(t / 1000000000),
                     (long long)(t % 1000000000 / 1000), iface,
                     (unsigned)((f->id & 0x1fffffffu) | PB_CANDUMP_ERR_FLAG));
    else if (f->flags & PB_CAN_EXT)
        n = snprintf(buf, size, "(%010lld.%06lld) %s %08X#", (long long)(t / 1000000000),
                     (long long)(t % 1000000000 / 1000), iface, (unsigned)(f->id & 0x1fffffffu));
    else
        n = snprintf(buf, size, "(%010lld.%06lld) %s %03X#", (long long)(t / 1000000000),
                     (long long)(t % 1000000000 / 1000), iface, (unsigned)(f->id & 0x7ffu));
    if (n < 0 || (size_t)n >= size)
        return -1;
    size_t w = (size_t)n;
    /* worst case: "#" + flags + 128 hex digits + "_X" + "\n" + NUL */
    if (size - w < 2 + 2 * (size_t)f->len + 4)
        return -1;
    if (f->flags & PB_CAN_FD) {
        buf[w++] = '#';
        buf[w++] = hex[((f->flags & PB_CAN_BRS) ? 1 : 0) | ((f->flags & PB_CAN_ESI) ? 2 : 0)];
    } else if (f->flags & PB_CAN_RTR) {
        buf[w++] = 'R';
        if (f->len)
            buf[w++] = (char)('0' + (f->len > 8 ? 8 : f->len));
    }
    if (!(f->flags & PB_CAN_RTR))
        for (unsigned i = 0; i < f->len && i < PB_CAN_MAX_DATA; i++) {
            buf[w++] = hex[f->data[i] >> 4];
            buf[w++] = hex[f->data[i] & 15];
        }
    if (!(f->flags & PB_CAN_FD) && f->len == 8 && f->dlc > 8 && f->dlc <= 15) {
        buf[w++] = '_';
        buf[w++] = hex[f->dlc];
    }
    buf[w++] = '\n';
    buf[w] = '\0';
    return (int)w;
}

int pb_candump_write(FILE *out, const pb_can_frame *f, const char *iface)
{
    char line[PB_CANDUMP_LINE_MAX];
    const int n = pb_candump_format(f, iface, line, sizeof line);
    if (n < 0) {
        errno = EINVAL;
        return -1;
    }
    return fwrite(line, 1, (size_t)n, out) == (size_t)n && fflush(out) == 0 ? 0 : -1;
}

int pb_candump_open(pb_candump_reader *r, const char *path, char *err, size_t err_size)
{
    memset(r, 0, sizeof *r);
    r->file = fopen(path, "rb");
    if (!r->file) {
        if (err && err_size)
            snprintf(err, err_size, "%s: %s", path, strerror(errno));
        return -1;
    }
    r->path = strdup(path);
    if (!r->path) {
        fclose(r->file);
        r->file = NULL;
        if (err && err_size)
            snprintf(err, err_size, "%s: out of memory", path);
        return -1;
    }
    return 0;
}

/* One line into buf by length: fgets + strlen would stop at a NUL byte and
 * take the rest of the line (or the next one) for a line of its own. Returns
 * 0 at the end of the file, else 1 with *n bytes kept (the newline not
 * included), *terminated when a newline ended it, *nul when it held a NUL
 * and *overlong when it had more than `cap` bytes (the rest is consumed). */
static int read_line(FILE *file, char *buf, size_t cap, size_t *n, int *terminated, int *nul, int *overlong)
{
    int c;
    size_t len = 0, total = 0;
    *terminated = *nul = 0;
    while ((c = getc(file)) != EOF) {
        if (c == '\n') {
            *terminated = 1;
            break;
        }
        if (c == '\0')
            *nul = 1;
        if (len < cap)
            buf[len++] = (char)c;
        total++;
    }
    *n = len;
    *overlong = total > cap;
    return total > 0 || *terminated;
}

static void reject(pb_candump_reader *r, const char *why, const char *cut)
{
    r->bad_lines++;
    snprintf(r->last_error, sizeof r->last_error, "%s:%zu: %s%s", r->path, r->line, cut, why);
    pb_warn("%s", r->last_error);
}

int pb_candump_next(pb_candump_reader *r, pb_can_frame *f)
{
    char buf[PB_CANDUMP_LINE_MAX];
    size_t n;
    int terminated, nul, overlong;
    while (read_line(r->file, buf, sizeof buf, &n, &terminated, &nul, &overlong)) {
        r->line++;
        /* candump ends every line with a newline: a last line without one was
         * cut short (a recorder killed mid-write), whatever it parses as. */
        const char *cut = terminated ? "" : "last line cut (no newline at the end of the file): ";
        const char *why = NULL;
        if (overlong)
            reject(r, "line too long (over " PB_STR(PB_CANDUMP_LINE_MAX) " bytes)", cut);
        else if (nul)
            reject(r, "NUL byte in the line", cut);
        else {
            const int rc = pb_candump_parse_line(buf, n, f, r->iface, sizeof r->iface, &why);
            if (rc == 1 && terminated) {
                r->frames++;
                return 1;
            }
            if (rc != 0) /* not a blank or comment line */
                reject(r, rc == 1 ? "skipped" : why, cut);
        }
    }
    return ferror(r->file) ? -1 : 0;
}

int pb_candump_rewind(pb_candump_reader *r)
{
    if (fseek(r->file, 0, SEEK_SET) != 0)
        return -1;
    clearerr(r->file);
    r->line = r->frames = r->bad_lines = 0;
    r->last_error[0] = '\0';
    return 0;
}

void pb_candump_close(pb_candump_reader *r)
{
    if (r->file)
        fclose(r->file);
    free(r->path);
    memset(r, 0, sizeof *r);
}
