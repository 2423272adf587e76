/* SPDX-License-Identifier: Apache-2.0 */
#include "usb_frame.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ the layout */

static int json_uint(const cJSON *v, uint64_t max, uint64_t *out)
{
    if (cJSON_IsNumber(v)) {
        double d = v->valuedouble;
        if (!(d >= 0 && d <= (double)max) || d != floor(d))
            return -1;
        *out = (uint64_t)d;
        return 0;
    }
    if (cJSON_IsString(v) && v->valuestring[0]) {
        char *end;
        errno = 0;
        unsigned long long u = strtoull(v->valuestring, &end, 0);
        if (errno || *end || u > max || v->valuestring[0] == '-')
            return -1;
        *out = u;
        return 0;
    }
    return -1;
}

static int json_endian(const cJSON *o, int *big)
{
    const cJSON *e = cJSON_GetObjectItemCaseSensitive(o, "endian");
    *big = 0;
    if (!e)
        return 0;
    if (!cJSON_IsString(e))
        return -1;
    if (!strcmp(e->valuestring, "little"))
        return 0;
    if (!strcmp(e->valuestring, "big")) {
        *big = 1;
        return 0;
    }
    return -1;
}

static pose_status get_uint(const cJSON *o, const char *key, uint64_t max, int required, uint64_t *out,
                            const char *name, const char *where, pb_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v)
        return required ? pb_fail(err, POSE_ERR_FORMAT, "%s: %s: \"%s\" is missing", name, where, key) : POSE_OK;
    if (json_uint(v, max, out) != 0)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: \"%s\" must be an integer from 0 to %llu", name, where, key,
                       (unsigned long long)max);
    return POSE_OK;
}

static pose_status parse_field(const cJSON *o, pb_usb_field *f, int allow_sign, const char *name, const char *where,
                               pb_error *err)
{
    uint64_t byte = 0, size = 1, shift = 0, bits = 0;
    pose_status s;
    if ((s = get_uint(o, "byte", PB_USB_MAX_FRAME - 1, 1, &byte, name, where, err)) < 0 ||
        (s = get_uint(o, "size", 8, 0, &size, name, where, err)) < 0 ||
        (s = get_uint(o, "shift", 63, 0, &shift, name, where, err)) < 0 ||
        (s = get_uint(o, "bits", 64, 0, &bits, name, where, err)) < 0)
        return s;
    int big;
    if (json_endian(o, &big) != 0)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: \"endian\" must be \"little\" or \"big\"", name, where);
    const cJSON *sg = cJSON_GetObjectItemCaseSensitive(o, "signed");
    if (sg && !cJSON_IsBool(sg))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: \"signed\" must be true or false", name, where);
    if (sg && cJSON_IsTrue(sg) && !allow_sign)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: a sequence counter is unsigned", name, where);
    *f = (pb_usb_field){(uint32_t)byte, (uint8_t)size, (uint8_t)big, (uint8_t)(sg && cJSON_IsTrue(sg)),
                        (uint8_t)shift, (uint8_t)(bits ? bits : size * 8)};
    return POSE_OK;
}

static pose_status check_field(const pb_usb_field *f, uint32_t frame_bytes, const char *name, const char *where,
                               pb_error *err)
{
    if (f->size != 1 && f->size != 2 && f->size != 4 && f->size != 8)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: size %u is not 1, 2, 4 or 8 bytes", name, where, f->size);
    if ((uint64_t)f->byte + f->size > frame_bytes)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: bytes %u..%u lie past the frame's %u bytes", name, where,
                       f->byte, f->byte + f->size - 1, frame_bytes);
    if (f->bits == 0 || f->bits > 64 || (unsigned)f->shift + f->bits > 8u * f->size)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: shift %u + bits %u do not fit in %u bytes", name, where,
                       f->shift, f->bits, f->size);
    return POSE_OK;
}

pose_status pb_usb_layout_check(const pb_usb_layout *l, const char *name, pb_error *err)
{
    pose_status s;
    char where[96];
    if (l->frame_bytes == 0 || l->frame_bytes > PB_USB_MAX_FRAME)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: usb.frame_bytes %u is not within 1..%d", name, l->frame_bytes,
                       PB_USB_MAX_FRAME);
    if (l->channel_count == 0 || l->channel_count > PB_USB_MAX_CHANNELS)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: usb.channels: %zu channels (1..%d)", name, l->channel_count,
                       PB_USB_MAX_CHANNELS);
    if (l->has_sequence && (s = check_field(&l->sequence, l->frame_bytes, name, "usb.sequence", err)) < 0)
        return s;
    if (l->checksum != PB_USB_CHECKSUM_NONE) {
        uint32_t w = l->checksum == PB_USB_CHECKSUM_CRC16_CCITT ? 2 : 1;
        if ((uint64_t)l->checksum_byte + w > l->frame_bytes || l->checksum_from >= l->checksum_to ||
            l->checksum_to > l->frame_bytes)
            return pb_fail(err, POSE_ERR_FORMAT,
                           "%s: usb.checksum: stored at byte %u (%u bytes) over [%u, %u) does not fit the %u-byte frame",
                           name, l->checksum_byte, w, l->checksum_from, l->checksum_to, l->frame_bytes);
    }
    for (size_t i = 0; i < l->channel_count; i++) {
        snprintf(where, sizeof where, "usb.channels[%zu] (%.40s)", i, l->channels[i].name);
        if (!l->channels[i].name[0])
            return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: no name", name, where);
        if ((s = check_field(&l->channels[i].field, l->frame_bytes, name, where, err)) < 0)
            return s;
        if (!isfinite(l->channels[i].scale) || !isfinite(l->channels[i].offset) || l->channels[i].scale == 0)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: scale must be finite and not 0, offset finite", name, where);
        for (size_t k = 0; k < i; k++)
            if (!strcmp(l->channels[k].name, l->channels[i].name))
                return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: the name is given twice (also usb.channels[%zu])", name,
                               where, k);
    }
    return POSE_OK;
}

static pose_status parse_usb(const cJSON *usb, const char *name, pb_usb_layout *l, pb_error *err)
{
    pose_status s;
    uint64_t u;
    memset(l, 0, sizeof *l);
    l->endpoint = 0x81;
    if (!cJSON_IsObject(usb))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: \"usb\" must be an object", name);
    if ((s = get_uint(usb, "vid", 0xFFFF, 0, &u, name, "usb", err)) < 0)
        return s;
    l->vid = (uint16_t)u;
    u = 0;
    if ((s = get_uint(usb, "pid", 0xFFFF, 0, &u, name, "usb", err)) < 0)
        return s;
    l->pid = (uint16_t)u;
    const cJSON *serial = cJSON_GetObjectItemCaseSensitive(usb, "serial");
    if (serial) {
        if (!cJSON_IsString(serial) || strlen(serial->valuestring) >= sizeof l->serial)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: usb: \"serial\" must be a string under %zu bytes", name,
                           sizeof l->serial);
        snprintf(l->serial, sizeof l->serial, "%s", serial->valuestring);
    }
    u = 0;
    if ((s = get_uint(usb, "interface", 255, 0, &u, name, "usb", err)) < 0)
        return s;
    l->interface = (int)u;
    u = 0x81;
    if ((s = get_uint(usb, "endpoint", 0xFF, 0, &u, name, "usb", err)) < 0)
        return s;
    if (!(u & 0x80) || (u & 0x70) || (u & 0x0F) == 0)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: usb: \"endpoint\" 0x%02llx is not an IN endpoint (0x81..0x8F)", name,
                       (unsigned long long)u);
    l->endpoint = (uint8_t)u;
    const cJSON *tr = cJSON_GetObjectItemCaseSensitive(usb, "transfer");
    if (tr) {
        if (!cJSON_IsString(tr) || (strcmp(tr->valuestring, "interrupt") && strcmp(tr->valuestring, "bulk")))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: usb: \"transfer\" must be \"interrupt\" or \"bulk\"", name);
        l->bulk = !strcmp(tr->valuestring, "bulk");
    }
    const cJSON *det = cJSON_GetObjectItemCaseSensitive(usb, "detach_kernel_driver");
    if (det && !cJSON_IsBool(det))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: usb: \"detach_kernel_driver\" must be true or false", name);
    l->detach_kernel_driver = det && cJSON_IsTrue(det);
    const cJSON *hold = cJSON_GetObjectItemCaseSensitive(usb, "hold_channel");
    if (hold) {
        if (!cJSON_IsString(hold) || strlen(hold->valuestring) >= sizeof l->hold_channel)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: usb: \"hold_channel\" must be a channel name", name);
        snprintf(l->hold_channel, sizeof l->hold_channel, "%s", hold->valuestring);
    }
    u = 0;
    if ((s = get_uint(usb, "frame_bytes", PB_USB_MAX_FRAME, 1, &u, name, "usb", err)) < 0)
        return s;
    l->frame_bytes = (uint32_t)u;
    const cJSON *seq = cJSON_GetObjectItemCaseSensitive(usb, "sequence");
    if (seq) {
        if (!cJSON_IsObject(seq))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: usb.sequence must be an object", name);
        if ((s = parse_field(seq, &l->sequence, 0, name, "usb.sequence", err)) < 0)
            return s;
        l->has_sequence = 1;
    }
    const cJSON *ck = cJSON_GetObjectItemCaseSensitive(usb, "checksum");
    if (ck) {
        const cJSON *kind = cJSON_GetObjectItemCaseSensitive(ck, "kind");
        if (!cJSON_IsObject(ck) || !cJSON_IsString(kind))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: usb.checksum must be an object with a \"kind\"", name);
        if (!strcmp(kind->valuestring, "sum8"))
            l->checksum = PB_USB_CHECKSUM_SUM8;
        else if (!strcmp(kind->valuestring, "xor8"))
            l->checksum = PB_USB_CHECKSUM_XOR8;
        else if (!strcmp(kind->valuestring, "crc16-ccitt"))
            l->checksum = PB_USB_CHECKSUM_CRC16_CCITT;
        else
            return pb_fail(err, POSE_ERR_FORMAT,
                           "%s: usb.checksum: kind \"%.40s\" is not \"sum8\", \"xor8\" or \"crc16-ccitt\"", name,
                           kind->valuestring);
        uint64_t b = 0, from = 0, to = 0;
        if ((s = get_uint(ck, "byte", PB_USB_MAX_FRAME, 1, &b, name, "usb.checksum", err)) < 0 ||
            (s = get_uint(ck, "from", PB_USB_MAX_FRAME, 0, &from, name, "usb.checksum", err)) < 0)
            return s;
        to = b;
        if ((s = get_uint(ck, "to", PB_USB_MAX_FRAME, 0, &to, name, "usb.checksum", err)) < 0)
            return s;
        if (json_endian(ck, &l->checksum_big_endian) != 0)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: usb.checksum: \"endian\" must be \"little\" or \"big\"", name);
        l->checksum_byte = (uint32_t)b;
        l->checksum_from = (uint32_t)from;
        l->checksum_to = (uint32_t)to;
    }
    const cJSON *chs = cJSON_GetObjectItemCaseSensitive(usb, "channels");
    if (!cJSON_IsArray(chs))
        return pb_fail(err, POSE_ERR_FORMAT, "%s: usb.channels must be an array of channels", name);
    int n = cJSON_GetArraySize(chs);
    if (n <= 0 || n > PB_USB_MAX_CHANNELS)
        return pb_fail(err, POSE_ERR_FORMAT, "%s: usb.channels: %d channels (1..%d)", name, n, PB_USB_MAX_CHANNELS);
    int i = 0;
    const cJSON *c;
    cJSON_ArrayForEach(c, chs)
    {
        char where[48];
        snprintf(where, sizeof where, "usb.channels[%d]", i);
        pb_usb_channel *ch = &l->channels[i++];
        const cJSON *nm = cJSON_GetObjectItemCaseSensitive(c, "name");
        if (!cJSON_IsObject(c) || !cJSON_IsString(nm) || !nm->valuestring[0] ||
            strlen(nm->valuestring) >= sizeof ch->name)
            return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: needs a \"name\" of 1..%zu characters", name, where,
                           sizeof ch->name - 1);
        snprintf(ch->name, sizeof ch->name, "%s", nm->valuestring);
        if ((s = parse_field(c, &ch->field, 1, name, where, err)) < 0)
            return s;
        const cJSON *sc = cJSON_GetObjectItemCaseSensitive(c, "scale"), *of = cJSON_GetObjectItemCaseSensitive(c, "offset"),
                    *un = cJSON_GetObjectItemCaseSensitive(c, "unit");
        if ((sc && !cJSON_IsNumber(sc)) || (of && !cJSON_IsNumber(of)) || (un && !cJSON_IsString(un)))
            return pb_fail(err, POSE_ERR_FORMAT, "%s: %s: scale and offset are numbers, unit a string", name, where);
        ch->scale = sc ? sc->valuedouble : 1.0;
        ch->offset = of ? of->valuedouble : 0.0;
        snprintf(ch->unit, sizeof ch->unit, "%s", un ? un->valuestring : "");
    }
    l->channel_count = (size_t)n;
    return pb_usb_layout_check(l, name, err);
}

pose_status pb_usb_layout_parse(const char *json, size_t len, const char *name, pb_usb_layout *out, pb_error *err)
{
    cJSON *root = cJSON_ParseWithLength(json, len);
    if (!root) {
        const char *at = cJSON_GetErrorPtr();
        size_t off = at && at >= json && at <= json + len ? (size_t)(at - json) : 0;
        return pb_fail(err, POSE_ERR_FORMAT, "%s: offset %zu: not valid JSON", name, off);
    }
    const cJSON *usb = cJSON_GetObjectItemCaseSensitive(root, "usb");
    pose_status s;
    if (!usb && cJSON_IsObject(root) && cJSON_GetObjectItemCaseSensitive(root, "channels") &&
        !cJSON_GetObjectItemCaseSensitive(root, "frame_bytes"))
        s = pb_fail(err, POSE_ERR_FORMAT, "%s: no \"usb\" object describing the device's frame", name);
    else
        s = parse_usb(usb ? usb : root, name, out, err);
    cJSON_Delete(root);
    return s;
}

pose_status pb_usb_layout_load(const char *path, pb_usb_layout *out, pb_error *err)
{
    char *text;
    size_t n;
    pose_status st = pb_read_file(path, 16u << 20, &text, &n, err);
    if (st != POSE_OK)
        return st;
    st = pb_usb_layout_parse(text, n, path, out, err);
    free(text);
    return st;
}

void pb_usb_layout_channels(const pb_usb_layout *l, pb_channel *out)
{
    for (size_t i = 0; i < l->channel_count; i++) {
        memset(&out[i], 0, sizeof out[i]);
        snprintf(out[i].name, sizeof out[i].name, "%s", l->channels[i].name);
        snprintf(out[i].unit, sizeof out[i].unit, "%s", l->channels[i].unit);
        const pb_usb_field *f = &l->channels[i].field;
        double lo, hi;
        if (f->is_signed) {
            lo = -ldexp(1.0, f->bits - 1);
            hi = ldexp(1.0, f->bits - 1) - 1;
        } else {
            lo = 0;
            hi = ldexp(1.0, f->bits) - 1;
        }
        double a = lo * l->channels[i].scale + l->channels[i].offset, b = hi * l->channels[i].scale + l->channels[i].offset;
        out[i].min = a < b ? a : b;
        out[i].max = a < b ? b : a;
    }
}

/* ---------------------------------------------------------- fields, sums */

int64_t pb_usb_field_get(const pb_usb_field *f, const uint8_t *frame)
{
    uint64_t u = 0;
    const uint8_t *p = frame + f->byte;
    for (unsigned i = 0; i < f->size; i++)
        u |= (uint64_t)p[f->big_endian ? f->size - 1 - i : i] << (8 * i);
    u >>= f->shift;
    if (f->bits < 64)
        u &= (UINT64_C(1) << f->bits) - 1;
    if (f->is_signed && f->bits < 64 && (u >> (f->bits - 1) & 1))
        u |= ~((UINT64_C(1) << f->bits) - 1);
    return (int64_t)u;
}

void pb_usb_field_put(const pb_usb_field *f, uint8_t *frame, int64_t v)
{
    uint64_t mask = f->bits < 64 ? (UINT64_C(1) << f->bits) - 1 : ~UINT64_C(0);
    uint64_t cur = 0;
    uint8_t *p = frame + f->byte;
    for (unsigned i = 0; i < f->size; i++)
        cur |= (uint64_t)p[f->big_endian ? f->size - 1 - i : i] << (8 * i);
    cur &= ~(mask << f->shift);
    cur |= ((uint64_t)v & mask) << f->shift;
    for (unsigned i = 0; i < f->size; i++)
        p[f->big_endian ? f->size - 1 - i : i] = (uint8_t)(cur >> (8 * i));
}

uint32_t pb_usb_checksum(pb_usb_checksum_kind kind, const uint8_t *p, size_t n)
{
    uint32_t c = 0;
    switch (kind) {
    case PB_USB_CHECKSUM_SUM8:
        for (size_t i = 0; i < n; i++)
            c += p[i];
        return c & 0xFF;
    case PB_USB_CHECKSUM_XOR8:
        for (size_t i = 0; i < n; i++)
            c ^= p[i];
        return c;
    case PB_USB_CHECKSUM_CRC16_CCITT: {
        /* a nibble at a time: nib[k] is the CRC (poly 0x1021) of k shifted in from the top */
        static const uint16_t nib[16] = {0x0000, 0x1021, 0x2042, 0x3063, 0x4084, 0x50a5, 0x60c6, 0x70e7,
                                         0x8108, 0x9129, 0xa14a, 0xb16b, 0xc18c, 0xd1ad, 0xe1ce, 0xf1ef};
        c = 0xFFFF;
        for (size_t i = 0; i < n; i++) {
            c = ((c << 4) ^ nib[(c >> 12) ^ (p[i] >> 4)]) & 0xFFFF;
            c = ((c << 4) ^ nib[(c >> 12) ^ (p[i] & 0x0F)]) & 0xFFFF;
        }
        return c;
    }
    default:
        return 0;
    }
}

static pb_usb_field checksum_field(const pb_usb_layout *l)
{
    uint8_t w = l->checksum == PB_USB_CHECKSUM_CRC16_CCITT ? 2 : 1;
    return (pb_usb_field){l->checksum_byte, w, (uint8_t)l->checksum_big_endian, 0, 0, (uint8_t)(8 * w)};
}

void pb_usb_checksum_store(const pb_usb_layout *l, uint8_t *frame)
{
    if (l->checksum == PB_USB_CHECKSUM_NONE)
        return;
    pb_usb_field f = checksum_field(l);
    pb_usb_field_put(&f, frame,
                     pb_usb_checksum(l->checksum, frame + l->checksum_from, l->checksum_to - l->checksum_from));
}

/* --------------------------------------------------------- the decoder */

const char *pb_usb_status_name(pb_usb_status s)
{
    switch (s) {
    case PB_USB_XFER_OK: return "ok";
    case PB_USB_XFER_STALL: return "stall (endpoint halted)";
    case PB_USB_XFER_OVERFLOW: return "babble (device sent more than the transfer asked)";
    case PB_USB_XFER_NO_DEVICE: return "device gone";
    case PB_USB_XFER_ERROR: return "transfer error on the wire";
    case PB_USB_XFER_CANCELLED: return "cancelled";
    }
    return "?";
}

pb_usb_status pb_usb_status_from_errno(int st)
{
    switch (-st) {
    case 0: return PB_USB_XFER_OK;
    case EPIPE: return PB_USB_XFER_STALL;
    case EOVERFLOW: return PB_USB_XFER_OVERFLOW;
    case ENODEV: case ESHUTDOWN: return PB_USB_XFER_NO_DEVICE;
    case ENOENT: case ECONNRESET: return PB_USB_XFER_CANCELLED;
    case EREMOTEIO: return PB_USB_XFER_OK; /* short packet flagged by URB_SHORT_NOT_OK: the length tells */
    default: return PB_USB_XFER_ERROR;      /* EPROTO, EILSEQ, ETIME, ECOMM, ENOSR ... */
    }
}

const char *pb_usb_decode_result_string(pb_usb_decode_result r)
{
    switch (r) {
    case PB_USB_DECODE_OK: return "ok";
    case PB_USB_DECODE_SHORT: return "short transfer";
    case PB_USB_DECODE_LONG: return "transfer longer than the frame";
    case PB_USB_DECODE_CHECKSUM: return "checksum mismatch";
    case PB_USB_DECODE_REORDERED: return "sequence counter went back (late or repeated frame)";
    }
    return "?";
}

pose_status pb_usb_decoder_init(pb_usb_decoder *d, const pb_usb_layout *l, pb_error *err)
{
    memset(d, 0, sizeof *d);
    d->layout = l;
    size_t n = l->channel_count ? l->channel_count : 1;
    d->values = malloc(n * sizeof *d->values);
    d->raw = calloc(n, sizeof *d->raw);
    if (!d->values || !d->raw) {
        pb_usb_decoder_free(d);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "usb decoder: out of memory");
    }
    for (size_t i = 0; i < n; i++)
        d->values[i] = NAN;
    d->seq_modulus = l->has_sequence && l->sequence.bits < 64 ? UINT64_C(1) << l->sequence.bits : 0;
    return POSE_OK;
}

void pb_usb_decoder_free(pb_usb_decoder *d)
{
    free(d->values);
    free(d->raw);
    d->values = NULL;
    d->raw = NULL;
}

void pb_usb_decoder_resync(pb_usb_decoder *d)
{
    d->have_seq = 0;
}

void pb_usb_decoder_count_status(pb_usb_decoder *d, pb_usb_status s)
{
    switch (s) {
    case PB_USB_XFER_STALL: d->stats.stalls++; break;
    case PB_USB_XFER_OVERFLOW: d->stats.overflows++; break;
    case PB_USB_XFER_NO_DEVICE:
        if (!d->gone)
            d->stats.disconnects++;
        d->gone = 1;
        d->have_seq = 0;
        break;
    case PB_USB_XFER_ERROR: d->stats.wire_errors++; break;
    default: break;
    }
}

pb_usb_decode_result pb_usb_decode(pb_usb_decoder *d, const uint8_t *frame, size_t len, uint64_t *seq_out)
{
    const pb_usb_layout *l = d->layout;
    if (len < l->frame_bytes) {
        d->stats.short_frames++;
        return PB_USB_DECODE_SHORT;
    }
    if (len > l->frame_bytes) {
        d->stats.long_frames++;
        return PB_USB_DECODE_LONG;
    }
    if (l->checksum != PB_USB_CHECKSUM_NONE) {
        pb_usb_field f = checksum_field(l);
        uint32_t want = pb_usb_checksum(l->checksum, frame + l->checksum_from, l->checksum_to - l->checksum_from);
        if ((uint32_t)pb_usb_field_get(&f, frame) != want) {
            d->stats.bad_checksums++;
            return PB_USB_DECODE_CHECKSUM;
        }
    }
    if (l->has_sequence) {
        uint64_t seq = (uint64_t)pb_usb_field_get(&l->sequence, frame);
        if (seq_out)
            *seq_out = seq;
        if (d->have_seq) {
            uint64_t m = d->seq_modulus, delta = m ? (seq - d->last_seq) & (m - 1) : seq - d->last_seq;
            uint64_t half = m ? m / 2 : UINT64_C(1) << 63;
            if (delta == 0 || delta >= half) {
                /* went back: a late frame (counted lost when the counter skipped it) or a repeated one */
                uint64_t back = m ? m - delta : (uint64_t)0 - delta;
                if (delta == 0)
                    back = 0;
                d->stats.reordered++;
                if (back < 64 && !(d->seen >> back & 1)) {
                    d->seen |= UINT64_C(1) << back;
                    if (d->stats.lost > 0)
                        d->stats.lost--;
                }
                return PB_USB_DECODE_REORDERED;
            }
            d->stats.lost += delta - 1;
            d->seen = delta >= 64 ? 1 : d->seen << delta | 1;
        } else {
            d->seen = 1;
        }
        d->have_seq = 1;
        d->last_seq = seq;
    }
    for (size_t i = 0; i < l->channel_count; i++) {
        const pb_usb_channel *c = &l->channels[i];
        int64_t r = pb_usb_field_get(&c->field, frame);
        d->raw[i] = r;
        d->values[i] = (double)r * c->scale + c->offset;
    }
    d->stats.frames++;
    d->gone = 0;
    return PB_USB_DECODE_OK;
}
