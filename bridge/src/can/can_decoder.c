/* SPDX-License-Identifier: Apache-2.0
 *
 * Frames are routed to "nodes" (a DBC message, a CANopen node, a J1939
 * sensor): standard identifiers through a 2048-entry table, extended ones
 * through the J1939 address table or the DBC index. Everything is sized at
 * creation, so feeding a frame never allocates.
 */
#include "can_decoder.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "canopen_decode.h"
#include "dbc_decode.h"
#include "j1939_slope.h"

enum node_kind { NODE_DBC, NODE_CANOPEN, NODE_J1939 };

/* Routes in the standard-id table: node index, with the CANopen heartbeat marked. */
#define ROUTE_NONE 0xffffu
#define ROUTE_HEARTBEAT 0x8000u

typedef struct can_node {
    enum node_kind kind;
    char name[64];
    uint32_t id;
    int64_t timeout_ns;
    int64_t hb_timeout_ns; /* CANopen with heartbeat; 0 otherwise */
    int64_t last_ns, last_hb_ns;
    uint64_t frames;
    pb_can_node_state state;
    int nmt;
    int short_reported;
    /* DBC: channel of each signal (-1: not delivered) */
    const pb_dbc_message *msg;
    int32_t *sig_channel;
    /* CANopen / J1939: channel of each value (-1: not delivered) */
    int32_t value_channel[2];
    const pb_canopen_node_config *co;
} can_node;

struct pb_can_decoder {
    pb_can_config cfg;
    can_node *nodes;
    size_t node_count;
    size_t *dbc_node; /* message index -> node index, SIZE_MAX when none */
    uint16_t std_route[2048];
    uint16_t j1939_route[256];
    pb_channel *channels;
    size_t channel_count;
    pb_can_filter *filters;
    size_t filter_count;
    /* per-feed scratch and output */
    double *sig_values;
    uint8_t *sig_presence;
    uint32_t *out_channels;
    double *out_values;
    size_t max_signals;
    /* health */
    pb_can_stats stats;
    int64_t first_ns; /* first frame seen, INT64_MIN before */
    int64_t now_ns;
    int64_t last_scan_ns;
    char notice[200];
    pb_source_state last_state;
    char last_message[256];
    int reported_once;
};

static void scan(pb_can_decoder *d, int64_t now, int force);

static int wanted(const pb_can_config *cfg, const char *name, unsigned char *used)
{
    if (!cfg->channels)
        return 1;
    for (size_t i = 0; i < cfg->channel_count; i++)
        if (cfg->channels[i] && strcmp(cfg->channels[i], name) == 0) {
            used[i] = 1;
            return 1;
        }
    return 0;
}

/* Truncating copy (names longer than the field are cut, not rejected). */
static void copy_str(char *dst, size_t size, const char *src)
{
    size_t n = strlen(src);
    if (n >= size)
        n = size - 1;
    memcpy(dst, src, n);
    dst[n] = '\0';
}

static int32_t add_channel(pb_can_decoder *d, const char *name, const char *unit, double lo, double hi)
{
    pb_channel *c = &d->channels[d->channel_count];
    memset(c, 0, sizeof *c);
    copy_str(c->name, sizeof c->name, name);
    copy_str(c->unit, sizeof c->unit, unit);
    /* DBC files write [0|0] for "no range": report the range as unknown then. */
    c->min = lo;
    c->max = hi;
    if (!(lo < hi)) {
        c->min = 1;
        c->max = 0;
    }
    return (int32_t)d->channel_count++;
}

static void add_filter(pb_can_decoder *d, uint32_t id, uint32_t mask, int ext)
{
    d->filters[d->filter_count].id = id;
    d->filters[d->filter_count].mask = mask;
    d->filters[d->filter_count].extended = (uint8_t)ext;
    d->filter_count++;
}

static int64_t ms_ns(uint32_t ms) { return (int64_t)ms * 1000000; }

pose_status pb_can_decoder_create(const pb_can_config *cfg, pb_can_decoder **out, pb_error *err)
{
    *out = NULL;
    if (!cfg)
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "CAN: no configuration");
    const pb_dbc *dbc = cfg->dbc;
    size_t max_nodes = cfg->canopen_count + cfg->j1939_count + (dbc ? dbc->message_count : 0);
    size_t max_channels = 2 * (cfg->canopen_count + cfg->j1939_count);
    size_t max_signals = 2;
    if (dbc)
        for (size_t i = 0; i < dbc->message_count; i++) {
            max_channels += dbc->messages[i].signal_count;
            if (dbc->messages[i].signal_count > max_signals)
                max_signals = dbc->messages[i].signal_count;
        }
    pb_can_decoder *d = calloc(1, sizeof *d);
    unsigned char *used = calloc(cfg->channel_count + 1, 1);
    if (!d || !used) {
        free(d);
        free(used);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "CAN: out of memory");
    }
    d->cfg = *cfg;
    d->nodes = calloc(max_nodes + 1, sizeof *d->nodes);
    d->dbc_node = calloc((dbc ? dbc->message_count : 0) + 1, sizeof *d->dbc_node);
    d->channels = calloc(max_channels + 1, sizeof *d->channels);
    d->filters = calloc(2 * max_nodes + 1, sizeof *d->filters);
    d->sig_values = calloc(max_signals, sizeof *d->sig_values);
    d->sig_presence = calloc(max_signals, 1);
    d->out_channels = calloc(max_signals, sizeof *d->out_channels);
    d->out_values = calloc(max_signals, sizeof *d->out_values);
    d->max_signals = max_signals;
    pose_status st = POSE_OK;
    if (!d->nodes || !d->dbc_node || !d->channels || !d->filters || !d->sig_values ||
        !d->sig_presence || !d->out_channels || !d->out_values) {
        st = pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "CAN: out of memory");
        goto fail;
    }
    for (size_t i = 0; i < 2048; i++)
        d->std_route[i] = ROUTE_NONE;
    for (size_t i = 0; i < 256; i++)
        d->j1939_route[i] = ROUTE_NONE;
    const uint32_t default_timeout = cfg->timeout_ms ? cfg->timeout_ms : 100;

    for (size_t i = 0; i < cfg->canopen_count; i++) {
        const pb_canopen_node_config *c = &cfg->canopen[i];
        if (c->node < 1 || c->node > 127) {
            st = pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "CAN: CANopen node id %u not in 1..127", c->node);
            goto fail;
        }
        if (c->profile != PB_CANOPEN_CIA406 && c->profile != PB_CANOPEN_CIA410) {
            st = pb_fail(err, POSE_ERR_UNSUPPORTED, "CAN: CANopen node %u: profile %u (406 or 410 expected)",
                         c->node, c->profile);
            goto fail;
        }
        if (d->std_route[PB_CANOPEN_TPDO1 + c->node] != ROUTE_NONE) {
            st = pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "CAN: CANopen node %u listed twice", c->node);
            goto fail;
        }
        can_node *n = &d->nodes[d->node_count];
        n->kind = NODE_CANOPEN;
        n->co = c;
        n->id = c->node;
        if (c->name)
            copy_str(n->name, sizeof n->name, c->name);
        else
            snprintf(n->name, sizeof n->name, "node%u", c->node);
        char ch[128];
        n->value_channel[0] = n->value_channel[1] = -1;
        if (c->profile == PB_CANOPEN_CIA406) {
            snprintf(ch, sizeof ch, "%s.angle", n->name);
            if (wanted(cfg, ch, used))
                n->value_channel[0] = add_channel(d, ch, "deg", -180, 180);
        } else {
            snprintf(ch, sizeof ch, "%s.slope_long", n->name);
            if (wanted(cfg, ch, used))
                n->value_channel[0] = add_channel(d, ch, "deg", -180, 180);
            snprintf(ch, sizeof ch, "%s.slope_lat", n->name);
            if (wanted(cfg, ch, used))
                n->value_channel[1] = add_channel(d, ch, "deg", -180, 180);
        }
        if (n->value_channel[0] < 0 && n->value_channel[1] < 0)
            continue; /* nothing wanted from this node: neither routed nor watched */
        n->timeout_ns = ms_ns(default_timeout);
        n->hb_timeout_ns = c->heartbeat_ms ? ms_ns(c->heartbeat_ms) * 3 / 2 : 0;
        d->std_route[PB_CANOPEN_TPDO1 + c->node] = (uint16_t)d->node_count;
        d->std_route[PB_CANOPEN_HEARTBEAT + c->node] = (uint16_t)(d->node_count | ROUTE_HEARTBEAT);
        add_filter(d, PB_CANOPEN_TPDO1 + c->node, 0x7ff, 0);
        add_filter(d, PB_CANOPEN_HEARTBEAT + c->node, 0x7ff, 0);
        d->node_count++;
    }
    for (size_t i = 0; i < cfg->j1939_count; i++) {
        const pb_j1939_sensor_config *c = &cfg->j1939[i];
        if (d->j1939_route[c->address] != ROUTE_NONE) {
            st = pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "CAN: J1939 address 0x%02x listed twice", c->address);
            goto fail;
        }
        can_node *n = &d->nodes[d->node_count];
        n->kind = NODE_J1939;
        n->id = c->address;
        if (c->name)
            copy_str(n->name, sizeof n->name, c->name);
        else
            snprintf(n->name, sizeof n->name, "sa%02X", c->address);
        char ch[128];
        snprintf(ch, sizeof ch, "%s.pitch", n->name);
        n->value_channel[0] = wanted(cfg, ch, used) ? add_channel(d, ch, "deg", -64, 64.51) : -1;
        snprintf(ch, sizeof ch, "%s.roll", n->name);
        n->value_channel[1] = wanted(cfg, ch, used) ? add_channel(d, ch, "deg", -64, 64.51) : -1;
        if (n->value_channel[0] < 0 && n->value_channel[1] < 0)
            continue;
        n->timeout_ns = c->cycle_ms ? ms_ns(c->cycle_ms) * 3 : ms_ns(default_timeout);
        d->j1939_route[c->address] = (uint16_t)d->node_count;
        /* any priority, this PGN from this address */
        add_filter(d, pb_j1939_id(PB_J1939_PGN_SSI, c->address, 0), 0x03ffffff, 1);
        d->node_count++;
    }
    if (dbc) {
        for (size_t i = 0; i < dbc->message_count; i++) {
            const pb_dbc_message *m = &dbc->messages[i];
            d->dbc_node[i] = SIZE_MAX;
            if (pb_dbc_find(dbc, m->id, m->extended) != m)
                continue; /* pseudo or repeated message */
            if (!m->extended && d->std_route[m->id & 0x7ff] != ROUTE_NONE)
                continue; /* a configured CANopen node owns this identifier */
            can_node *n = &d->nodes[d->node_count];
            n->sig_channel = malloc((m->signal_count ? m->signal_count : 1) * sizeof *n->sig_channel);
            if (!n->sig_channel) {
                st = pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "CAN: out of memory");
                goto fail;
            }
            int any = 0;
            for (size_t j = 0; j < m->signal_count; j++) {
                const pb_dbc_signal *s = &m->signals[j];
                char ch[160];
                snprintf(ch, sizeof ch, "%s.%s", m->name, s->name);
                n->sig_channel[j] = -1;
                if (strlen(ch) < sizeof d->channels[0].name && wanted(cfg, ch, used)) {
                    n->sig_channel[j] = add_channel(d, ch, s->unit, s->min, s->max);
                    any = 1;
                }
            }
            if (!any) {
                free(n->sig_channel);
                n->sig_channel = NULL;
                continue;
            }
            n->kind = NODE_DBC;
            n->msg = m;
            n->id = m->id;
            copy_str(n->name, sizeof n->name, m->name);
            n->timeout_ns = m->cycle_ms ? ms_ns(m->cycle_ms) * 3 : ms_ns(default_timeout);
            n->value_channel[0] = n->value_channel[1] = -1;
            d->dbc_node[i] = d->node_count;
            if (!m->extended)
                d->std_route[m->id] = (uint16_t)d->node_count;
            add_filter(d, m->id, m->extended ? 0x1fffffff : 0x7ff, m->extended);
            d->node_count++;
        }
    }
    for (size_t i = 0; i < cfg->channel_count; i++)
        if (!used[i]) {
            st = pb_fail(err, POSE_ERR_NOT_FOUND, "CAN: no channel named '%s' (DBC \"MESSAGE.SIGNAL\", "
                         "CANopen \"<name>.angle\", J1939 \"<name>.pitch\")",
                         cfg->channels[i] ? cfg->channels[i] : "(null)");
            goto fail;
        }
    free(used);
    pb_can_decoder_reset(d);
    d->last_state = PB_SOURCE_WAITING;
    *out = d;
    return POSE_OK;
fail:
    free(used);
    pb_can_decoder_free(d);
    return st;
}

void pb_can_decoder_free(pb_can_decoder *d)
{
    if (!d)
        return;
    if (d->nodes)
        for (size_t i = 0; i <= d->node_count; i++)
            free(d->nodes[i].sig_channel);
    free(d->nodes);
    free(d->dbc_node);
    free(d->channels);
    free(d->filters);
    free(d->sig_values);
    free(d->sig_presence);
    free(d->out_channels);
    free(d->out_values);
    free(d);
}

void pb_can_decoder_reset(pb_can_decoder *d)
{
    for (size_t i = 0; i < d->node_count; i++) {
        d->nodes[i].state = PB_CAN_NODE_NEVER;
        d->nodes[i].last_ns = d->nodes[i].last_hb_ns = INT64_MIN;
        d->nodes[i].nmt = -1;
        d->nodes[i].short_reported = 0;
    }
    d->first_ns = INT64_MIN;
    d->now_ns = INT64_MIN;
    d->last_scan_ns = INT64_MIN;
    d->stats.bus = PB_CAN_BUS_ACTIVE;
    d->notice[0] = '\0';
}

const pb_channel *pb_can_decoder_channels(const pb_can_decoder *d, size_t *count)
{
    *count = d->channel_count;
    return d->channels;
}

const pb_can_filter *pb_can_decoder_filters(const pb_can_decoder *d, size_t *count)
{
    *count = d->filter_count;
    return d->filters;
}

/* A data frame from n at t. A CANopen node whose heartbeat is overdue
 * stays silent: its PDOs alone would flip it back and forth every frame. */
static void touch(const pb_can_decoder *d, can_node *n, int64_t t)
{
    n->last_ns = t;
    n->frames++;
    const int64_t hb = n->last_hb_ns == INT64_MIN ? d->first_ns : n->last_hb_ns;
    if (!n->hb_timeout_ns || t - hb <= n->hb_timeout_ns)
        n->state = PB_CAN_NODE_ALIVE;
}

static size_t feed_dbc(pb_can_decoder *d, can_node *n, const pb_can_frame *f)
{
    const pb_dbc_message *m = n->msg;
    pb_dbc_decode(m, f->data, f->len, d->sig_values, NULL, d->sig_presence);
    size_t k = 0;
    int short_frame = f->len < m->size;
    for (size_t j = 0; j < m->signal_count; j++) {
        if (d->sig_presence[j] == PB_DBC_SHORT)
            short_frame = 1;
        if (n->sig_channel[j] < 0 || d->sig_presence[j] != PB_DBC_PRESENT)
            continue;
        d->out_channels[k] = (uint32_t)n->sig_channel[j];
        d->out_values[k] = d->sig_values[j];
        k++;
    }
    if (short_frame) {
        d->stats.short_frames++;
        if (!n->short_reported) { /* once per message: a broken sender repeats every cycle */
            n->short_reported = 1;
            snprintf(d->notice, sizeof d->notice,
                     "%s (0x%X): %u data bytes, DBC says %u; signals past the end hold", m->name,
                     (unsigned)m->id, f->len, m->size);
        }
    }
    return k;
}

static size_t feed_canopen(pb_can_decoder *d, can_node *n, const pb_can_frame *f, int heartbeat)
{
    if (heartbeat) {
        if (f->len < 1)
            return 0;
        const int state = f->data[0] & 0x7f;
        if (state != n->nmt && (n->nmt >= 0 || state != PB_CANOPEN_OPERATIONAL))
            snprintf(d->notice, sizeof d->notice, "CANopen node %u (%s): %s", (unsigned)n->id,
                     n->name, pb_canopen_nmt_name((unsigned)state));
        n->nmt = state;
        n->last_hb_ns = f->t_ns;
        return 0;
    }
    size_t k = 0;
    double v[2];
    int have[2] = {0, 0};
    if (n->co->profile == PB_CANOPEN_CIA406) {
        have[0] = pb_canopen_406_angle(f->data, f->len,
                                       n->co->steps_per_rev ? n->co->steps_per_rev : 4096, &v[0]);
        if (!have[0])
            d->stats.short_frames++;
    } else {
        int got = pb_canopen_410_slopes(f->data, f->len,
                                        n->co->resolution_deg > 0 ? n->co->resolution_deg : 0.01,
                                        &v[0], &v[1]);
        have[0] = got >= 1;
        have[1] = got >= 2;
        if (got < 2)
            d->stats.short_frames++;
    }
    for (int i = 0; i < 2; i++)
        if (have[i] && n->value_channel[i] >= 0) {
            d->out_channels[k] = (uint32_t)n->value_channel[i];
            d->out_values[k] = v[i];
            k++;
        }
    return k;
}

static size_t feed_j1939(pb_can_decoder *d, can_node *n, const pb_can_frame *f)
{
    double v[2];
    int ok = pb_j1939_ssi_decode(f->data, f->len, &v[0], &v[1]);
    if (f->len < 4)
        d->stats.short_frames++;
    size_t k = 0;
    for (int i = 0; i < 2; i++)
        if ((ok >> i & 1) && n->value_channel[i] >= 0) {
            d->out_channels[k] = (uint32_t)n->value_channel[i];
            d->out_values[k] = v[i];
            k++;
        }
    return k;
}

size_t pb_can_decoder_feed(pb_can_decoder *d, const pb_can_frame *f, pb_update *out)
{
    out->t_ns = f->t_ns;
    out->count = 0;
    out->channels = d->out_channels;
    out->values = d->out_values;
    d->stats.frames++;
    if (d->first_ns == INT64_MIN)
        d->first_ns = f->t_ns;
    if (f->flags & PB_CAN_ERR) {
        pb_can_error_info e;
        pb_can_error_decode(f, &e);
        d->stats.error_frames++;
        if (e.has_state)
            d->stats.bus = e.state;
        if (f->len >= 8) { /* the kernel's error frames carry the counters in bytes 6 and 7 */
            d->stats.tx_errors = e.tx_errors;
            d->stats.rx_errors = e.rx_errors;
        }
        if (e.rx_overflow)
            d->stats.dropped++;
        scan(d, f->t_ns, 0);
        return 0;
    }
    if (f->flags & PB_CAN_RTR) {
        d->stats.remote_frames++;
        scan(d, f->t_ns, 0);
        return 0;
    }
    /* Frames arriving prove the controller is back on the bus after bus-off
     * even when the driver sends no "restarted" error frame; a restarted
     * controller starts error-active with its counters cleared. */
    if (d->stats.bus == PB_CAN_BUS_OFF)
        d->stats.bus = PB_CAN_BUS_ACTIVE;
    can_node *n = NULL;
    int heartbeat = 0;
    if (!(f->flags & PB_CAN_EXT)) {
        uint16_t r = d->std_route[f->id & 0x7ff];
        if (r != ROUTE_NONE) {
            heartbeat = (r & ROUTE_HEARTBEAT) != 0;
            n = &d->nodes[r & ~ROUTE_HEARTBEAT];
        }
    } else {
        if (pb_j1939_pgn(f->id) == PB_J1939_PGN_SSI && d->j1939_route[f->id & 0xff] != ROUTE_NONE)
            n = &d->nodes[d->j1939_route[f->id & 0xff]];
        else if (d->cfg.dbc) {
            const pb_dbc_message *m = pb_dbc_find(d->cfg.dbc, f->id, 1);
            if (m && d->dbc_node[m - d->cfg.dbc->messages] != SIZE_MAX)
                n = &d->nodes[d->dbc_node[m - d->cfg.dbc->messages]];
        }
    }
    size_t k = 0;
    if (!n) {
        d->stats.unknown++;
    } else {
        switch (n->kind) {
        case NODE_DBC: k = feed_dbc(d, n, f); break;
        case NODE_CANOPEN: k = feed_canopen(d, n, f, heartbeat); break;
        case NODE_J1939: k = feed_j1939(d, n, f); break;
        }
        if (!heartbeat)
            touch(d, n, f->t_ns);
        else
            n->frames++;
        if (k)
            d->stats.decoded++;
    }
    scan(d, f->t_ns, 0);
    out->count = k;
    return k;
}

/* Silence checks. Frames call it with force 0: a node that speaks turns
 * alive in touch(), so scanning every node for timeouts once per
 * millisecond of bus time is enough, and keeps big DBCs cheap per frame. */
static void scan(pb_can_decoder *d, int64_t now, int force)
{
    if (now < d->now_ns)
        return; /* clocks only move forward; a reordered stamp changes nothing */
    d->now_ns = now;
    if (d->first_ns == INT64_MIN)
        return;
    if (!force && d->last_scan_ns != INT64_MIN && now - d->last_scan_ns < 1000000)
        return;
    d->last_scan_ns = now;
    for (size_t i = 0; i < d->node_count; i++) {
        can_node *n = &d->nodes[i];
        /* A node never heard counts from the bus's first frame. */
        const int64_t since = n->last_ns == INT64_MIN ? d->first_ns : n->last_ns;
        int silent = now - since > n->timeout_ns;
        if (n->hb_timeout_ns) {
            const int64_t hb = n->last_hb_ns == INT64_MIN ? d->first_ns : n->last_hb_ns;
            if (now - hb > n->hb_timeout_ns)
                silent = 1;
        }
        if (silent)
            n->state = PB_CAN_NODE_SILENT;
        else if (n->state == PB_CAN_NODE_SILENT)
            n->state = n->last_ns == INT64_MIN ? PB_CAN_NODE_NEVER : PB_CAN_NODE_ALIVE;
    }
}

void pb_can_decoder_tick(pb_can_decoder *d, int64_t now) { scan(d, now, 1); }

void pb_can_decoder_add_dropped(pb_can_decoder *d, uint64_t n)
{
    if (n) {
        d->stats.dropped += n;
        snprintf(d->notice, sizeof d->notice, "receiver dropped %llu frames (total %llu)",
                 (unsigned long long)n, (unsigned long long)d->stats.dropped);
    }
}

void pb_can_decoder_add_bad_lines(pb_can_decoder *d, uint64_t n, const char *what)
{
    d->stats.bad_lines += n;
    snprintf(d->notice, sizeof d->notice, "malformed log line: %s", what);
}

int pb_can_decoder_health(pb_can_decoder *d, pb_source_state *state, char *message, size_t size)
{
    pb_source_state s;
    char msg[256];
    msg[0] = '\0';
    size_t silent = 0, alive = 0;
    const can_node *first = NULL;
    for (size_t i = 0; i < d->node_count; i++) {
        if (d->nodes[i].state == PB_CAN_NODE_SILENT) {
            if (!silent++)
                first = &d->nodes[i];
        } else if (d->nodes[i].state == PB_CAN_NODE_ALIVE) {
            alive++;
        }
    }
    if (d->stats.bus == PB_CAN_BUS_OFF || d->stats.bus == PB_CAN_BUS_PASSIVE) {
        s = PB_SOURCE_FAULT;
        if (d->stats.tx_errors || d->stats.rx_errors)
            snprintf(msg, sizeof msg, "CAN controller %s (tx errors %u, rx errors %u)",
                     pb_can_bus_state_name(d->stats.bus), d->stats.tx_errors, d->stats.rx_errors);
        else
            snprintf(msg, sizeof msg, "CAN controller %s", pb_can_bus_state_name(d->stats.bus));
    } else if (silent) {
        s = PB_SOURCE_STALE;
        const int64_t hb = first->last_hb_ns == INT64_MIN ? d->first_ns : first->last_hb_ns;
        if (first->hb_timeout_ns && d->now_ns - hb > first->hb_timeout_ns)
            snprintf(msg, sizeof msg, "%s: heartbeat lost; %zu node(s) silent, values held",
                     first->name, silent);
        else
            snprintf(msg, sizeof msg, "%s silent; %zu node(s) silent, values held", first->name,
                     silent);
    } else if (!alive) {
        s = PB_SOURCE_WAITING;
        snprintf(msg, sizeof msg, "no data yet");
    } else {
        s = PB_SOURCE_OK;
        snprintf(msg, sizeof msg, "%s", d->notice);
    }
    int changed = !d->reported_once || s != d->last_state || strcmp(msg, d->last_message) != 0;
    d->reported_once = 1;
    d->last_state = s;
    snprintf(d->last_message, sizeof d->last_message, "%s", msg);
    *state = s;
    if (size)
        snprintf(message, size, "%s", msg);
    return changed;
}

const pb_can_stats *pb_can_decoder_stats(const pb_can_decoder *d) { return &d->stats; }

size_t pb_can_decoder_node_count(const pb_can_decoder *d) { return d->node_count; }

void pb_can_decoder_node(const pb_can_decoder *d, size_t i, pb_can_node_info *info)
{
    const can_node *n = &d->nodes[i];
    info->name = n->name;
    info->id = n->id;
    info->state = n->state;
    info->frames = n->frames;
    info->last_ns = n->last_ns;
    info->nmt = n->nmt;
    info->timeout_ms = (uint32_t)((n->hb_timeout_ns ? n->hb_timeout_ns : n->timeout_ns) / 1000000);
}
