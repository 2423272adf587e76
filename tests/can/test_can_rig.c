/* SPDX-License-Identifier: Apache-2.0
 * The reference goniometer rig (data/can-rig) replayed as a simulated bus:
 * every decoded channel matches the generator's ground truth to its
 * resolution, held values included; the faults in the log give the right
 * state transitions; the mapping drives the full-body and the bar rigs. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>

#include "can_mapping.h"
#include "can_source.h"
#include "mapping.h"
#include "rig_skel.h"

#define MAX_COLS 32
#define MAX_ROWS 256

typedef struct truth {
    int cols;
    char names[MAX_COLS][64];
    int rows;
    int64_t t_ns[MAX_ROWS];
    double v[MAX_ROWS][MAX_COLS];
    int has[MAX_ROWS][MAX_COLS];
} truth;

static void data_path(char *out, size_t size, const char *rel)
{
    snprintf(out, size, "%s/%s", getenv("POSE_DATA_DIR"), rel);
}

static void repo_path(char *out, size_t size, const char *rel)
{
    snprintf(out, size, "%s/../%s", getenv("POSE_DATA_DIR"), rel);
}

static void load_truth(truth *t)
{
    char path[1024], line[4096];
    data_path(path, sizeof path, "can-rig/sit_stand_arm_raise_truth.csv");
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    memset(t, 0, sizeof *t);
    assert_non_null(fgets(line, sizeof line, f));
    line[strcspn(line, "\r\n")] = '\0';
    char *save = NULL;
    for (char *tok = strtok_r(line, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (strcmp(tok, "t_s") == 0)
            continue;
        assert_true(t->cols < MAX_COLS);
        snprintf(t->names[t->cols++], 64, "%s", tok);
    }
    while (fgets(line, sizeof line, f) && t->rows < MAX_ROWS) {
        char *p = line;
        double ts = strtod(p, &p);
        t->t_ns[t->rows] = (int64_t)llround(ts * 1e3) * 1000000;
        for (int c = 0; c < t->cols; c++) {
            assert_int_equal(*p, ',');
            p++;
            if (*p == ',' || *p == '\n' || *p == '\0')
                continue;
            t->v[t->rows][c] = strtod(p, &p);
            t->has[t->rows][c] = 1;
        }
        t->rows++;
    }
    fclose(f);
    assert_int_equal(t->rows, 200);
    assert_int_equal(t->cols, 20);
}

static pb_can_bus *load_bus(const char *map)
{
    char path[1024];
    repo_path(path, sizeof path, map);
    pb_can_bus *bus = NULL;
    pb_error err;
    if (pb_can_bus_load(path, &bus, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return bus;
}

static pb_source *open_replay(pb_can_bus *bus)
{
    char log[1024];
    data_path(log, sizeof log, "can-rig/sit_stand_arm_raise.log");
    pb_source *src = NULL;
    pb_error err;
    pb_candump_replay_options opt = {.as_fast_as_possible = 1};
    if (pb_candump_replay_open(log, bus, &opt, &src, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return src;
}

/* Half the quantisation step of each channel's encoding. */
static double resolution(const pb_can_bus *bus, const char *name)
{
    if (strstr(name, ".angle"))
        return 180.0 / 4096 + 1e-9; /* CiA 406, 4096 steps */
    if (strncmp(name, "HEAD.", 5) == 0)
        return 0.001 + 1e-9; /* J1939 0.002 deg/bit */
    char msg[64];
    snprintf(msg, sizeof msg, "%.*s", (int)(strchr(name, '.') - name), name);
    const pb_dbc_message *m;
    int si = pb_dbc_find_signal(pb_can_bus_dbc(bus), msg, strchr(name, '.') + 1, &m);
    assert_true(si >= 0);
    if (m->signals[si].value_type == PB_DBC_FLOAT32)
        return 1e-4;
    return m->signals[si].factor / 2 + 1e-9;
}

typedef struct transitions {
    int count;
    pb_source_state state[64];
    int64_t t_ns[64];
    char message[64][200];
    int64_t now; /* time of the update being read */
} transitions;

static void on_status(pb_source *src, pb_source_state st, const char *msg, void *user)
{
    (void)src;
    transitions *tr = user;
    if (tr->count < 64) {
        tr->state[tr->count] = st;
        tr->t_ns[tr->count] = tr->now;
        snprintf(tr->message[tr->count], sizeof tr->message[0], "%s", msg);
        tr->count++;
    }
}

/* First transition to `state` whose message contains `text`, at or after from_ns; -1 if none. */
static int find_transition(const transitions *tr, pb_source_state state, const char *text, int64_t from_ns)
{
    for (int i = 0; i < tr->count; i++)
        if (tr->state[i] == state && tr->t_ns[i] >= from_ns && strstr(tr->message[i], text))
            return i;
    return -1;
}

static void test_decode_matches_truth(void **state)
{
    (void)state;
    static truth t;
    load_truth(&t);
    pb_can_bus *bus = load_bus("bridge/maps/can_rig_fullbody.json");
    pb_source *src = open_replay(bus);
    pb_can_decoder *dec = pb_can_source_decoder(src);
    /* column -> channel index and tolerance (the source owns bus now; it lives as long) */
    int col_channel[MAX_COLS];
    double tol[MAX_COLS];
    for (int c = 0; c < t.cols; c++) {
        col_channel[c] = (int)pb_source_find_channel(src, t.names[c]);
        if (col_channel[c] < 0)
            fail_msg("no channel %s", t.names[c]);
        tol[c] = resolution(bus, t.names[c]);
    }
    static double latest[256];
    static int have[256];
    memset(have, 0, sizeof have);
    transitions tr = {0};
    src->on_status = on_status;
    src->on_status_user = &tr;
    pb_update u;
    int row = 0, checked = 0;
    int rc;
    while ((rc = src->ops->read(src, &u, -1)) == 1) {
        while (row < t.rows && t.t_ns[row] < u.t_ns) {
            for (int c = 0; c < t.cols; c++) {
                if (!t.has[row][c])
                    continue;
                const int ch = col_channel[c];
                assert_true(have[ch]);
                if (!(fabs(latest[ch] - t.v[row][c]) <= tol[c]))
                    fail_msg("t=%.3f %s: decoded %.6f, truth %.6f", t.t_ns[row] * 1e-9, t.names[c],
                             latest[ch], t.v[row][c]);
                checked++;
            }
            row++;
        }
        tr.now = u.t_ns;
        for (size_t k = 0; k < u.count; k++) {
            latest[u.channels[k]] = u.values[k];
            have[u.channels[k]] = 1;
        }
    }
    assert_int_equal(rc, -1);
    assert_int_equal(src->state, PB_SOURCE_ENDED);
    assert_true(row >= t.rows - 1); /* the last row lies after the last frame */
    assert_true(checked > 3500);

    const pb_can_stats *st = pb_can_decoder_stats(dec);
    assert_int_equal(st->frames, 32944);
    assert_int_equal(st->bad_lines, 7);
    assert_int_equal(st->short_frames, 1);
    assert_int_equal(st->error_frames, 3);
    assert_int_equal(st->unknown, 1); /* the NMT start command 000#0124 */

    /* fault timeline (seconds after the first frame; a transition is stamped
     * with the latest update delivered before it) */
    const int64_t s = 1000000000;
    int i = find_transition(&tr, PB_SOURCE_STALE, "KNEE_L silent", 5 * s);
    assert_true(i >= 0);
    /* last KNEE_L frame just before 5.0 s, timeout 3 cycles of 5 ms */
    assert_true(tr.t_ns[i] >= 5005000000 && tr.t_ns[i] < 5025000000);
    int back = find_transition(&tr, PB_SOURCE_OK, "", tr.t_ns[i]);
    assert_true(back > i);
    assert_true(tr.t_ns[back] >= 5500000000 && tr.t_ns[back] < 5510000000);
    i = find_transition(&tr, PB_SOURCE_STALE, "ANKLE_R", 6 * s);
    assert_true(i >= 0);
    assert_true(tr.t_ns[i] < 6100000000);
    back = find_transition(&tr, PB_SOURCE_OK, "", tr.t_ns[i]);
    assert_true(tr.t_ns[back] >= 6600000000 && tr.t_ns[back] < 6700000000);
    i = find_transition(&tr, PB_SOURCE_FAULT, "error-passive", 7 * s);
    assert_true(i >= 0 && tr.t_ns[i] < 7010000000);
    i = find_transition(&tr, PB_SOURCE_FAULT, "bus-off", 7 * s);
    assert_true(i >= 0 && tr.t_ns[i] >= 7290000000 && tr.t_ns[i] < 7310000000);
    back = find_transition(&tr, PB_SOURCE_OK, "", tr.t_ns[i]);
    assert_true(back > i && tr.t_ns[back] >= 7400000000 && tr.t_ns[back] < 7500000000);
    i = find_transition(&tr, PB_SOURCE_OK, "malformed log line", 8 * s);
    assert_true(i >= 0 && tr.t_ns[i] < 8010000000);
    assert_non_null(strstr(tr.message[i], "sit_stand_arm_raise.log:"));
    i = find_transition(&tr, PB_SOURCE_OK, "ELBOW_R (0x108): 2 data bytes, DBC says 8", 8 * s);
    assert_true(i >= 0 && tr.t_ns[i] >= 8500000000 && tr.t_ns[i] < 8510000000);
    assert_int_equal(tr.state[tr.count - 1], PB_SOURCE_ENDED);

    /* seek back into the knee's silence: the monitor state is rebuilt */
    assert_int_equal(src->ops->seek(src, 5200000000), 0);
    assert_int_equal(src->state, PB_SOURCE_STALE);
    assert_int_equal(src->ops->read(src, &u, -1), 1);
    assert_true(u.t_ns >= 5200000000);
    pb_source_destroy(src);
}

static pb_rig_skel *make_skel(const char *const (*names)[2], size_t n)
{
    pose_joint_desc j[32];
    memset(j, 0, sizeof j);
    for (size_t i = 0; i < n; i++) {
        j[i].name = names[i][0];
        j[i].parent = -1;
        for (size_t k = 0; k < i; k++)
            if (strcmp(names[k][0], names[i][1]) == 0)
                j[i].parent = (int)k;
        j[i].rest_model.rotation[3] = 1.0f;
        j[i].rest_model.translation[2] = (float)i * 0.1f;
    }
    pb_rig_skel *s = NULL;
    pb_error err;
    if (pb_rig_skel_from_desc(j, n, &s, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return s;
}

/* Replay through the mapping until time t_ns; returns the last update time. */
static void replay_until(pb_source *src, pb_chanmap *cm, int64_t t_ns)
{
    pb_update u;
    while (src->ops->read(src, &u, -1) == 1) {
        pb_chanmap_update(cm, &u);
        if (u.t_ns >= t_ns)
            return;
    }
}

static int entry_of(const pb_mapping *m, const char *channel)
{
    for (int i = 0; i < m->channel_count; i++)
        if (strcmp(m->channels[i].channel, channel) == 0)
            return i;
    fail_msg("mapping has no %s", channel);
    return -1;
}

static void test_full_body_mapping(void **state)
{
    (void)state;
    char path[1024];
    repo_path(path, sizeof path, "bridge/maps/can_rig_fullbody.json");
    pb_mapping *map = NULL;
    pb_error err;
    if (pb_mapping_load(path, &map, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_source *src = open_replay(load_bus("bridge/maps/can_rig_fullbody.json"));
    pb_rig_skel *skel = NULL;
    if (pb_rig_skel_schematic_body(&skel, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_chanmap *cm = NULL;
    if (pb_chanmap_create(map, src->channels, src->channel_count, skel, &cm, &err) != POSE_OK)
        fail_msg("%s", err.message);
    const int knee_l = entry_of(map, "KNEE_L.flex"), hip_l = entry_of(map, "HIP_L.flex");
    const int shoulder_r = entry_of(map, "SHOULDER_R.flex"), ankle_r = entry_of(map, "ANKLE_R.angle");
    pb_pose pose;
    assert_int_equal(pb_pose_init(&pose, skel->joint_count), 0);

    /* seated (0.8 s): knee 90, hip flexed 90 (clinical angles: flexion positive on both) */
    replay_until(src, cm, 800000000);
    assert_true(fabs(pb_chanmap_value(cm, knee_l) - 90.0) < 0.5);
    assert_true(fabs(pb_chanmap_value(cm, hip_l) - 90.0) < 0.5);
    pb_chanmap_pose(cm, &pose);
    const int kj = pb_rig_skel_find(skel, "knee_l");
    assert_true(pose.active[kj]);
    /* 90 degrees about the knee's flexion axis (+y): {0, sin 45, 0, cos 45} */
    assert_true(fabs(pose.q[kj][1] - 0.70710678f) < 0.01f && fabs(pose.q[kj][3] - 0.70710678f) < 0.01f);
    /* the hip flexes about -y (the template's +y extends it) */
    const int hj = pb_rig_skel_find(skel, "hip_l");
    assert_true(fabs(pose.q[hj][1] + 0.70710678f) < 0.01f && fabs(pose.q[hj][3] - 0.70710678f) < 0.01f);
    /* standing (4.0 s): legs straight, arms down */
    replay_until(src, cm, 4000000000);
    assert_true(fabs(pb_chanmap_value(cm, knee_l)) < 1.0);
    assert_true(fabs(pb_chanmap_value(cm, hip_l)) < 1.0);
    assert_true(fabs(pb_chanmap_value(cm, shoulder_r)) < 1.0);
    /* knee silent 5.0-5.5 s: its joint holds while the bus moves on */
    replay_until(src, cm, 5020000000);
    const double held = pb_chanmap_value(cm, knee_l);
    replay_until(src, cm, 5450000000);
    assert_true(pb_chanmap_value(cm, knee_l) == held);
    /* ANKLE_R lost 6.0-6.6 s: held too */
    replay_until(src, cm, 6050000000);
    const double ankle_held = pb_chanmap_value(cm, ankle_r);
    replay_until(src, cm, 6550000000);
    assert_true(pb_chanmap_value(cm, ankle_r) == ankle_held);
    /* arms up (7.6 s): right shoulder flexion 150, within the clinical range (the rig's
     * range of motion, not the mapping, limits it: libpose clamps) */
    replay_until(src, cm, 7600000000);
    assert_true(fabs(pb_chanmap_value(cm, shoulder_r) - 150.0) < 0.5);
    pb_pose_free(&pose);
    pb_chanmap_free(cm);
    pb_rig_skel_free(skel);
    pb_source_destroy(src);
    pb_mapping_free(map);
}

static void test_bar_mapping(void **state)
{
    (void)state;
    static const char *const BAR[][2] = {{"joint0", ""}, {"joint1", "joint0"}, {"joint2", "joint1"}, {"joint3", "joint2"}};
    char path[1024];
    repo_path(path, sizeof path, "bridge/maps/can_rig_bar.json");
    pb_mapping *map = NULL;
    pb_error err;
    if (pb_mapping_load(path, &map, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pb_source *src = open_replay(load_bus("bridge/maps/can_rig_bar.json"));
    assert_int_equal(src->channel_count, 3); /* the map's "can.channels" selection */
    pb_rig_skel *skel = make_skel(BAR, 4);
    pb_chanmap *cm = NULL;
    if (pb_chanmap_create(map, src->channels, src->channel_count, skel, &cm, &err) != POSE_OK)
        fail_msg("%s", err.message);
    /* the mapping alone also selects what the bus delivers and the kernel passes */
    pb_can_bus *mapped = load_bus("bridge/maps/can_rig_fullbody.json");
    assert_int_equal(pb_can_bus_select_mapped(mapped, map, &err), POSE_OK);
    pb_can_decoder *dec = NULL;
    assert_int_equal(pb_can_decoder_create(pb_can_bus_config(mapped), &dec, &err), POSE_OK);
    size_t nf, nc;
    const pb_can_filter *flt = pb_can_decoder_filters(dec, &nf);
    pb_can_decoder_channels(dec, &nc);
    assert_int_equal(nc, 3);
    assert_int_equal(nf, 4); /* ANKLE_L's TPDO1 and heartbeat, HIP_L, KNEE_L */
    assert_int_equal(flt[0].id, 0x1A3);
    assert_int_equal(flt[1].id, 0x723);
    assert_int_equal(flt[2].id, 0x109);
    assert_int_equal(flt[3].id, 0x10B);
    pb_can_decoder_free(dec);
    pb_can_bus_free(mapped);

    replay_until(src, cm, 800000000);
    assert_true(fabs(pb_chanmap_value(cm, 1) - -90.0) < 0.1); /* knee, inverted, unfiltered */
    assert_true(fabs(pb_chanmap_value(cm, 2) - -15.0) < 0.2); /* ankle encoder */
    replay_until(src, cm, 4000000000);
    assert_true(fabs(pb_chanmap_value(cm, 1)) < 0.1);
    pb_chanmap_free(cm);
    pb_rig_skel_free(skel);
    pb_source_destroy(src);
    pb_mapping_free(map);
}

/* A three-frame log: looping keeps time moving forward, recorded timing
 * takes the recorded time, as fast as possible does not. */
static void test_replay_loop_and_timing(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/three.log", getenv("POSE_TEST_TMP"));
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    /* KNEE_L 0x10B: 90 deg = 40 19 01; 45 deg = A0 8C 00 */
    fputs("(1000.000000) can0 10B#4019010000000000\n"
          "(1000.040000) can0 10B#A08C000000000000\n"
          "(1000.080000) can0 10B#4019010000000000\n",
          f);
    fclose(f);
    const char *const knee[] = {"KNEE_L.flex"};
    for (int mode = 0; mode < 2; mode++) {
        pb_can_bus *bus = load_bus("bridge/maps/can_rig_fullbody.json");
        assert_int_equal(pb_can_bus_select(bus, knee, 1), POSE_OK);
        pb_source *src = NULL;
        pb_error err;
        pb_candump_replay_options opt = {.as_fast_as_possible = mode == 0, .loop = mode == 0};
        assert_int_equal(pb_candump_replay_open(path, bus, &opt, &src, &err), POSE_OK);
        pb_update u;
        struct timespec a, b;
        clock_gettime(CLOCK_MONOTONIC, &a);
        if (mode == 0) {
            static const double want[7] = {90, 45, 90, 90, 45, 90, 90};
            int64_t prev = -1;
            for (int i = 0; i < 7; i++) {
                assert_int_equal(src->ops->read(src, &u, 0), 1);
                assert_true(u.values[0] == want[i]);
                assert_true(u.t_ns > prev);
                prev = u.t_ns;
            }
            /* each pass starts one mean frame period (80 ms / 2) after the last frame:
             * 0 40 80 | 120 160 200 | 240 */
            assert_true(prev == 240000000);
            assert_true(src->state != PB_SOURCE_ENDED);
        } else {
            int n = 0;
            while (src->ops->read(src, &u, 200) >= 0)
                n++;
            assert_int_equal(n, 3);
            assert_int_equal(src->state, PB_SOURCE_ENDED);
            clock_gettime(CLOCK_MONOTONIC, &b);
            const double wall = (double)(b.tv_sec - a.tv_sec) + (b.tv_nsec - a.tv_nsec) * 1e-9;
            assert_true(wall >= 0.075 && wall < 1.0); /* 80 ms recorded */
        }
        pb_source_destroy(src);
    }
}

static void test_bus_json_errors(void **state)
{
    (void)state;
    static const char *const bad[][2] = {
        {"[", "not valid JSON"},
        {"{\"can\": 3}", "must be an object"},
        {"{\"dbc\": 5}", "file name"},
        {"{\"dbc\": \"/nonexistent.dbc\"}", "/nonexistent.dbc"},
        {"{\"canopen\": [{\"node\": 0}]}", "canopen[0]"},
        {"{\"canopen\": [{\"node\": 200}]}", "canopen[0]"},
        {"{\"canopen\": {}}", "must be an array"},
        {"{\"j1939\": [{\"name\": \"x\"}]}", "j1939[0]"},
        {"{\"timeout_ms\": -1}", "timeout_ms"},
        {"{\"channels\": [1]}", "channels[0]"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        pb_can_bus *b = (pb_can_bus *)1;
        pb_error err;
        err.message[0] = '\0';
        assert_true(pb_can_bus_parse(bad[i][0], strlen(bad[i][0]), "bus.json", NULL, &b, &err) != POSE_OK);
        assert_null(b);
        if (!strstr(err.message, bad[i][1]))
            fail_msg("'%s': message '%s' lacks '%s'", bad[i][0], err.message, bad[i][1]);
    }
    /* a CANopen profile that is neither 406 nor 410 fails when the source opens */
    const char *odd = "{\"canopen\": [{\"node\": 5, \"profile\": 401}]}";
    pb_can_bus *b = NULL;
    pb_error err;
    assert_int_equal(pb_can_bus_parse(odd, strlen(odd), "bus.json", NULL, &b, &err), POSE_OK);
    pb_source *src = NULL;
    char log[1024];
    data_path(log, sizeof log, "can-rig/sit_stand_arm_raise.log");
    assert_int_equal(pb_candump_replay_open(log, b, NULL, &src, &err), POSE_ERR_UNSUPPORTED);
    assert_null(src);
    assert_non_null(strstr(err.message, "profile 401"));
    /* a missing log */
    assert_int_equal(pb_can_bus_parse("{}", 2, "bus.json", NULL, &b, &err), POSE_OK);
    assert_int_equal(pb_candump_replay_open("/nonexistent.log", b, NULL, &src, &err), POSE_ERR_IO);
    assert_non_null(strstr(err.message, "/nonexistent.log"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bus_json_errors),
        cmocka_unit_test(test_replay_loop_and_timing),
        cmocka_unit_test(test_decode_matches_truth),
        cmocka_unit_test(test_full_body_mapping),
        cmocka_unit_test(test_bar_mapping),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
