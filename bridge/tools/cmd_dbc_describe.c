/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge dbc-describe: what a DBC file holds, as the bridge reads it:
 * messages, signals with their bit layout, scaling, range, multiplexing and
 * value tables; warnings the parser raised; parse errors with file:line. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dbc_parse.h"
#include "pose_bridge_cli.h"
#include "pose_cli.h"

static void help(FILE *f)
{
    fprintf(f, "usage: pose-bridge dbc-describe FILE.dbc [--json]\n"
               "  --json   machine-readable output\n"
               "Lists every message (identifier, size, cycle time) and signal (start bit,\n"
               "length, byte order, sign, value type, factor, offset, range, unit,\n"
               "multiplexing, value table). Exit status 1 with FILE:LINE on a parse error.\n");
}

/* JSON string; DBC text is often Windows-1252: bytes that are not UTF-8 are
 * written as the Latin-1 code point so the output stays valid JSON. */
static void json_text(const char *s)
{
    const unsigned char *p = (const unsigned char *)s;
    putchar('"');
    while (*p) {
        unsigned c = *p;
        size_t n = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
        int valid = n > 0;
        for (size_t k = 1; valid && k < n; k++)
            valid = (p[k] & 0xc0) == 0x80;
        if (c == '"' || c == '\\')
            printf("\\%c", c);
        else if (c < 0x20)
            printf("\\u%04x", c);
        else if (valid && n > 1) {
            fwrite(p, 1, n, stdout);
            p += n;
            continue;
        } else if (!valid)
            printf("\\u%04x", c);
        else
            putchar((int)c);
        p++;
    }
    putchar('"');
}

static void num(double v)
{
    if (!isfinite(v))
        fputs("null", stdout);
    else
        printf("%.17g", v);
}

static const char *type_name(const pb_dbc_signal *s)
{
    return s->value_type == PB_DBC_FLOAT32 ? "float32" : s->value_type == PB_DBC_FLOAT64 ? "float64"
           : s->is_signed                  ? "signed"
                                           : "unsigned";
}

static pb_warnings warnings; /* what the parser warned about, file:line each */

static void describe_json(const pb_dbc *d)
{
    printf("{\"file\":");
    json_text(d->path);
    printf(",\"warning_count\":%zu,", d->warning_count);
    pb_cli_json_warnings(stdout, &warnings);
    printf(",\"messages\":[");
    for (size_t i = 0; i < d->message_count; i++) {
        const pb_dbc_message *m = &d->messages[i];
        printf("%s\n{\"name\":", i ? "," : "");
        json_text(m->name);
        printf(",\"id\":%u,\"extended\":%s,\"size\":%u,\"cycle_ms\":%u,\"sender\":", (unsigned)m->id,
               m->extended ? "true" : "false", m->size, (unsigned)m->cycle_ms);
        json_text(m->sender);
        printf(",\"signals\":[");
        for (size_t j = 0; j < m->signal_count; j++) {
            const pb_dbc_signal *s = &m->signals[j];
            printf("%s{\"name\":", j ? "," : "");
            json_text(s->name);
            printf(",\"start\":%u,\"length\":%u,\"byte_order\":\"%s\",\"type\":\"%s\",\"factor\":", s->start,
                   s->length, s->intel ? "intel" : "motorola", type_name(s));
            num(s->factor);
            printf(",\"offset\":");
            num(s->offset);
            printf(",\"min\":");
            num(s->min);
            printf(",\"max\":");
            num(s->max);
            printf(",\"unit\":");
            json_text(s->unit);
            if (s->is_multiplexor)
                printf(",\"multiplexor\":true");
            if (s->muxed_by >= 0) {
                printf(",\"multiplexed_by\":");
                json_text(m->signals[s->muxed_by].name);
                printf(",\"multiplexer_values\":[");
                for (size_t k = 0; k < s->mux_range_count; k++)
                    printf("%s[%llu,%llu]", k ? "," : "", (unsigned long long)s->mux_ranges[k].lo,
                           (unsigned long long)s->mux_ranges[k].hi);
                putchar(']');
            }
            if (s->choice_count) {
                printf(",\"choices\":{");
                for (size_t k = 0; k < s->choice_count; k++) {
                    printf("%s\"%lld\":", k ? "," : "", (long long)s->choices[k].value);
                    json_text(s->choices[k].text);
                }
                putchar('}');
            }
            putchar('}');
        }
        printf("]}");
    }
    printf("]}\n");
}

static void describe_text(const pb_dbc *d)
{
    printf("%s: %zu messages, %zu warnings%s\n", d->path, d->message_count, d->warning_count,
           d->warning_count ? " (on stderr)" : "");
    for (size_t i = 0; i < d->message_count; i++) {
        const pb_dbc_message *m = &d->messages[i];
        printf("%s 0x%0*X (%u) %u bytes%s", m->name, m->extended ? 8 : 3, (unsigned)m->id, (unsigned)m->id,
               m->size, m->extended ? " extended" : "");
        if (m->cycle_ms)
            printf(", every %u ms", (unsigned)m->cycle_ms);
        printf(", from %s\n", m->sender);
        for (size_t j = 0; j < m->signal_count; j++) {
            const pb_dbc_signal *s = &m->signals[j];
            printf("  %-20s %3u|%-2u %-8s %-8s x%g %+g [%g, %g] %s", s->name, s->start, s->length,
                   s->intel ? "intel" : "motorola", type_name(s), s->factor, s->offset, s->min, s->max, s->unit);
            if (s->is_multiplexor)
                printf(" multiplexor");
            if (s->muxed_by >= 0) {
                printf(" when %s in", m->signals[s->muxed_by].name);
                for (size_t k = 0; k < s->mux_range_count; k++)
                    printf(" %llu-%llu", (unsigned long long)s->mux_ranges[k].lo,
                           (unsigned long long)s->mux_ranges[k].hi);
            }
            if (s->choice_count)
                printf(" (%zu named values)", s->choice_count);
            putchar('\n');
        }
    }
}

static int run(int argc, char **argv)
{
    enum { OPT_JSON = POSE_CLI_LONG_ONLY };
    static const struct option options[] = {
        {"json", no_argument, NULL, OPT_JSON}, {"help", no_argument, NULL, 'h'}, {0}};
    const char *file = NULL;
    int json = 0;
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bridge dbc-describe", argc, argv, options);
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
        switch (c) {
        case 'h':
            help(stdout);
            return 0;
        case OPT_JSON:
            json = 1;
            break;
        case POSE_CLI_ARGUMENT:
            if (file) {
                pose_cli_error(&cli, "unexpected argument '%s' (one DBC only)", cli.value);
                return 2;
            }
            file = cli.value;
            break;
        default: /* POSE_CLI_ERROR: reported */
            return 2;
        }
    if (!file) {
        pose_cli_error(&cli, "no DBC file given");
        return 2;
    }
    pb_dbc *d = NULL;
    pb_dbc_error err;
    pb_cli_warnings_begin(&warnings);
    int loaded = pb_dbc_load(file, &d, &err);
    pb_warnings_install(NULL);
    if (loaded != 0) {
        fprintf(stderr, "pose-bridge dbc-describe: %s\n", err.message);
        return 1;
    }
    if (json)
        describe_json(d);
    else
        describe_text(d);
    pb_dbc_free(d);
    return 0;
}

const pb_command pb_cmd_dbc_describe = {"dbc-describe", "list a DBC file's messages and signals", run};
