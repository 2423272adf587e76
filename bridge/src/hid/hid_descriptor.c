/* SPDX-License-Identifier: Apache-2.0
 *
 * HID report-descriptor parser. Hand-written: no permissively licensed C
 * library in Debian parses descriptors into field layouts (hidapi only hands
 * out the bytes; the kernel's parser is GPL and in-kernel), and the item
 * grammar is small. Behaviour follows HID 1.11 section 6.2.2, with the
 * kernel's readings where the spec is loose (noted where they apply).
 *
 * What real descriptors get away with is decided by what the Linux kernel
 * accepts (drivers/hid/hid-core.c, hid_open_report and the hid_parser_*
 * dispatchers), since that is what runs these devices:
 *   - a main item with a reserved tag, e.g. a stray 0x00 byte after the last
 *     End Collection: the kernel logs "unknown main item tag" and goes on
 *     (hid_parser_main); here: skipped with a warning (pb_warn);
 *   - an item of the reserved type 3, and a local item with a reserved tag:
 *     the kernel skips them (hid_parser_reserved, hid_parser_local); here:
 *     skipped with a warning;
 *   - a global item with a reserved tag: the kernel refuses the descriptor
 *     ("unknown global tag"), so do we;
 *   - a long item (any prefix 0xF0..0xFF): the kernel's fetch_item reads it
 *     and hid_open_report then refuses it ("unexpected long global item"),
 *     so do we (hid-tools refuses it too);
 *   - a Report Count above 12288 (the kernel's HID_MAX_USAGES) and a logical
 *     maximum below the logical minimum (hid_add_field) are refused;
 *   - what the kernel keeps but a 32-bit signed field cannot hold is kept with
 *     a warning: an unsigned maximum above INT32_MAX (clamped) and a unit
 *     exponent no double can carry (taken as 0).
 */
#include "hid_descriptor.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pb_warn.h"

/* Item types and tags (HID 1.11, 6.2.2.4-6.2.2.8). */
enum { TYPE_MAIN = 0, TYPE_GLOBAL = 1, TYPE_LOCAL = 2, TYPE_RESERVED = 3 };
enum { MAIN_INPUT = 0x8, MAIN_OUTPUT = 0x9, MAIN_COLLECTION = 0xA, MAIN_FEATURE = 0xB, MAIN_END_COLLECTION = 0xC };
enum {
    G_USAGE_PAGE = 0x0, G_LOGICAL_MIN = 0x1, G_LOGICAL_MAX = 0x2, G_PHYSICAL_MIN = 0x3,
    G_PHYSICAL_MAX = 0x4, G_UNIT_EXPONENT = 0x5, G_UNIT = 0x6, G_REPORT_SIZE = 0x7,
    G_REPORT_ID = 0x8, G_REPORT_COUNT = 0x9, G_PUSH = 0xA, G_POP = 0xB,
};
enum { L_USAGE = 0x0, L_USAGE_MIN = 0x1, L_USAGE_MAX = 0x2, L_DELIMITER = 0xA };
#define LONG_ITEM_TAG 0xF        /* the kernel's HID_ITEM_TAG_LONG: any prefix 0xF0..0xFF */
#define KERNEL_MAX_REPORT_COUNT 12288 /* the kernel's HID_MAX_USAGES */

/* Global state; Push/Pop copy it whole. Maxima keep both readings of their
 * bytes because whether they are signed depends on the minimum (kernel rule:
 * a negative minimum makes the maximum signed, else it is unsigned). */
typedef struct globals {
    uint32_t usage_page;
    int64_t logical_min, logical_max_s, logical_max_u;
    int64_t physical_min, physical_max_s, physical_max_u;
    int32_t unit_exponent;
    uint32_t unit, report_size, report_count, report_id;
} globals;

typedef struct usage_range {
    uint32_t first, last;
    bool extended; /* 32-bit usage: carries its own page */
} usage_range;

typedef struct parser {
    size_t pos, len;
    uint8_t byte; /* prefix of the item at pos */
    const char *origin;
    pb_error *err;
    pose_status status;
    globals g, stack[PB_HID_MAX_DEPTH];
    int stack_depth;
    usage_range usages[PB_HID_MAX_USAGES];
    size_t usage_count;
    bool have_min;
    uint32_t pending_min;
    bool pending_min_extended;
    int delimiter_depth;
    bool delimiter_taken;
    int32_t open[PB_HID_MAX_DEPTH];
    int open_depth;
    bool seen_data_without_id;
    uint32_t bits[3][256];
    pb_hid_desc *d;
    size_t field_cap, pool_len, pool_cap;
} parser;

static int fail(parser *p, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static int fail(parser *p, const char *fmt, ...)
{
    char msg[192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (p->status == POSE_OK)
        p->status = strcmp(msg, "out of memory") == 0 ? POSE_ERR_OUT_OF_MEMORY : POSE_ERR_FORMAT;
    pb_fail(p->err, p->status, "%s: report descriptor byte %zu: %s", p->origin, p->pos, msg);
    return -1;
}

/* A warning about the item at p->pos, naming the origin and byte offset. */
static void warn_at(const parser *p, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void warn_at(const parser *p, const char *fmt, ...)
{
    char msg[192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    pb_warn("%s: report descriptor byte %zu: %s", p->origin, p->pos, msg);
}

static void clear_locals(parser *p)
{
    p->usage_count = 0;
    p->have_min = false;
    p->delimiter_taken = false;
}

static int add_usage(parser *p, uint32_t first, uint32_t last, bool extended)
{
    if (p->delimiter_depth > 0) {
        /* Delimited sets list alternatives; the first one is the preferred usage. */
        if (p->delimiter_taken)
            return 0;
        p->delimiter_taken = true;
    }
    if (p->usage_count >= PB_HID_MAX_USAGES)
        return fail(p, "more than %d usages before one main item", PB_HID_MAX_USAGES);
    p->usages[p->usage_count++] = (usage_range){first, last, extended};
    return 0;
}

/* Usage page applies to usages shorter than 32 bits at the main item (kernel
 * reading since 5.x; the spec lets the page change after the usage). */
static uint32_t resolve(const parser *p, uint32_t u, bool extended)
{
    return extended ? u : (p->g.usage_page << 16) | (u & 0xFFFF);
}

static int pool_push(parser *p, uint32_t v)
{
    if (p->pool_len == p->pool_cap) {
        size_t cap = p->pool_cap ? p->pool_cap * 2 : 64;
        uint32_t *n = realloc(p->d->usage_pool, cap * sizeof *n);
        if (!n)
            return fail(p, "out of memory");
        p->d->usage_pool = n;
        p->pool_cap = cap;
    }
    p->d->usage_pool[p->pool_len++] = v;
    return 0;
}

static pb_hid_field *new_field(parser *p)
{
    pb_hid_desc *d = p->d;
    if (d->field_count >= PB_HID_MAX_FIELDS) {
        fail(p, "more than %d fields", PB_HID_MAX_FIELDS);
        return NULL;
    }
    if (d->field_count == p->field_cap) {
        size_t cap = p->field_cap ? p->field_cap * 2 : 32;
        pb_hid_field *n = realloc(d->fields, cap * sizeof *n);
        if (!n) {
            fail(p, "out of memory");
            return NULL;
        }
        d->fields = n;
        p->field_cap = cap;
    }
    pb_hid_field *f = &d->fields[d->field_count++];
    memset(f, 0, sizeof *f);
    return f;
}

static int32_t nibble(uint32_t unit, int shift)
{
    int32_t v = (int32_t)((unit >> shift) & 0xF);
    return v >= 8 ? v - 16 : v;
}

/* Names the common units; others print as their raw code so nothing is hidden. */
static void unit_name(uint32_t unit, char *out, size_t size)
{
    int32_t system = (int32_t)(unit & 0xF);
    int32_t length = nibble(unit, 4), mass = nibble(unit, 8), time = nibble(unit, 12);
    int32_t temp = nibble(unit, 16), current = nibble(unit, 20), light = nibble(unit, 24);
    bool only_length = length != 0 && mass == 0 && time == 0 && temp == 0 && current == 0 && light == 0;
    bool rotation = system == 2 || system == 4;
    const char *name = NULL;
    if (unit == 0)
        name = "";
    else if (only_length && length == 1)
        name = system == 1 ? "cm" : system == 2 ? "rad" : system == 3 ? "in" : system == 4 ? "deg" : NULL;
    else if (rotation && length == 1 && time == -1 && mass == 0 && temp == 0 && current == 0 && light == 0)
        name = system == 2 ? "rad/s" : "deg/s";
    else if (time == 1 && length == 0 && mass == 0 && temp == 0 && current == 0 && light == 0)
        name = "s";
    else if (mass == 1 && length == 0 && time == 0 && temp == 0 && current == 0 && light == 0)
        name = system == 1 || system == 2 ? "g" : "slug";
    if (name)
        snprintf(out, size, "%s", name);
    else
        snprintf(out, size, "0x%x", unit);
}

static void set_scaling(pb_hid_field *f)
{
    double lmin = f->logical_min, lmax = f->logical_max;
    double pmin = f->physical_min, pmax = f->physical_max;
    if (f->physical_min == 0 && f->physical_max == 0) {
        pmin = lmin; /* spec: undefined physical range = logical range */
        pmax = lmax;
    }
    double e = f->unit ? pow(10.0, f->unit_exponent) : 1.0;
    if (lmax == lmin) {
        f->scale = e;
        f->offset = 0.0;
    } else {
        double s = (pmax - pmin) / (lmax - lmin);
        f->scale = s * e;
        f->offset = (pmin - lmin * s) * e;
    }
    unit_name(f->unit, f->unit_name, sizeof f->unit_name);
}

/* Usage of the i-th value of a Variable item: the i-th usage of the list, the
 * last one repeating when the list is shorter than the count (HID 1.11, 6.2.2.8). */
static uint32_t nth_usage(const parser *p, uint32_t i)
{
    uint32_t last = 0;
    for (size_t k = 0; k < p->usage_count; k++) {
        const usage_range *r = &p->usages[k];
        uint32_t n = r->last - r->first + 1;
        if (i < n)
            return resolve(p, r->first + i, r->extended);
        i -= n;
        last = resolve(p, r->last, r->extended);
    }
    return last;
}

static int main_data(parser *p, uint32_t tag, uint32_t data)
{
    int kind = tag == MAIN_INPUT ? PB_HID_INPUT : tag == MAIN_OUTPUT ? PB_HID_OUTPUT : PB_HID_FEATURE;
    const globals *g = &p->g;
    uint32_t rid = g->report_id;
    if (rid == 0)
        p->seen_data_without_id = true;
    /* hid_add_field refuses a logical maximum below the minimum, padding included. */
    if (g->logical_min < 0 ? g->logical_max_s < g->logical_min
                           : (uint32_t)g->logical_max_u < (uint32_t)g->logical_min)
        return fail(p, "logical maximum %lld below logical minimum %lld",
                    (long long)(g->logical_min < 0 ? g->logical_max_s : g->logical_max_u), (long long)g->logical_min);
    uint64_t total = (uint64_t)g->report_size * g->report_count;
    uint32_t *bits = &p->bits[kind][rid];
    if ((uint64_t)*bits + total > (uint64_t)PB_HID_MAX_REPORT_BYTES * 8)
        return fail(p, "report %u grows beyond %d bytes", rid, PB_HID_MAX_REPORT_BYTES);
    if (total == 0) {
        clear_locals(p);
        return 0;
    }
    bool is_signed = g->logical_min < 0;
    int64_t lmax = is_signed ? g->logical_max_s : g->logical_max_u;
    int64_t pmax = g->physical_min < 0 ? g->physical_max_s : g->physical_max_u;
    /* An unsigned maximum above INT32_MAX (e.g. Logical Maximum 0xFFFFFFFF for a 32-bit
     * counter): the kernel keeps the field, its values being signed 32-bit as here;
     * the maximum is clamped so that the range stays ordered. Minima are signed items. */
    if (lmax > INT32_MAX) {
        warn_at(p, "logical maximum %lld does not fit 32-bit signed values; kept as %d, as values above it "
                   "decode negative (as in the Linux kernel)", (long long)lmax, INT32_MAX);
        lmax = INT32_MAX;
    }
    if (pmax > INT32_MAX) {
        warn_at(p, "physical maximum %lld does not fit 32-bit signed values; kept as %d", (long long)pmax, INT32_MAX);
        pmax = INT32_MAX;
    }
    int32_t parent = p->open_depth ? p->open[p->open_depth - 1] : -1;

    bool constant = data & PB_HID_CONSTANT, variable = data & PB_HID_VARIABLE;
    uint32_t slots = constant ? 1 : g->report_count;
    uint32_t slot_bits = constant ? (uint32_t)total : g->report_size;
    uint32_t pool_start = (uint32_t)p->pool_len;
    if (!constant && !variable) {
        for (size_t k = 0; k < p->usage_count; k++) {
            if (pool_push(p, resolve(p, p->usages[k].first, p->usages[k].extended)) != 0 ||
                pool_push(p, resolve(p, p->usages[k].last, p->usages[k].extended)) != 0)
                return -1;
        }
    }
    for (uint32_t i = 0; i < slots; i++) {
        pb_hid_field *f = new_field(p);
        if (!f)
            return -1;
        f->kind = (uint8_t)kind;
        f->report_id = (uint8_t)rid;
        f->flags = (uint16_t)data;
        f->bit_offset = *bits + i * slot_bits;
        f->bit_size = slot_bits;
        f->logical_min = (int32_t)g->logical_min;
        f->logical_max = (int32_t)lmax;
        f->physical_min = (int32_t)g->physical_min;
        f->physical_max = (int32_t)pmax;
        f->unit = g->unit;
        f->unit_exponent = (int8_t)g->unit_exponent;
        f->is_signed = is_signed;
        f->collection = parent;
        if (constant) {
            f->usage = f->usage_last = p->usage_count ? nth_usage(p, 0) : 0;
        } else if (variable) {
            f->usage = f->usage_last = nth_usage(p, i);
        } else {
            f->array_index = i;
            f->usage_count = (uint32_t)(p->pool_len - pool_start) / 2;
            /* The pool may still move (realloc): usages is set once parsing ends. */
            f->usage_pool_index = pool_start;
            f->usage = p->usage_count ? resolve(p, p->usages[0].first, p->usages[0].extended) : 0;
            f->usage_last = p->usage_count ? resolve(p, p->usages[p->usage_count - 1].last,
                                                     p->usages[p->usage_count - 1].extended)
                                           : 0;
        }
        set_scaling(f);
    }
    *bits += (uint32_t)total;
    clear_locals(p);
    return 0;
}

static int main_item(parser *p, uint32_t tag, uint32_t data)
{
    switch (tag) {
    case MAIN_INPUT:
    case MAIN_OUTPUT:
    case MAIN_FEATURE:
        return main_data(p, tag, data);
    case MAIN_COLLECTION: {
        pb_hid_desc *d = p->d;
        if (p->open_depth >= PB_HID_MAX_DEPTH)
            return fail(p, "collections nested deeper than %d", PB_HID_MAX_DEPTH);
        if (d->collection_count >= PB_HID_MAX_COLLECTIONS)
            return fail(p, "more than %d collections", PB_HID_MAX_COLLECTIONS);
        pb_hid_collection *n = realloc(d->collections, (d->collection_count + 1) * sizeof *n);
        if (!n)
            return fail(p, "out of memory");
        d->collections = n;
        pb_hid_collection *c = &n[d->collection_count];
        c->usage = p->usage_count ? resolve(p, p->usages[0].first, p->usages[0].extended) : 0;
        c->type = (uint8_t)data;
        c->parent = p->open_depth ? p->open[p->open_depth - 1] : -1;
        p->open[p->open_depth++] = (int32_t)d->collection_count++;
        clear_locals(p);
        return 0;
    }
    case MAIN_END_COLLECTION:
        if (p->open_depth == 0)
            return fail(p, "End Collection without an open collection");
        p->open_depth--;
        clear_locals(p);
        return 0;
    default:
        /* hid_parser_main: "unknown main item tag", then the locals are reset as for any main item. */
        warn_at(p, "main item with reserved tag 0x%x (prefix 0x%02x) skipped, as the Linux kernel does", tag,
                p->byte);
        clear_locals(p);
        return 0;
    }
}

static int global_item(parser *p, uint32_t tag, uint32_t u, int32_t s)
{
    globals *g = &p->g;
    switch (tag) {
    case G_USAGE_PAGE:
        g->usage_page = u & 0xFFFF;
        break;
    case G_LOGICAL_MIN:
        g->logical_min = s;
        break;
    case G_LOGICAL_MAX:
        g->logical_max_s = s;
        g->logical_max_u = u;
        break;
    case G_PHYSICAL_MIN:
        g->physical_min = s;
        break;
    case G_PHYSICAL_MAX:
        g->physical_max_s = s;
        g->physical_max_u = u;
        break;
    case G_UNIT_EXPONENT:
        /* Spec: a 4-bit two's-complement nibble; devices also send a signed byte (kernel reading). */
        g->unit_exponent = u <= 0xF ? (int32_t)(u >= 8 ? (int32_t)u - 16 : (int32_t)u) : s;
        if (g->unit_exponent < -38 || g->unit_exponent > 38) {
            /* The kernel keeps any exponent (it only scales resolutions); 10^e beyond a
             * double's reach would make every physical value 0 or infinite here. */
            warn_at(p, "unit exponent %d out of -38..38 taken as 0 (the Linux kernel accepts it)", g->unit_exponent);
            g->unit_exponent = 0;
        }
        break;
    case G_UNIT:
        g->unit = u;
        break;
    case G_REPORT_SIZE:
        if (u > 256)
            return fail(p, "report size %u bits is larger than 256", u);
        g->report_size = u;
        break;
    case G_REPORT_ID:
        if (u == 0 || u > 255)
            return fail(p, "report ID %u is outside 1..255", u);
        if (p->seen_data_without_id)
            return fail(p, "report ID declared after fields without one");
        g->report_id = u;
        p->d->uses_report_ids = true;
        break;
    case G_REPORT_COUNT:
        if (u > KERNEL_MAX_REPORT_COUNT)
            return fail(p, "report count %u too large (the Linux kernel allows %d)", u, KERNEL_MAX_REPORT_COUNT);
        g->report_count = u;
        break;
    case G_PUSH:
        if (p->stack_depth >= PB_HID_MAX_DEPTH)
            return fail(p, "Push deeper than %d", PB_HID_MAX_DEPTH);
        p->stack[p->stack_depth++] = *g;
        break;
    case G_POP:
        if (p->stack_depth == 0)
            return fail(p, "Pop without a matching Push");
        *g = p->stack[--p->stack_depth];
        break;
    default:
        /* hid_parser_global: "unknown global tag", and the descriptor is refused. */
        return fail(p, "reserved global item tag 0x%x (the Linux kernel refuses it)", tag);
    }
    return 0;
}

static int local_item(parser *p, uint32_t tag, uint32_t u, size_t size)
{
    bool extended = size == 4;
    switch (tag) {
    case L_USAGE:
        return add_usage(p, u, u, extended);
    case L_USAGE_MIN:
        p->have_min = true;
        p->pending_min = u;
        p->pending_min_extended = extended;
        return 0;
    case L_USAGE_MAX: {
        if (!p->have_min)
            return fail(p, "Usage Maximum without Usage Minimum");
        p->have_min = false;
        uint32_t first = p->pending_min, last = u;
        if (p->pending_min_extended && !extended)
            last = (first & 0xFFFF0000u) | (u & 0xFFFF); /* the range keeps the minimum's page */
        else if (!p->pending_min_extended && extended)
            first = (last & 0xFFFF0000u) | (first & 0xFFFF);
        bool ext = p->pending_min_extended || extended;
        if (last < first)
            return fail(p, "Usage Maximum 0x%x below Usage Minimum 0x%x", last, first);
        if ((first >> 16) != (last >> 16) && ext)
            return fail(p, "usage range spans usage pages");
        return add_usage(p, first, last, ext);
    }
    case L_DELIMITER:
        if (u == 1) {
            if (p->delimiter_depth > 0)
                return fail(p, "nested delimiter");
            p->delimiter_depth = 1;
            p->delimiter_taken = false;
        } else if (u == 0) {
            if (p->delimiter_depth == 0)
                return fail(p, "delimiter close without open");
            p->delimiter_depth = 0;
        } else {
            return fail(p, "delimiter value %u", u);
        }
        return 0;
    case 0x3: case 0x4: case 0x5: case 0x7: case 0x8: case 0x9:
        return 0; /* designators and strings: no effect on the report layout */
    default:
        /* hid_parser_local ignores unknown local tags. */
        warn_at(p, "local item with reserved tag 0x%x (prefix 0x%02x) skipped, as the Linux kernel does", tag,
                p->byte);
        return 0;
    }
}

/* Channels: decodable, non-constant input fields, grouped by report ID. */
static int build_channels(parser *p)
{
    pb_hid_desc *d = p->d;
    size_t n = 0;
    for (size_t i = 0; i < d->field_count; i++) {
        const pb_hid_field *f = &d->fields[i];
        if (f->kind == PB_HID_INPUT && !(f->flags & PB_HID_CONSTANT) && f->bit_size >= 1 && f->bit_size <= 32)
            n++;
    }
    d->channels = calloc(n ? n : 1, sizeof *d->channels);
    d->channel_field = calloc(n ? n : 1, sizeof *d->channel_field);
    if (!d->channels || !d->channel_field)
        return fail(p, "out of memory");
    /* Counting sort by report ID keeps each report's channels contiguous and in bit order. */
    uint32_t count[256] = {0};
    for (size_t i = 0; i < d->field_count; i++) {
        const pb_hid_field *f = &d->fields[i];
        if (f->kind == PB_HID_INPUT && !(f->flags & PB_HID_CONSTANT) && f->bit_size >= 1 && f->bit_size <= 32)
            count[f->report_id]++;
    }
    uint32_t start = 0;
    for (int r = 0; r < 256; r++) {
        d->report_first[r] = start;
        d->report_count[r] = count[r];
        start += count[r];
        count[r] = 0;
    }
    for (size_t i = 0; i < d->field_count; i++) {
        const pb_hid_field *f = &d->fields[i];
        if (!(f->kind == PB_HID_INPUT && !(f->flags & PB_HID_CONSTANT) && f->bit_size >= 1 && f->bit_size <= 32))
            continue;
        uint32_t c = d->report_first[f->report_id] + count[f->report_id]++;
        d->channel_field[c] = (uint32_t)i;
    }
    d->channel_count = n;
    /* Names: "<Page>.<Usage>", arrays "<Page>.array"; repeats get "#k" (k counts from 1). */
    for (size_t c = 0; c < n; c++) {
        const pb_hid_field *f = &d->fields[d->channel_field[c]];
        pb_channel *ch = &d->channels[c];
        char base[48];
        if (f->flags & PB_HID_VARIABLE) {
            pb_hid_usage_name(f->usage, base, sizeof base);
        } else {
            char page[32];
            pb_hid_usage_name(f->usage & 0xFFFF0000u, page, sizeof page);
            char *dot = strchr(page, '.');
            if (dot)
                *dot = '\0';
            snprintf(base, sizeof base, "%s.array", page);
        }
        unsigned repeat = 0;
        for (size_t k = 0; k < c; k++) {
            const pb_hid_field *o = &d->fields[d->channel_field[k]];
            if ((o->flags & PB_HID_VARIABLE) == (f->flags & PB_HID_VARIABLE) &&
                ((f->flags & PB_HID_VARIABLE) ? o->usage == f->usage : (o->usage >> 16) == (f->usage >> 16)))
                repeat++;
        }
        if (repeat)
            snprintf(ch->name, sizeof ch->name, "%s#%u", base, repeat);
        else
            snprintf(ch->name, sizeof ch->name, "%s", base);
        ch->usage = f->usage;
        if (f->flags & PB_HID_VARIABLE) {
            snprintf(ch->unit, sizeof ch->unit, "%s", f->unit_name);
            double a = f->logical_min * f->scale + f->offset, b = f->logical_max * f->scale + f->offset;
            ch->min = a < b ? a : b;
            ch->max = a < b ? b : a;
        } else {
            ch->unit[0] = '\0'; /* arrays deliver the selected usage ID */
            ch->min = 1.0;
            ch->max = 0.0;
        }
    }
    return 0;
}

pose_status pb_hid_desc_parse(const uint8_t *bytes, size_t len, const char *origin, pb_hid_desc **out,
                              pb_error *err)
{
    *out = NULL;
    if (!origin)
        origin = "HID device";
    parser *p = calloc(1, sizeof *p);
    if (!p)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "%s: report descriptor: out of memory", origin);
    p->origin = origin;
    p->err = err;
    p->d = calloc(1, sizeof *p->d);
    pose_status rc = POSE_ERR_FORMAT;
    if (!p->d) {
        fail(p, "out of memory");
        goto done;
    }
    if (len == 0) {
        fail(p, "empty descriptor");
        goto done;
    }
    if (len > PB_HID_MAX_DESC_BYTES) {
        fail(p, "descriptor of %zu bytes exceeds %d", len, PB_HID_MAX_DESC_BYTES);
        goto done;
    }
    p->len = len;
    while (p->pos < len) {
        uint8_t prefix = bytes[p->pos];
        p->byte = prefix;
        if ((prefix >> 4) == LONG_ITEM_TAG) {
            /* Long items have no defined tags; the kernel refuses them in hid_open_report. */
            fail(p, "long item (prefix 0x%02x): the Linux kernel refuses long items", prefix);
            goto done;
        }
        if (prefix == 0x00) {
            /* Zero padding at the end (seen on real devices): each 0x00 is a Main item with
             * the reserved tag 0, which the kernel warns about and skips; hid-tools skips one
             * trailing 0x00. One warning for the run. */
            size_t z = p->pos;
            while (z < len && bytes[z] == 0x00)
                z++;
            if (z == len) {
                warn_at(p, "%zu trailing 0x00 byte%s after the last item skipped, as the Linux kernel does",
                        len - p->pos, len - p->pos == 1 ? "" : "s");
                clear_locals(p);
                p->pos = len;
                break;
            }
        }
        size_t size = prefix & 3;
        if (size == 3)
            size = 4;
        uint32_t type = (prefix >> 2) & 3, tag = prefix >> 4;
        if (p->pos + 1 + size > len) {
            fail(p, "item 0x%02x needs %zu data bytes, %zu left", prefix, size, len - p->pos - 1);
            goto done;
        }
        const uint8_t *b = bytes + p->pos + 1;
        uint32_t u = 0;
        for (size_t i = 0; i < size; i++)
            u |= (uint32_t)b[i] << (8 * i);
        /* Sign extension by data size: 8, 16 or 32 bits. */
        int32_t s = size == 1 ? (int32_t)(int8_t)u : size == 2 ? (int32_t)(int16_t)u : (int32_t)u;
        int r = 0;
        switch (type) {
        case TYPE_MAIN:
            r = main_item(p, tag, u);
            break;
        case TYPE_GLOBAL:
            r = global_item(p, tag, u, s);
            break;
        case TYPE_LOCAL:
            r = local_item(p, tag, u, size);
            break;
        default:
            /* hid_parser_reserved: skipped. */
            warn_at(p, "item of reserved type 3 (prefix 0x%02x) skipped, as the Linux kernel does", prefix);
            break;
        }
        if (r != 0)
            goto done;
        p->pos += 1 + size;
    }
    if (p->open_depth != 0) {
        fail(p, "%d collection(s) not closed at the end", p->open_depth);
        goto done;
    }
    if (p->delimiter_depth != 0) {
        fail(p, "delimiter not closed at the end");
        goto done;
    }
    for (size_t i = 0; i < p->d->field_count; i++) {
        pb_hid_field *f = &p->d->fields[i];
        f->usages = f->usage_count ? p->d->usage_pool + f->usage_pool_index : NULL;
    }
    for (int r = 0; r < 256; r++) {
        p->d->input_bytes[r] = (uint16_t)((p->bits[PB_HID_INPUT][r] + 7) / 8);
        p->d->output_bytes[r] = (uint16_t)((p->bits[PB_HID_OUTPUT][r] + 7) / 8);
        p->d->feature_bytes[r] = (uint16_t)((p->bits[PB_HID_FEATURE][r] + 7) / 8);
    }
    if (build_channels(p) != 0)
        goto done;
    *out = p->d;
    p->d = NULL;
    p->status = POSE_OK;
done:
    rc = p->status;
    pb_hid_desc_free(p->d);
    free(p);
    return rc;
}

void pb_hid_desc_free(pb_hid_desc *d)
{
    if (!d)
        return;
    free(d->fields);
    free(d->collections);
    free(d->channels);
    free(d->channel_field);
    free(d->usage_pool);
    free(d);
}

size_t pb_hid_desc_input_length(const pb_hid_desc *d, uint8_t report_id)
{
    if (d->uses_report_ids)
        return report_id && d->input_bytes[report_id] ? (size_t)d->input_bytes[report_id] + 1 : 0;
    return report_id == 0 ? d->input_bytes[0] : 0;
}

typedef struct named {
    uint16_t id;
    const char *name;
} named;

static const named pages[] = {
    {0x01, "GenericDesktop"}, {0x02, "Simulation"}, {0x03, "VR"}, {0x04, "Sport"},
    {0x05, "Game"}, {0x06, "GenericDevice"}, {0x07, "Keyboard"}, {0x08, "LED"},
    {0x09, "Button"}, {0x0A, "Ordinal"}, {0x0B, "Telephony"}, {0x0C, "Consumer"},
    {0x0D, "Digitizer"}, {0x0F, "PID"}, {0x20, "Sensor"}, {0x40, "Medical"},
};

static const named desktop[] = {
    {0x01, "Pointer"}, {0x02, "Mouse"}, {0x04, "Joystick"}, {0x05, "Gamepad"}, {0x06, "Keyboard"},
    {0x07, "Keypad"}, {0x08, "MultiAxisController"}, {0x30, "X"}, {0x31, "Y"}, {0x32, "Z"},
    {0x33, "Rx"}, {0x34, "Ry"}, {0x35, "Rz"}, {0x36, "Slider"}, {0x37, "Dial"}, {0x38, "Wheel"},
    {0x39, "HatSwitch"}, {0x3B, "ByteCount"}, {0x40, "Vx"}, {0x41, "Vy"}, {0x42, "Vz"},
};

static const char *lookup(const named *t, size_t n, uint32_t id)
{
    for (size_t i = 0; i < n; i++)
        if (t[i].id == id)
            return t[i].name;
    return NULL;
}

const char *pb_hid_usage_name(uint32_t usage, char *buf, size_t size)
{
    uint32_t page = usage >> 16, id = usage & 0xFFFF;
    char pbuf[16];
    const char *pn = lookup(pages, sizeof pages / sizeof pages[0], page);
    if (!pn) {
        snprintf(pbuf, sizeof pbuf, page >= 0xFF00 ? "Vendor0x%04X" : "Page0x%04X", page);
        pn = pbuf;
    }
    const char *un = page == 0x01 ? lookup(desktop, sizeof desktop / sizeof desktop[0], id) : NULL;
    if (un)
        snprintf(buf, size, "%s.%s", pn, un);
    else if (page == 0x09 || page == 0x0A)
        snprintf(buf, size, "%s.%u", pn, id); /* buttons and ordinals are numbers */
    else
        snprintf(buf, size, "%s.0x%02X", pn, id);
    return buf;
}
