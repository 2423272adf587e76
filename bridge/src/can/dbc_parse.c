/* SPDX-License-Identifier: Apache-2.0
 *
 * DBC parser. A small tokenizer feeds one function per statement; BO_, SG_,
 * BU_, BS_ and NS_ are line-oriented, every other statement ends with ';'.
 * Statements the decoder does not need (CM_, BA_*, EV_, ...) are skipped by
 * token, so strings with ';' or newlines inside them do no harm. Errors
 * longjmp back to pb_dbc_parse, which frees the half-built result: every
 * allocation hangs off the pb_dbc (an arena for strings and small arrays,
 * realloc'd vectors for messages and signals).
 *
 * Real files are judged by what cantools loads (database/can/formats/dbc.py
 * and database/can/message.py):
 *   - a message named VECTOR__INDEPENDENT_SIG_MSG is CANdb++'s holder for
 *     signals that belong to no message; cantools drops it, whatever its
 *     signals (_load_messages), so its signals may repeat names. Here its
 *     SG_ lines are still checked for syntax, then dropped; each repeated
 *     name is a warning (pb_warn), and statements that refer to its
 *     identifier (VAL_, SIG_VALTYPE_, SG_MUL_VAL_, BA_) are skipped quietly;
 *   - any other message whose identifier exceeds 29 bits is refused, as
 *     cantools' Message refuses it.
 */
#include "dbc_parse.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pb_warn.h"

#define PB_DBC_MAX_FILE (64u << 20)
#define PSEUDO_MESSAGE "VECTOR__INDEPENDENT_SIG_MSG"
#define PSEUDO_MAX 8 /* distinct pseudo-message identifiers remembered */

/* ---- arena ------------------------------------------------------------ */

struct pb_dbc_arena {
    struct pb_dbc_arena *next;
    size_t used, size;
    _Alignas(16) unsigned char data[];
};

struct pb_dbc_index_entry {
    uint32_t key; /* id | extended << 31 */
    uint32_t message;
};

/* ---- parser state ----------------------------------------------------- */

typedef enum tkind { T_EOF, T_IDENT, T_NUMBER, T_STRING, T_PUNCT } tkind;

typedef struct token {
    tkind kind;
    const char *s; /* text (strings: between the quotes) */
    size_t n;
    size_t line;
    size_t col;    /* 0 = first column */
} token;

typedef struct parser {
    const char *p, *end, *start;
    const char *name;
    size_t line;
    const char *line_start;
    token peeked;
    int have_peek;
    pb_dbc *dbc;
    size_t cap_messages;
    size_t *cap_signals; /* per message */
    pb_dbc_error *err;
    jmp_buf fail;
    /* scratch for VAL_ and SG_MUL_VAL_ lists before they move to the arena */
    void *scratch;
    size_t scratch_cap;
    /* VECTOR__INDEPENDENT_SIG_MSG: set while its SG_ lines follow; its
     * identifiers; the names of its signals so far (pointers into the text). */
    int in_pseudo;
    uint64_t pseudo_raw[PSEUDO_MAX];
    size_t pseudo_raw_count;
    struct pseudo_signal {
        const char *s;
        size_t n, line;
    } *pseudo_sigs;
    size_t pseudo_sig_count, pseudo_sig_cap;
} parser;

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4), noreturn))
#endif
static void fail_at(parser *ps, size_t line, const char *fmt, ...)
{
    if (ps->err) {
        char what[200];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(what, sizeof what, fmt, ap);
        va_end(ap);
        snprintf(ps->err->message, sizeof ps->err->message, "%s:%zu: %s", ps->name, line, what);
        ps->err->line = line;
    }
    longjmp(ps->fail, 1);
}

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static void warn_at(parser *ps, size_t line, const char *fmt, ...)
{
    char what[200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (ps->dbc->warning_count++ == 0)
        snprintf(ps->dbc->warning, sizeof ps->dbc->warning, "%s:%zu: %s", ps->name, line, what);
    pb_warn("%s:%zu: %s", ps->name, line, what);
}

static void *arena_alloc(parser *ps, size_t size)
{
    size = (size + 15) & ~(size_t)15;
    struct pb_dbc_arena *a = ps->dbc->arena;
    if (!a || a->size - a->used < size) {
        size_t block = size > 16384 ? size : 16384;
        struct pb_dbc_arena *b = malloc(sizeof *b + block);
        if (!b)
            fail_at(ps, ps->line, "out of memory");
        b->next = a;
        b->used = 0;
        b->size = block;
        ps->dbc->arena = b;
        a = b;
    }
    void *r = a->data + a->used;
    a->used += size;
    return r;
}

/* Copy a token's text, undoing the \" and \\ escapes strings may carry. */
static const char *arena_str(parser *ps, const token *t)
{
    char *s = arena_alloc(ps, t->n + 1);
    size_t j = 0;
    for (size_t i = 0; i < t->n; i++) {
        if (t->kind == T_STRING && t->s[i] == '\\' && i + 1 < t->n &&
            (t->s[i + 1] == '"' || t->s[i + 1] == '\\'))
            i++;
        s[j++] = t->s[i];
    }
    s[j] = '\0';
    return s;
}

static void *scratch_reserve(parser *ps, size_t bytes)
{
    if (bytes > ps->scratch_cap) {
        size_t cap = ps->scratch_cap ? ps->scratch_cap : 256;
        while (cap < bytes)
            cap *= 2;
        void *n = realloc(ps->scratch, cap);
        if (!n)
            fail_at(ps, ps->line, "out of memory");
        ps->scratch = n;
        ps->scratch_cap = cap;
    }
    return ps->scratch;
}

/* ---- tokenizer -------------------------------------------------------- */

static int is_ident_start(int c) { return isalpha(c) || c == '_'; }
static int is_ident_char(int c) { return isalnum(c) || c == '_'; }

static token lex(parser *ps)
{
    for (;;) {
        while (ps->p < ps->end && (*ps->p == ' ' || *ps->p == '\t' || *ps->p == '\r' ||
                                   *ps->p == '\n' || *ps->p == '\f' || *ps->p == '\v')) {
            if (*ps->p == '\n') {
                ps->line++;
                ps->line_start = ps->p + 1;
            }
            ps->p++;
        }
        if (ps->p + 1 < ps->end && ps->p[0] == '/' && ps->p[1] == '/') {
            while (ps->p < ps->end && *ps->p != '\n')
                ps->p++;
            continue;
        }
        break;
    }
    token t = {T_EOF, ps->p, 0, ps->line, (size_t)(ps->p - ps->line_start)};
    if (ps->p >= ps->end)
        return t;
    const unsigned char c = (unsigned char)*ps->p;
    const unsigned char prev = ps->p > ps->start ? (unsigned char)ps->p[-1] : ' ';
    const unsigned char next = ps->p + 1 < ps->end ? (unsigned char)ps->p[1] : 0;
    if (c == '"') {
        const char *q = ++ps->p;
        while (ps->p < ps->end && *ps->p != '"') {
            if (*ps->p == '\\' && ps->p + 1 < ps->end)
                ps->p++;
            else if (*ps->p == '\n') {
                ps->line++;
                ps->line_start = ps->p + 1;
            }
            ps->p++;
        }
        if (ps->p >= ps->end)
            fail_at(ps, t.line, "string not closed");
        t.kind = T_STRING;
        t.s = q;
        t.n = (size_t)(ps->p - q);
        ps->p++;
        return t;
    }
    /* A sign starts a number only after a separator: "8-8" is a range and
     * "@1-" a signedness mark, while "(0.1,-5)" and "[-450|450]" hold numbers. */
    const int sign_number = (c == '-' || c == '+') && (isdigit(next) || next == '.') &&
                            !is_ident_char(prev) && prev != '.';
    if (isdigit(c) || sign_number || (c == '.' && isdigit(next))) {
        const char *q = ps->p++;
        while (ps->p < ps->end) {
            const unsigned char d = (unsigned char)*ps->p;
            if (isdigit(d) || d == '.')
                ps->p++;
            else if ((d == 'e' || d == 'E') && ps->p + 1 < ps->end &&
                     (isdigit((unsigned char)ps->p[1]) ||
                      ((ps->p[1] == '+' || ps->p[1] == '-') && ps->p + 2 < ps->end &&
                       isdigit((unsigned char)ps->p[2]))))
                ps->p += 2;
            else
                break;
        }
        t.kind = T_NUMBER;
        t.s = q;
        t.n = (size_t)(ps->p - q);
        return t;
    }
    if (is_ident_start(c)) {
        const char *q = ps->p++;
        while (ps->p < ps->end && is_ident_char((unsigned char)*ps->p))
            ps->p++;
        t.kind = T_IDENT;
        t.s = q;
        t.n = (size_t)(ps->p - q);
        return t;
    }
    t.kind = T_PUNCT;
    t.n = 1;
    ps->p++;
    return t;
}

static token next(parser *ps)
{
    if (ps->have_peek) {
        ps->have_peek = 0;
        return ps->peeked;
    }
    return lex(ps);
}

static const token *peek(parser *ps)
{
    if (!ps->have_peek) {
        ps->peeked = lex(ps);
        ps->have_peek = 1;
    }
    return &ps->peeked;
}

static int tok_is(const token *t, const char *word)
{
    size_t n = strlen(word);
    return t->n == n && memcmp(t->s, word, n) == 0 && t->kind != T_STRING;
}

static const char *describe(const token *t, char *buf, size_t size)
{
    if (t->kind == T_EOF)
        return "end of file";
    int n = t->n > 40 ? 40 : (int)t->n;
    snprintf(buf, size, "%s'%.*s'", t->kind == T_STRING ? "string " : "", n, t->s);
    return buf;
}

static token expect_kind(parser *ps, tkind kind, const char *what)
{
    token t = next(ps);
    if (t.kind != kind) {
        char b[64];
        fail_at(ps, t.line, "expected %s, found %s", what, describe(&t, b, sizeof b));
    }
    return t;
}

static void expect_punct(parser *ps, char c)
{
    token t = next(ps);
    if (t.kind != T_PUNCT || t.s[0] != c) {
        char b[64];
        fail_at(ps, t.line, "expected '%c', found %s", c, describe(&t, b, sizeof b));
    }
}

static double number_value(parser *ps, const token *t)
{
    char buf[64];
    if (t->n >= sizeof buf)
        fail_at(ps, t->line, "number too long");
    memcpy(buf, t->s, t->n);
    buf[t->n] = '\0';
    char *endp;
    errno = 0;
    double v = strtod(buf, &endp);
    if (*endp != '\0' || !isfinite(v))
        fail_at(ps, t->line, "bad number '%s'", buf);
    return v;
}

static double expect_double(parser *ps)
{
    token t = expect_kind(ps, T_NUMBER, "a number");
    return number_value(ps, &t);
}

/* An integer token within [lo, hi]. Unsigned values up to 2^64-1 pass as uint64. */
static uint64_t expect_uint(parser *ps, uint64_t hi, const char *what)
{
    token t = expect_kind(ps, T_NUMBER, what);
    char buf[32];
    if (t.n >= sizeof buf || t.s[0] == '-' || memchr(t.s, '.', t.n) || memchr(t.s, 'e', t.n) ||
        memchr(t.s, 'E', t.n))
        fail_at(ps, t.line, "expected %s, found '%.*s'", what, (int)(t.n > 30 ? 30 : t.n), t.s);
    memcpy(buf, t.s, t.n);
    buf[t.n] = '\0';
    errno = 0;
    unsigned long long v = strtoull(buf, NULL, 10);
    if (errno || v > hi)
        fail_at(ps, t.line, "%s out of range: %s", what, buf);
    return v;
}

static int64_t expect_int(parser *ps, const char *what)
{
    token t = expect_kind(ps, T_NUMBER, what);
    char buf[32];
    if (t.n >= sizeof buf || memchr(t.s, '.', t.n) || memchr(t.s, 'e', t.n) || memchr(t.s, 'E', t.n))
        fail_at(ps, t.line, "expected %s, found '%.*s'", what, (int)(t.n > 30 ? 30 : t.n), t.s);
    memcpy(buf, t.s, t.n);
    buf[t.n] = '\0';
    errno = 0;
    long long v = strtoll(buf, NULL, 10);
    if (errno) {
        /* VAL_ tables of 64-bit unsigned signals may exceed INT64_MAX: keep the bits. */
        errno = 0;
        unsigned long long u = strtoull(buf, NULL, 10);
        if (errno || buf[0] == '-')
            fail_at(ps, t.line, "%s out of range: %s", what, buf);
        v = (long long)u;
    }
    return v;
}

/* ---- statements ------------------------------------------------------- */

static const char *const top_keywords[] = {
    "VERSION", "NS_", "BS_", "BU_", "BO_", "SG_", "CM_", "BA_DEF_", "BA_", "VAL_", "VAL_TABLE_",
    "BA_DEF_DEF_", "EV_", "ENVVAR_DATA_", "SIG_VALTYPE_", "SG_MUL_VAL_", "BO_TX_BU_",
    "SIG_GROUP_", "SGTYPE_", "BA_DEF_REL_", "BA_REL_", "BA_DEF_DEF_REL_", "CAT_DEF_", "CAT_",
    "FILTER", "SIG_TYPE_REF_", "SGTYPE_VAL_", "BA_DEF_SGTYPE_", "BA_SGTYPE_", "SIGTYPE_VALTYPE_",
    "BU_SG_REL_", "BU_EV_REL_", "BU_BO_REL_", "NS_DESC_", "EV_DATA_",
};

static int is_top_keyword(const token *t)
{
    if (t->kind != T_IDENT)
        return 0;
    for (size_t i = 0; i < sizeof top_keywords / sizeof top_keywords[0]; i++)
        if (tok_is(t, top_keywords[i]))
            return 1;
    return 0;
}

/* Skip a ';'-terminated statement. A keyword at column 0 also ends it, so
 * one missing ';' costs one statement, not the rest of the file. */
static void skip_statement(parser *ps)
{
    for (;;) {
        const token *t = peek(ps);
        if (t->kind == T_EOF)
            return;
        if (t->col == 0 && is_top_keyword(t))
            return;
        token u = next(ps);
        if (u.kind == T_PUNCT && u.s[0] == ';')
            return;
    }
}

/* The rest of a line the parser does not use (BU_'s and SG_'s node lists,
 * BS_). Bytes that are not text there (NUL, 0xFF: a binary file, a broken
 * encoding) are named once per line, not skipped without a word. */
static void skip_line(parser *ps, size_t line)
{
    int warned = 0;
    while (peek(ps)->kind != T_EOF && peek(ps)->line == line) {
        token t = next(ps);
        const unsigned char c = (unsigned char)t.s[0];
        if (t.kind == T_PUNCT && (c == 0x00 || c == 0xFF) && !warned++)
            warn_at(ps, line, "byte 0x%02X at column %zu is not text (in a node list, skipped)", c, t.col + 1);
    }
}

static pb_dbc_message *find_message_raw(parser *ps, uint64_t raw_id)
{
    const uint32_t id = (uint32_t)(raw_id & 0x7fffffffu);
    const uint8_t ext = (raw_id & 0x80000000u) != 0;
    for (size_t i = 0; i < ps->dbc->message_count; i++)
        if (ps->dbc->messages[i].id == id && ps->dbc->messages[i].extended == ext)
            return &ps->dbc->messages[i];
    return NULL;
}

static int find_signal(const pb_dbc_message *m, const token *t)
{
    for (size_t i = 0; i < m->signal_count; i++)
        if (strlen(m->signals[i].name) == t->n && memcmp(m->signals[i].name, t->s, t->n) == 0)
            return (int)i;
    return -1;
}

static int is_pseudo_raw(const parser *ps, uint64_t raw)
{
    for (size_t i = 0; i < ps->pseudo_raw_count; i++)
        if (ps->pseudo_raw[i] == raw)
            return 1;
    return 0;
}

static void parse_bo(parser *ps, size_t line)
{
    uint64_t raw = expect_uint(ps, 0xffffffffu, "a message identifier");
    token name = expect_kind(ps, T_IDENT, "a message name");
    expect_punct(ps, ':');
    uint64_t size = expect_uint(ps, 64, "a message size (0..64)");
    token sender = expect_kind(ps, T_IDENT, "a sender node");
    skip_line(ps, sender.line);

    ps->in_pseudo = tok_is(&name, PSEUDO_MESSAGE);
    if (ps->in_pseudo) {
        /* Dropped, as cantools drops it; its signals are checked in parse_sg. */
        if (!is_pseudo_raw(ps, raw) && ps->pseudo_raw_count < PSEUDO_MAX)
            ps->pseudo_raw[ps->pseudo_raw_count++] = raw;
        ps->pseudo_sig_count = 0;
        return;
    }
    if ((raw & 0x7fffffffu) > 0x1fffffffu)
        fail_at(ps, line, "identifier %llu of message %.*s exceeds 29 bits (only " PSEUDO_MESSAGE " may)",
                (unsigned long long)raw, (int)(name.n > 64 ? 64 : name.n), name.s);

    pb_dbc *d = ps->dbc;
    if (d->message_count == ps->cap_messages) {
        size_t cap = ps->cap_messages ? ps->cap_messages * 2 : 16;
        pb_dbc_message *m = realloc(d->messages, cap * sizeof *m);
        size_t *cs = realloc(ps->cap_signals, cap * sizeof *cs);
        if (m)
            d->messages = m;
        if (cs)
            ps->cap_signals = cs;
        if (!m || !cs)
            fail_at(ps, line, "out of memory");
        ps->cap_messages = cap;
    }
    pb_dbc_message *m = &d->messages[d->message_count];
    memset(m, 0, sizeof *m);
    ps->cap_signals[d->message_count] = 0;
    d->message_count++;
    m->extended = (raw & 0x80000000u) != 0;
    m->id = (uint32_t)(raw & 0x7fffffffu);
    if (!m->extended && m->id > 0x7ff && m->id <= 0x1fffffff) {
        warn_at(ps, line, "identifier %u of %.*s exceeds 11 bits; treated as extended", m->id,
                (int)name.n, name.s);
        m->extended = 1;
    }
    m->size = (uint8_t)size;
    m->name = arena_str(ps, &name);
    m->sender = arena_str(ps, &sender);
    m->line = line;
}

static void parse_sg(parser *ps, size_t line)
{
    pb_dbc *d = ps->dbc;
    const int pseudo = ps->in_pseudo;
    if (d->message_count == 0 && !pseudo)
        fail_at(ps, line, "SG_ outside a message (no BO_ before it)");
    const size_t mi = pseudo ? 0 : d->message_count - 1;
    pb_dbc_message *m = pseudo ? NULL : &d->messages[mi];

    token name = expect_kind(ps, T_IDENT, "a signal name");
    int is_mux = 0, has_mux_value = 0;
    uint64_t mux_value = 0;
    if (peek(ps)->kind == T_IDENT) {
        token mx = next(ps);
        /* "M", "mN" or "mNM" (extended multiplexing: muxed and a multiplexor itself). */
        size_t i = 0;
        if (mx.s[0] == 'M' && mx.n == 1) {
            is_mux = 1;
        } else if (mx.s[0] == 'm' && mx.n >= 2 && isdigit((unsigned char)mx.s[1])) {
            i = 1;
            while (i < mx.n && isdigit((unsigned char)mx.s[i])) {
                if (mux_value > (UINT64_MAX - 9) / 10)
                    fail_at(ps, mx.line, "multiplexer value too large");
                mux_value = mux_value * 10 + (uint64_t)(mx.s[i] - '0');
                i++;
            }
            has_mux_value = 1;
            if (i < mx.n && mx.s[i] == 'M' && i + 1 == mx.n)
                is_mux = 1;
            else if (i != mx.n)
                fail_at(ps, mx.line, "bad multiplexer indicator '%.*s'", (int)mx.n, mx.s);
        } else {
            fail_at(ps, mx.line, "bad multiplexer indicator '%.*s'", (int)(mx.n > 30 ? 30 : mx.n),
                    mx.s);
        }
    }
    expect_punct(ps, ':');
    uint64_t start = expect_uint(ps, 511, "a start bit (0..511)");
    expect_punct(ps, '|');
    uint64_t length = expect_uint(ps, 64, "a bit length (1..64)");
    if (length == 0)
        fail_at(ps, line, "signal %.*s has length 0", (int)name.n, name.s);
    expect_punct(ps, '@');
    uint64_t order = expect_uint(ps, 1, "byte order 0 (Motorola) or 1 (Intel)");
    token sign = next(ps);
    if (sign.kind != T_PUNCT || (sign.s[0] != '+' && sign.s[0] != '-'))
        fail_at(ps, sign.line, "expected '+' or '-' after the byte order");
    expect_punct(ps, '(');
    double factor = expect_double(ps);
    expect_punct(ps, ',');
    double offset = expect_double(ps);
    expect_punct(ps, ')');
    expect_punct(ps, '[');
    double lo = expect_double(ps);
    expect_punct(ps, '|');
    double hi = expect_double(ps);
    expect_punct(ps, ']');
    token unit = expect_kind(ps, T_STRING, "a unit string");
    skip_line(ps, unit.line); /* receivers */

    /* Linear bit numbering: Intel counts LSB-first from bit 0 of byte 0;
     * Motorola counts MSB-first, so start bit 7 (byte 0's MSB) is linear 0
     * and the signal runs towards higher linear indices. */
    uint32_t lin, last;
    if (order == 1) {
        lin = (uint32_t)start;
        last = lin + (uint32_t)length - 1;
    } else {
        lin = (uint32_t)(start / 8 * 8 + (7 - start % 8));
        last = lin + (uint32_t)length - 1;
    }
    if (last >= 512)
        fail_at(ps, line, "signal %.*s (start %u, length %u) runs past 64 bytes", (int)name.n, name.s,
                (unsigned)start, (unsigned)length);
    if (pseudo) {
        for (size_t i = 0; i < ps->pseudo_sig_count; i++) {
            const struct pseudo_signal *o = &ps->pseudo_sigs[i];
            if (o->n == name.n && memcmp(o->s, name.s, name.n) == 0) {
                warn_at(ps, line,
                        "signal %.*s repeats in " PSEUDO_MESSAGE " (first at line %zu); that pseudo-message "
                        "of signals in no message is skipped, as cantools skips it",
                        (int)(name.n > 64 ? 64 : name.n), name.s, o->line);
                return;
            }
        }
        if (ps->pseudo_sig_count == ps->pseudo_sig_cap) {
            size_t cap = ps->pseudo_sig_cap ? ps->pseudo_sig_cap * 2 : 32;
            struct pseudo_signal *n = realloc(ps->pseudo_sigs, cap * sizeof *n);
            if (!n)
                fail_at(ps, line, "out of memory");
            ps->pseudo_sigs = n;
            ps->pseudo_sig_cap = cap;
        }
        ps->pseudo_sigs[ps->pseudo_sig_count++] = (struct pseudo_signal){name.s, name.n, line};
        return;
    }
    if (last / 8 + 1 > m->size)
        warn_at(ps, line, "signal %.*s runs past its message's %u bytes", (int)name.n, name.s,
                m->size);
    if (find_signal(m, &name) >= 0)
        fail_at(ps, line, "signal %.*s defined twice in %s", (int)name.n, name.s, m->name);

    if (m->signal_count == ps->cap_signals[mi]) {
        size_t cap = m->signal_count ? m->signal_count * 2 : 8;
        pb_dbc_signal *s = realloc(m->signals, cap * sizeof *s);
        if (!s)
            fail_at(ps, line, "out of memory");
        m->signals = s;
        ps->cap_signals[mi] = cap;
    }
    pb_dbc_signal *s = &m->signals[m->signal_count++];
    memset(s, 0, sizeof *s);
    s->name = arena_str(ps, &name);
    s->unit = arena_str(ps, &unit);
    s->start = (uint16_t)start;
    s->length = (uint16_t)length;
    s->intel = (uint8_t)order;
    s->is_signed = sign.s[0] == '-';
    s->value_type = PB_DBC_INTEGER;
    s->is_multiplexor = (uint8_t)is_mux;
    s->factor = factor;
    s->offset = offset;
    s->min = lo;
    s->max = hi;
    s->muxed_by = -1;
    s->linear_start = (uint16_t)lin;
    s->bytes_needed = (uint8_t)(last / 8 + 1);
    s->has_mux_value = (uint8_t)has_mux_value;
    s->mux_value = mux_value;
    s->line = line;
    if (factor == 0.0)
        warn_at(ps, line, "signal %s has factor 0: it always reads its offset %g", s->name, offset);
}

static int cmp_choice(const void *a, const void *b)
{
    const pb_dbc_choice *x = a, *y = b;
    return x->value < y->value ? -1 : x->value > y->value;
}

static void parse_val(parser *ps, size_t line)
{
    if (peek(ps)->kind != T_NUMBER) { /* VAL_ of an environment variable */
        skip_statement(ps);
        return;
    }
    uint64_t raw = expect_uint(ps, 0xffffffffu, "a message identifier");
    token sig = expect_kind(ps, T_IDENT, "a signal name");
    size_t n = 0;
    for (;;) {
        const token *t = peek(ps);
        if (t->kind == T_PUNCT && t->s[0] == ';') {
            next(ps);
            break;
        }
        int64_t v = expect_int(ps, "a raw value");
        token text = expect_kind(ps, T_STRING, "a value description");
        pb_dbc_choice *c = scratch_reserve(ps, (n + 1) * sizeof *c);
        c[n].value = v;
        c[n].text = arena_str(ps, &text);
        n++;
    }
    if (is_pseudo_raw(ps, raw))
        return;
    pb_dbc_message *m = find_message_raw(ps, raw);
    int si = m ? find_signal(m, &sig) : -1;
    if (si < 0) {
        warn_at(ps, line, "VAL_ for unknown signal %.*s of message %llu", (int)sig.n, sig.s,
                (unsigned long long)raw);
        return;
    }
    pb_dbc_choice *c = arena_alloc(ps, (n ? n : 1) * sizeof *c);
    if (n)
        memcpy(c, ps->scratch, n * sizeof *c);
    qsort(c, n, sizeof *c, cmp_choice);
    m->signals[si].choices = c;
    m->signals[si].choice_count = n;
}

static void parse_sig_valtype(parser *ps, size_t line)
{
    uint64_t raw = expect_uint(ps, 0xffffffffu, "a message identifier");
    token sig = expect_kind(ps, T_IDENT, "a signal name");
    if (peek(ps)->kind == T_PUNCT && peek(ps)->s[0] == ':')
        next(ps);
    uint64_t type = expect_uint(ps, 3, "a value type (0..3)");
    expect_punct(ps, ';');
    if (is_pseudo_raw(ps, raw))
        return;
    pb_dbc_message *m = find_message_raw(ps, raw);
    int si = m ? find_signal(m, &sig) : -1;
    if (si < 0) {
        warn_at(ps, line, "SIG_VALTYPE_ for unknown signal %.*s", (int)sig.n, sig.s);
        return;
    }
    pb_dbc_signal *s = &m->signals[si];
    if (type == 1 && s->length != 32)
        fail_at(ps, line, "float signal %s must be 32 bits long, not %u", s->name, s->length);
    if (type == 2 && s->length != 64)
        fail_at(ps, line, "double signal %s must be 64 bits long, not %u", s->name, s->length);
    if (type == 3)
        fail_at(ps, line, "value type 3 of %s is not defined", s->name);
    s->value_type = (uint8_t)type;
}

static void parse_sg_mul_val(parser *ps, size_t line)
{
    uint64_t raw = expect_uint(ps, 0xffffffffu, "a message identifier");
    token sig = expect_kind(ps, T_IDENT, "a signal name");
    token mux = expect_kind(ps, T_IDENT, "a multiplexor name");
    size_t n = 0;
    for (;;) {
        uint64_t lo = expect_uint(ps, UINT64_MAX, "a range start");
        expect_punct(ps, '-');
        uint64_t hi = expect_uint(ps, UINT64_MAX, "a range end");
        if (hi < lo)
            fail_at(ps, line, "multiplexer range %llu-%llu is empty", (unsigned long long)lo,
                    (unsigned long long)hi);
        pb_dbc_mux_range *r = scratch_reserve(ps, (n + 1) * sizeof *r);
        r[n].lo = lo;
        r[n].hi = hi;
        n++;
        token t = next(ps);
        if (t.kind == T_PUNCT && t.s[0] == ';')
            break;
        if (t.kind != T_PUNCT || t.s[0] != ',')
            fail_at(ps, t.line, "expected ',' or ';' in SG_MUL_VAL_");
    }
    if (is_pseudo_raw(ps, raw))
        return;
    pb_dbc_message *m = find_message_raw(ps, raw);
    int si = m ? find_signal(m, &sig) : -1;
    int mi = m ? find_signal(m, &mux) : -1;
    if (si < 0 || mi < 0) {
        warn_at(ps, line, "SG_MUL_VAL_ names unknown signals %.*s / %.*s", (int)sig.n, sig.s,
                (int)mux.n, mux.s);
        return;
    }
    if (!m->signals[mi].is_multiplexor)
        fail_at(ps, line, "%s is not a multiplexor (no M in its SG_ line)", m->signals[mi].name);
    pb_dbc_mux_range *r = arena_alloc(ps, n * sizeof *r);
    memcpy(r, ps->scratch, n * sizeof *r);
    m->signals[si].muxed_by = mi;
    m->signals[si].mux_ranges = r;
    m->signals[si].mux_range_count = n;
}

/* Simple multiplexing ("mN" without SG_MUL_VAL_) refers to the message's
 * one top-level multiplexor; then reject loops in the multiplexor chain. */
static void resolve_multiplexing(parser *ps)
{
    pb_dbc *d = ps->dbc;
    for (size_t i = 0; i < d->message_count; i++) {
        pb_dbc_message *m = &d->messages[i];
        int top = -1, tops = 0;
        for (size_t j = 0; j < m->signal_count; j++)
            if (m->signals[j].is_multiplexor && !m->signals[j].has_mux_value) {
                top = (int)j;
                tops++;
            }
        for (size_t j = 0; j < m->signal_count; j++) {
            pb_dbc_signal *s = &m->signals[j];
            if (!s->has_mux_value || s->muxed_by >= 0)
                continue;
            if (tops != 1)
                fail_at(ps, s->line, "signal %s is multiplexed but message %s has %s multiplexor",
                        s->name, m->name, tops ? "more than one" : "no");
            pb_dbc_mux_range *r = arena_alloc(ps, sizeof *r);
            r->lo = r->hi = s->mux_value;
            s->muxed_by = top;
            s->mux_ranges = r;
            s->mux_range_count = 1;
        }
        for (size_t j = 0; j < m->signal_count; j++) {
            int k = m->signals[j].muxed_by;
            for (size_t steps = 0; k >= 0; steps++) {
                if (steps > m->signal_count || k == (int)j)
                    fail_at(ps, m->signals[j].line, "multiplexor loop at signal %s",
                            m->signals[j].name);
                k = m->signals[k].muxed_by;
            }
        }
    }
}

/* The frame bits a signal occupies, as a 512-bit set (bit 8*byte + bit). */
static void signal_bits(const pb_dbc_signal *s, uint64_t bits[8])
{
    memset(bits, 0, 8 * sizeof *bits);
    for (unsigned k = 0; k < s->length; k++) {
        const unsigned lin = s->linear_start + k;
        const unsigned bit = s->intel ? lin : lin / 8 * 8 + (7 - lin % 8);
        bits[bit / 64] |= UINT64_C(1) << (bit % 64);
    }
}

static int mux_ranges_meet(const pb_dbc_signal *a, const pb_dbc_signal *b)
{
    for (size_t i = 0; i < a->mux_range_count; i++)
        for (size_t j = 0; j < b->mux_range_count; j++)
            if (a->mux_ranges[i].lo <= b->mux_ranges[j].hi && b->mux_ranges[j].lo <= a->mux_ranges[i].hi)
                return 1;
    return 0;
}

/* Signals of one message that share bits while both can be present (neither
 * multiplexed, one multiplexed, or both by the same multiplexor for a common
 * value) decode each other's bits: a warning, once per signal. Signals of
 * different multiplexors are not compared. Pairwise: messages hold tens of
 * signals; those with more than 1024 are not checked. */
static void check_overlaps(parser *ps)
{
    const pb_dbc *d = ps->dbc;
    for (size_t i = 0; i < d->message_count; i++) {
        const pb_dbc_message *m = &d->messages[i];
        if (m->signal_count < 2 || m->signal_count > 1024)
            continue;
        uint64_t(*bits)[8] = scratch_reserve(ps, m->signal_count * sizeof *bits);
        for (size_t j = 0; j < m->signal_count; j++)
            signal_bits(&m->signals[j], bits[j]);
        for (size_t j = 1; j < m->signal_count; j++) {
            const pb_dbc_signal *a = &m->signals[j];
            for (size_t k = 0; k < j; k++) {
                const pb_dbc_signal *b = &m->signals[k];
                if (a->muxed_by >= 0 && b->muxed_by >= 0 &&
                    (a->muxed_by != b->muxed_by || !mux_ranges_meet(a, b)))
                    continue;
                uint64_t common = 0;
                for (int w = 0; w < 8; w++)
                    common |= bits[j][w] & bits[k][w];
                if (common) {
                    warn_at(ps, a->line, "signal %s overlaps signal %s (line %zu) in message %s", a->name, b->name,
                            b->line, m->name);
                    break;
                }
            }
        }
    }
}

static int cmp_index(const void *a, const void *b)
{
    const struct pb_dbc_index_entry *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->message < y->message ? -1 : x->message > y->message;
}

static void build_index(parser *ps)
{
    pb_dbc *d = ps->dbc;
    d->index = malloc((d->message_count ? d->message_count : 1) * sizeof *d->index);
    if (!d->index)
        fail_at(ps, ps->line, "out of memory");
    size_t n = 0;
    for (size_t i = 0; i < d->message_count; i++) {
        const pb_dbc_message *m = &d->messages[i];
        if (m->id > 0x1fffffff) /* cannot happen: parse_bo refuses such identifiers */
            continue;
        d->index[n].key = m->id | (uint32_t)m->extended << 31;
        d->index[n].message = (uint32_t)i;
        n++;
    }
    qsort(d->index, n, sizeof *d->index, cmp_index);
    /* Keep the first definition of a duplicated identifier. */
    size_t w = 0;
    for (size_t i = 0; i < n; i++) {
        if (w && d->index[w - 1].key == d->index[i].key) {
            warn_at(ps, d->messages[d->index[i].message].line, "message %s repeats identifier %u",
                    d->messages[d->index[i].message].name, d->messages[d->index[i].message].id);
            continue;
        }
        d->index[w++] = d->index[i];
    }
    /* The index is searched over message_count entries: pad the slots that
     * pseudo or repeated messages left with keys that sort last and match nothing. */
    for (size_t i = w; i < d->message_count; i++) {
        d->index[i].key = UINT32_MAX;
        d->index[i].message = UINT32_MAX;
    }
}

/* BA_ "GenMsgCycleTime" BO_ <id> <ms>; gives the node monitor its timeout.
 * Every other attribute is skipped. */
static void parse_ba(parser *ps, size_t line)
{
    const token *t = peek(ps);
    if (t->kind != T_STRING || !(t->n == 15 && memcmp(t->s, "GenMsgCycleTime", 15) == 0)) {
        skip_statement(ps);
        return;
    }
    next(ps);
    if (!tok_is(peek(ps), "BO_")) {
        skip_statement(ps);
        return;
    }
    next(ps);
    uint64_t raw = expect_uint(ps, 0xffffffffu, "a message identifier");
    double ms = expect_double(ps);
    expect_punct(ps, ';');
    if (is_pseudo_raw(ps, raw))
        return;
    pb_dbc_message *m = find_message_raw(ps, raw);
    if (!m) {
        warn_at(ps, line, "GenMsgCycleTime for unknown message %llu", (unsigned long long)raw);
        return;
    }
    m->cycle_ms = ms > 0 && ms < 3600e3 ? (uint32_t)ms : 0;
}

static void parse_all(parser *ps)
{
    for (;;) {
        token t = next(ps);
        if (t.kind == T_EOF)
            break;
        if (t.kind != T_IDENT) {
            char b[64];
            fail_at(ps, t.line, "expected a keyword, found %s", describe(&t, b, sizeof b));
        }
        if (tok_is(&t, "VERSION")) {
            expect_kind(ps, T_STRING, "a version string");
        } else if (tok_is(&t, "NS_")) {
            /* The list names statement keywords, indented or not; BS_, BU_ or
             * BO_ (never in it) end it. */
            expect_punct(ps, ':');
            while (peek(ps)->kind == T_IDENT && !tok_is(peek(ps), "BS_") && !tok_is(peek(ps), "BU_") &&
                   !tok_is(peek(ps), "BO_"))
                next(ps);
        } else if (tok_is(&t, "BS_") || tok_is(&t, "BU_")) {
            expect_punct(ps, ':');
            skip_line(ps, t.line);
        } else if (tok_is(&t, "BO_")) {
            parse_bo(ps, t.line);
        } else if (tok_is(&t, "SG_")) {
            parse_sg(ps, t.line);
        } else if (tok_is(&t, "VAL_")) {
            parse_val(ps, t.line);
        } else if (tok_is(&t, "SIG_VALTYPE_")) {
            parse_sig_valtype(ps, t.line);
        } else if (tok_is(&t, "SG_MUL_VAL_")) {
            parse_sg_mul_val(ps, t.line);
        } else if (tok_is(&t, "BA_")) {
            parse_ba(ps, t.line);
        } else if (is_top_keyword(&t)) {
            skip_statement(ps);
        } else {
            /* Unknown keywords from newer tools: skip like any ';' statement. */
            warn_at(ps, t.line, "unknown keyword %.*s skipped", (int)(t.n > 40 ? 40 : t.n), t.s);
            skip_statement(ps);
        }
    }
    resolve_multiplexing(ps);
    check_overlaps(ps);
    build_index(ps);
}

int pb_dbc_parse(const char *text, size_t len, const char *name, pb_dbc **out, pb_dbc_error *err)
{
    *out = NULL;
    if (err) {
        err->message[0] = '\0';
        err->line = 0;
    }
    parser *ps = calloc(1, sizeof *ps);
    pb_dbc *d = calloc(1, sizeof *d);
    char *path = strdup(name ? name : "<dbc>");
    if (!ps || !d || !path) {
        free(ps);
        free(d);
        free(path);
        if (err)
            snprintf(err->message, sizeof err->message, "%s: out of memory", name ? name : "<dbc>");
        return -1;
    }
    d->path = path;
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0) { /* UTF-8 byte order mark */
        text += 3;
        len -= 3;
    }
    ps->p = ps->start = ps->line_start = text;
    ps->end = text + len;
    ps->name = d->path;
    ps->line = 1;
    ps->dbc = d;
    ps->err = err;
    int rc = 0;
    if (setjmp(ps->fail) == 0) {
        parse_all(ps);
        *out = d;
    } else {
        pb_dbc_free(d);
        rc = -1;
    }
    free(ps->cap_signals);
    free(ps->scratch);
    free(ps->pseudo_sigs);
    free(ps);
    return rc;
}

int pb_dbc_load(const char *path, pb_dbc **out, pb_dbc_error *err)
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        if (err)
            snprintf(err->message, sizeof err->message, "%s: %s", path, strerror(errno));
        return -1;
    }
    char *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (cap - n < 65536) {
            cap = cap ? cap * 2 : 65536;
            char *b = realloc(buf, cap);
            if (!b) {
                free(buf);
                fclose(f);
                if (err)
                    snprintf(err->message, sizeof err->message, "%s: out of memory", path);
                return -1;
            }
            buf = b;
        }
        size_t r = fread(buf + n, 1, cap - n, f);
        n += r;
        if (r == 0)
            break;
        if (n > PB_DBC_MAX_FILE) { /* the largest real DBCs are a few MB; this is not one */
            free(buf);
            fclose(f);
            if (err)
                snprintf(err->message, sizeof err->message, "%s: larger than %u MiB", path,
                         PB_DBC_MAX_FILE >> 20);
            return -1;
        }
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        if (err)
            snprintf(err->message, sizeof err->message, "%s: read error", path);
        return -1;
    }
    int rc = pb_dbc_parse(buf, n, path, out, err);
    free(buf);
    return rc;
}

void pb_dbc_free(pb_dbc *d)
{
    if (!d)
        return;
    for (size_t i = 0; i < d->message_count; i++)
        free(d->messages[i].signals);
    free(d->messages);
    free(d->index);
    struct pb_dbc_arena *a = d->arena;
    while (a) {
        struct pb_dbc_arena *n = a->next;
        free(a);
        a = n;
    }
    free(d->path);
    free(d);
}

const pb_dbc_message *pb_dbc_find(const pb_dbc *d, uint32_t id, int extended)
{
    if (!d->index)
        return NULL;
    const uint32_t key = (id & 0x1fffffffu) | (extended ? 1u << 31 : 0);
    size_t lo = 0, hi = d->message_count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (d->index[mid].key < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo < d->message_count && d->index[lo].key == key && d->index[lo].message != UINT32_MAX)
        return &d->messages[d->index[lo].message];
    return NULL;
}

int pb_dbc_find_signal(const pb_dbc *d, const char *msg, const char *sig,
                       const pb_dbc_message **out_msg)
{
    for (size_t i = 0; i < d->message_count; i++) {
        const pb_dbc_message *m = &d->messages[i];
        if (strcmp(m->name, msg) != 0)
            continue;
        for (size_t j = 0; j < m->signal_count; j++)
            if (strcmp(m->signals[j].name, sig) == 0) {
                if (out_msg)
                    *out_msg = m;
                return (int)j;
            }
    }
    return -1;
}

const char *pb_dbc_choice_text(const pb_dbc_signal *s, int64_t raw)
{
    size_t lo = 0, hi = s->choice_count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (s->choices[mid].value < raw)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < s->choice_count && s->choices[lo].value == raw ? s->choices[lo].text : NULL;
}
