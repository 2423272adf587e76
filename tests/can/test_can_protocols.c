/* SPDX-License-Identifier: Apache-2.0
 * CANopen CiA 406 / 410 and J1939 slope sensors, alone and through the bus
 * decoder: hand-computed frames, heartbeat monitoring and NMT states,
 * routing and kernel filters. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "can_bus.h"
#include "canopen_decode.h"
#include "j1939_slope.h"

static void test_canopen_decoders(void **state)
{
    (void)state;
    double a, lon, lat;
    /* 406: position 1024 of 4096 steps = 90 deg; bytes little-endian 00 04 00 00 */
    const uint8_t p90[4] = {0x00, 0x04, 0x00, 0x00};
    assert_true(pb_canopen_406_angle(p90, 4, 4096, &a));
    assert_true(a == 90.0);
    /* 3072 = 270 deg wraps to -90; a multi-turn count 5 * 4096 + 3072 too */
    const uint8_t p270[4] = {0x00, 0x0C, 0x00, 0x00};
    assert_true(pb_canopen_406_angle(p270, 4, 4096, &a));
    assert_true(a == -90.0);
    const uint32_t multi = 5 * 4096 + 3072; /* 0x5C00 */
    const uint8_t pm[4] = {(uint8_t)multi, (uint8_t)(multi >> 8), 0, 0};
    assert_true(pb_canopen_406_angle(pm, 4, 4096, &a));
    assert_true(a == -90.0);
    assert_false(pb_canopen_406_angle(p90, 3, 4096, &a)); /* short */
    assert_false(pb_canopen_406_angle(p90, 4, 0, &a));    /* no resolution */
    /* 410: -1234 = 0xFB2E -> 2E FB; 500 = 0x01F4 -> F4 01; 0.01 deg units */
    const uint8_t s[4] = {0x2E, 0xFB, 0xF4, 0x01};
    assert_int_equal(pb_canopen_410_slopes(s, 4, 0.01, &lon, &lat), 2);
    assert_true(fabs(lon - -12.34) < 1e-12 && fabs(lat - 5.0) < 1e-12);
    assert_int_equal(pb_canopen_410_slopes(s, 2, 0.01, &lon, &lat), 1);
    assert_string_equal(pb_canopen_nmt_name(0x05), "operational");
    assert_string_equal(pb_canopen_nmt_name(0x7f), "pre-operational");
    assert_string_equal(pb_canopen_nmt_name(0x42), "unknown");
}

static void test_j1939_decoder(void **state)
{
    (void)state;
    /* 0x0CF01390: priority 3, PF 0xF0, PS 0x13 -> PGN 0xF013 = 61459, source 0x90 */
    assert_int_equal(pb_j1939_pgn(0x0CF01390), 61459);
    assert_int_equal(pb_j1939_source(0x0CF01390), 0x90);
    assert_int_equal(pb_j1939_id(61459, 0x90, 3), 0x0CF01390);
    /* PDU1 (PF < 240): the PS byte is a destination, not part of the PGN */
    assert_int_equal(pb_j1939_pgn(0x18EA0080), 0xEA00);
    /* pitch 32000 * 0.002 - 64 = 0; roll 0x8000 = 32768 -> 1.536 deg */
    const uint8_t d[8] = {0x00, 0x7D, 0x00, 0x80, 0xFF, 0xFF, 0xFF, 0x00};
    double p = 1, r = 1;
    assert_int_equal(pb_j1939_ssi_decode(d, 8, &p, &r), 3);
    assert_true(fabs(p) < 1e-12);
    assert_true(fabs(r - 1.536) < 1e-12);
    /* 0xFExx error, 0xFFxx not available */
    const uint8_t na[4] = {0x00, 0xFE, 0xFF, 0xFF};
    assert_int_equal(pb_j1939_ssi_decode(na, 4, &p, &r), 0);
    assert_int_equal(pb_j1939_ssi_decode(d, 3, &p, &r), 1);
}

static pb_can_frame frame(int64_t t_ms, uint32_t id, int ext, const uint8_t *data, uint8_t len)
{
    pb_can_frame f;
    memset(&f, 0, sizeof f);
    f.t_ns = t_ms * 1000000;
    f.id = id;
    f.flags = ext ? PB_CAN_EXT : 0;
    f.len = len;
    memcpy(f.data, data, len);
    return f;
}

static void test_decoder_canopen_j1939(void **state)
{
    (void)state;
    const char *json = "{\"can\": {\"timeout_ms\": 50,"
                       " \"canopen\": [{\"node\": 33, \"name\": \"WRIST_L\", \"heartbeat_ms\": 100},"
                       "               {\"node\": 40, \"profile\": 410, \"name\": \"TRUNK\", \"resolution_deg\": 0.1}],"
                       " \"j1939\": [{\"address\": 144, \"name\": \"HEAD\", \"cycle_ms\": 10}]}}";
    pb_can_bus *bus = NULL;
    pb_error err;
    if (pb_can_bus_parse(json, strlen(json), "bus.json", NULL, &bus, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_can_decoder *dec = NULL;
    if (pb_can_decoder_create(pb_can_bus_config(bus), &dec, &err) != POSE_OK)
        fail_msg("%s", err.message);
    size_t n;
    const pb_channel *ch = pb_can_decoder_channels(dec, &n);
    assert_int_equal(n, 5);
    assert_string_equal(ch[0].name, "WRIST_L.angle");
    assert_string_equal(ch[1].name, "TRUNK.slope_long");
    assert_string_equal(ch[2].name, "TRUNK.slope_lat");
    assert_string_equal(ch[3].name, "HEAD.pitch");
    assert_string_equal(ch[4].name, "HEAD.roll");
    const pb_can_filter *flt = pb_can_decoder_filters(dec, &n);
    assert_int_equal(n, 5); /* 2 x (TPDO1, heartbeat) + the J1939 PGN */
    assert_int_equal(flt[0].id, 0x1A1);
    assert_int_equal(flt[1].id, 0x721);
    assert_int_equal(flt[4].id, 0x00F01390);
    assert_int_equal(flt[4].mask, 0x03FFFFFF);
    assert_true(flt[4].extended);

    pb_update u;
    pb_source_state st;
    char msg[256];
    const uint8_t hb_op[1] = {0x05}, boot[1] = {0x00};
    const uint8_t pos[4] = {0x00, 0x04, 0x00, 0x00};  /* 90 deg */
    const uint8_t slope[4] = {0x64, 0x00, 0x9C, 0xFF}; /* 100 -> 10.0 deg, -100 -> -10.0 deg */
    const uint8_t ssi[8] = {0x00, 0x7D, 0x00, 0x80, 0xFF, 0xFF, 0xFF, 0x00};
    assert_int_equal(pb_can_decoder_health(dec, &st, msg, sizeof msg), 1);
    assert_int_equal(st, PB_SOURCE_WAITING);
    pb_can_frame f = frame(0, 0x721, 0, hb_op, 1);
    assert_int_equal(pb_can_decoder_feed(dec, &f, &u), 0); /* heartbeats carry no channel */
    f = frame(1, 0x1A1, 0, pos, 4);
    assert_int_equal(pb_can_decoder_feed(dec, &f, &u), 1);
    assert_int_equal(u.channels[0], 0);
    assert_true(u.values[0] == 90.0);
    assert_true(u.t_ns == 1000000);
    f = frame(2, 0x1A8, 0, slope, 4);
    assert_int_equal(pb_can_decoder_feed(dec, &f, &u), 2);
    assert_true(fabs(u.values[0] - 10.0) < 1e-12 && fabs(u.values[1] - -10.0) < 1e-12);
    f = frame(3, 0x0CF01390, 1, ssi, 8);
    assert_int_equal(pb_can_decoder_feed(dec, &f, &u), 2);
    assert_int_equal(u.channels[1], 4);
    assert_true(fabs(u.values[1] - 1.536) < 1e-12);
    /* the same PGN from another address is not ours */
    f = frame(4, 0x0CF01391, 1, ssi, 8);
    assert_int_equal(pb_can_decoder_feed(dec, &f, &u), 0);
    assert_int_equal(pb_can_decoder_stats(dec)->unknown, 1);
    pb_can_decoder_health(dec, &st, msg, sizeof msg);
    assert_int_equal(st, PB_SOURCE_OK);

    /* keep TPDOs and J1939 flowing but stop WRIST_L's heartbeat: lost after 1.5 x 100 ms */
    for (int t = 10; t <= 140; t += 10) {
        f = frame(t, 0x1A1, 0, pos, 4);
        pb_can_decoder_feed(dec, &f, &u);
        f = frame(t, 0x1A8, 0, slope, 4);
        pb_can_decoder_feed(dec, &f, &u);
        f = frame(t, 0x0CF01390, 1, ssi, 8);
        pb_can_decoder_feed(dec, &f, &u);
    }
    pb_can_decoder_health(dec, &st, msg, sizeof msg);
    assert_int_equal(st, PB_SOURCE_OK);
    pb_can_decoder_tick(dec, 160000000);
    assert_int_equal(pb_can_decoder_health(dec, &st, msg, sizeof msg), 1);
    assert_int_equal(st, PB_SOURCE_STALE);
    assert_non_null(strstr(msg, "WRIST_L: heartbeat lost"));
    /* its PDOs alone do not bring it back */
    f = frame(162, 0x1A1, 0, pos, 4);
    assert_int_equal(pb_can_decoder_feed(dec, &f, &u), 1);
    assert_int_equal(pb_can_decoder_health(dec, &st, msg, sizeof msg), 0);
    assert_int_equal(st, PB_SOURCE_STALE);
    pb_can_node_info info;
    pb_can_decoder_node(dec, 0, &info);
    assert_int_equal(info.state, PB_CAN_NODE_SILENT);
    assert_int_equal(info.nmt, 0x05);
    assert_int_equal(info.timeout_ms, 150);
    /* the node reboots: boot-up is reported, then operational */
    f = frame(165, 0x721, 0, boot, 1);
    pb_can_decoder_feed(dec, &f, &u);
    assert_int_equal(pb_can_decoder_health(dec, &st, msg, sizeof msg), 1);
    assert_int_equal(st, PB_SOURCE_OK);
    assert_non_null(strstr(msg, "CANopen node 33 (WRIST_L): boot-up"));
    /* TRUNK and HEAD stopped at 140 ms: silent after their timeouts (3 x 10 ms, 50 ms) */
    pb_can_decoder_tick(dec, 175000000);
    pb_can_decoder_health(dec, &st, msg, sizeof msg);
    assert_int_equal(st, PB_SOURCE_STALE);
    assert_non_null(strstr(msg, "HEAD silent; 1 node(s)"));
    pb_can_decoder_tick(dec, 195000000);
    pb_can_decoder_health(dec, &st, msg, sizeof msg);
    assert_non_null(strstr(msg, "2 node(s) silent")); /* TRUNK, HEAD; WRIST_L spoke at 162 ms */
    f = frame(196, 0x1A8, 0, slope, 4);
    pb_can_decoder_feed(dec, &f, &u);
    f = frame(196, 0x0CF01390, 1, ssi, 8);
    pb_can_decoder_feed(dec, &f, &u);
    f = frame(197, 0x1A1, 0, pos, 4);
    pb_can_decoder_feed(dec, &f, &u);
    pb_can_decoder_health(dec, &st, msg, sizeof msg);
    assert_int_equal(st, PB_SOURCE_OK);
    f = frame(200, 0x721, 0, hb_op, 1);
    pb_can_decoder_feed(dec, &f, &u);
    assert_int_equal(pb_can_decoder_health(dec, &st, msg, sizeof msg), 1);
    assert_non_null(strstr(msg, "operational"));
    /* a short TPDO is counted and gives nothing */
    f = frame(201, 0x1A1, 0, pos, 2);
    assert_int_equal(pb_can_decoder_feed(dec, &f, &u), 0);
    assert_int_equal(pb_can_decoder_stats(dec)->short_frames, 1);
    /* a stamp from the past changes nothing */
    pb_can_decoder_tick(dec, 0);
    pb_can_decoder_health(dec, &st, msg, sizeof msg);
    assert_int_equal(st, PB_SOURCE_OK);
    assert_int_equal(pb_can_decoder_node_count(dec), 3);
    pb_can_decoder_free(dec);
    pb_can_bus_free(bus);
}

static void test_decoder_config_errors(void **state)
{
    (void)state;
    pb_can_decoder *dec = (pb_can_decoder *)1;
    pb_error err;
    assert_int_equal(pb_can_decoder_create(NULL, &dec, &err), POSE_ERR_INVALID_ARGUMENT);
    assert_null(dec);
    pb_canopen_node_config nodes[2] = {{.node = 5, .profile = 406}, {.node = 5, .profile = 406}};
    pb_can_config cfg = {.canopen = nodes, .canopen_count = 2};
    assert_int_equal(pb_can_decoder_create(&cfg, &dec, &err), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err.message, "twice"));
    nodes[1].node = 128;
    assert_int_equal(pb_can_decoder_create(&cfg, &dec, &err), POSE_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err.message, "128"));
    pb_j1939_sensor_config js[2] = {{.address = 7}, {.address = 7}};
    pb_can_config cj = {.j1939 = js, .j1939_count = 2};
    assert_int_equal(pb_can_decoder_create(&cj, &dec, &err), POSE_ERR_INVALID_ARGUMENT);
    /* default names */
    pb_can_config one = {.canopen = nodes, .canopen_count = 1, .j1939 = js, .j1939_count = 1};
    assert_int_equal(pb_can_decoder_create(&one, &dec, &err), POSE_OK);
    size_t n;
    const pb_channel *ch = pb_can_decoder_channels(dec, &n);
    assert_string_equal(ch[0].name, "node5.angle");
    assert_string_equal(ch[1].name, "sa07.pitch");
    pb_can_decoder_free(dec);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_decoder_config_errors),
        cmocka_unit_test(test_canopen_decoders),
        cmocka_unit_test(test_j1939_decoder),
        cmocka_unit_test(test_decoder_canopen_j1939),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
