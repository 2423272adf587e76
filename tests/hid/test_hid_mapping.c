/* SPDX-License-Identifier: Apache-2.0
 * Mannequin recordings through the bridge's channel mapping onto rigs: the
 * full-body template's joints and the synthetic four-bone bar follow the
 * recorded angles within calibration error; the calibration helper's round
 * trip recovers the simulated sensors' gain and offset. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "calibrate.h"
#include "hid_mannequin.h"
#include "hid_open.h"
#include "mapping.h"
#include "pose_synth.h"

static pb_rig_skel *body_skel(void)
{
    pb_rig_skel *s;
    pb_error err;
    if (pb_rig_skel_schematic_body(&s, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(s->joint_count, 19);
    return s;
}

static void repo_path(char *buf, size_t n, const char *rel)
{
    const char *dir = getenv("POSE_DATA_DIR");
    assert_non_null(dir);
    snprintf(buf, n, "%s/../%s", dir, rel);
}

static pb_source *replay(const char *file)
{
    char path[1024];
    snprintf(path, sizeof path, "data/hid/%s", file);
    char full[1100];
    repo_path(full, sizeof full, path);
    pb_hid_replay_options opt = {.as_fast_as_possible = 1};
    pb_source *src;
    pb_error err;
    if (pb_hid_open(full, &opt, &src, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return src;
}

static pb_mapping *load_map(const char *rel)
{
    char path[1024];
    repo_path(path, sizeof path, rel);
    pb_mapping *m;
    pb_error err;
    if (pb_mapping_load(path, &m, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return m;
}

static void test_invalid(void **state)
{
    (void)state;
    pb_rig_skel *skel = body_skel();
    pb_source *src = replay("mannequin_reach_1khz.hid");
    const char *cases[][2] = {
        {"{\"channels\":[{\"channel\":\"Ordinal.99\",\"joint\":\"knee_l\",\"axis\":\"y\"}]}", "no channel 'Ordinal.99'"},
        {"{\"channels\":[{\"channel\":\"Ordinal.1\",\"joint\":\"tail\",\"axis\":\"y\"}]}", "no joint 'tail'"},
        {"{\"channels\":[{\"usage\":\"0x000a0001\",\"index\":1,\"joint\":\"knee_l\",\"axis\":\"y\"}]}", "usage"},
    };
    for (int i = 0; i < 3; i++) {
        pb_mapping *m;
        pb_chanmap *c = NULL;
        pb_error err;
        assert_int_equal(pb_mapping_parse(cases[i][0], strlen(cases[i][0]), "bad.json", &m, &err), POSE_OK);
        assert_int_equal(pb_chanmap_create(m, src->channels, src->channel_count, skel, &c, &err), POSE_ERR_NOT_FOUND);
        assert_null(c);
        if (!strstr(err.message, cases[i][1]))
            fail_msg("'%s' lacks '%s'", err.message, cases[i][1]);
        pb_mapping_free(m);
    }
    /* By usage: Ordinal 13 is knee_l's goniometer. */
    const char *by_usage = "{\"channels\":[{\"usage\":\"0x000a000d\",\"joint\":\"knee_l\",\"axis\":\"y\"}]}";
    pb_mapping *m;
    pb_chanmap *c;
    pb_error err;
    assert_int_equal(pb_mapping_parse(by_usage, strlen(by_usage), "usage.json", &m, &err), POSE_OK);
    assert_int_equal(pb_chanmap_create(m, src->channels, src->channel_count, skel, &c, &err), POSE_OK);
    pb_update u;
    assert_int_equal(pb_source_read(src, &u, 100), 1);
    pb_chanmap_update(c, &u);
    assert_float_equal(pb_chanmap_value(c, 0), u.values[12], 1e-9);
    pb_chanmap_free(c);
    pb_mapping_free(m);
    pb_source_destroy(src);
    pb_rig_skel_free(skel);
}

static double clamp(double v, const pb_map_channel *m)
{
    if (m->has_limits)
        v = v < m->limit[0] ? m->limit[0] : v > m->limit[1] ? m->limit[1] : v;
    return v;
}

/* Feed a recording; compare every entry's output with the generator's angle. */
static double follow(const char *file, pb_mannequin_motion motion, double rate, pb_mapping *m, const pb_rig_skel *skel,
                     double settle_from_s, pb_chanmap **keep)
{
    pb_source *src = replay(file);
    pb_chanmap *c;
    pb_error err;
    if (pb_chanmap_create(m, src->channels, src->channel_count, skel, &c, &err) != POSE_OK)
        fail_msg("%s", err.message);
    double worst = 0;
    pb_update u;
    long n = 0;
    while (pb_source_read(src, &u, 100) == 1) {
        pb_chanmap_update(c, &u);
        double t = (double)n++ / rate, deg[16];
        pb_mannequin_pose(motion, t, deg, NULL);
        if (t < settle_from_s)
            continue;
        for (int i = 0; i < m->channel_count; i++) {
            const pb_map_channel *e = &m->channels[i];
            int axis = atoi(e->channel + strlen("Ordinal.")) - 1;
            double expect = clamp(e->invert ? -deg[axis] : deg[axis], e);
            double d = fabs(pb_chanmap_value(c, i) - expect);
            worst = d > worst ? d : worst;
        }
    }
    pb_source_destroy(src);
    if (keep)
        *keep = c;
    else
        pb_chanmap_free(c);
    return worst;
}

static void test_full_body_follows(void **state)
{
    (void)state;
    pb_rig_skel *skel = body_skel();
    pb_mapping *m = load_map("bridge/maps/hid_mannequin_full_body.json");
    assert_int_equal(m->channel_count, 16);
    /* Without filters: sensor noise (0.12 deg RMS), quantisation and the 0.05 deg deadband. */
    m->has_filter = 0;
    for (int i = 0; i < m->channel_count; i++)
        m->channels[i].has_filter = 0;
    double w1 = follow("mannequin_sit_to_stand.hid", PB_MOTION_SIT_TO_STAND, 500, m, skel, 0, NULL);
    double w2 = follow("mannequin_arm_raise.hid", PB_MOTION_ARM_RAISE, 250, m, skel, 0, NULL);
    print_message("largest joint error without filter: sit-to-stand %.3f deg, arm raise %.3f deg\n", w1, w2);
    assert_true(w1 < 0.8 && w2 < 0.8);
    assert_true(w1 > 0.05); /* noise passes unfiltered */
    pb_mapping_free(m);

    /* With the mapping's One Euro filter, once the mannequin stands still. */
    m = load_map("bridge/maps/hid_mannequin_full_body.json");
    pb_chanmap *c;
    double w3 = follow("mannequin_sit_to_stand.hid", PB_MOTION_SIT_TO_STAND, 500, m, skel, 6.0, &c);
    print_message("largest joint error with filter, standing: %.3f deg\n", w3);
    assert_true(w3 < 1.0);
    /* The pose: knee_l (y only) is a rotation about y by the knee angle. */
    pb_pose p;
    assert_int_equal(pb_pose_init(&p, skel->joint_count), 0);
    pb_chanmap_pose(c, &p);
    int knee = pb_rig_skel_find(skel, "knee_l");
    assert_true(p.active[knee]);
    assert_false(p.active[pb_rig_skel_find(skel, "head")]);
    double knee_deg = pb_chanmap_value(c, 12);
    double half = knee_deg * 3.14159265358979323846 / 360.0;
    assert_float_equal(p.q[knee][0], 0.0, 1e-6);
    assert_float_equal(p.q[knee][1], sin(half), 1e-5);
    assert_float_equal(p.q[knee][2], 0.0, 1e-6);
    assert_float_equal(p.q[knee][3], cos(half), 1e-5);
    pb_pose_free(&p);
    pb_chanmap_free(c);
    pb_mapping_free(m);
    pb_rig_skel_free(skel);
}

static void test_bar_follows(void **state)
{
    (void)state;
    pose_synth_bar_options o = {.layers_per_bone = 8, .rings = 2, .sectors = 6, .cor = POSE_SYNTH_COR_NONE};
    pose_synth_rig *rig;
    assert_int_equal(pose_synth_bar(&o, &rig), POSE_OK);
    const pose_rig_desc *d = pose_synth_desc(rig);
    pb_rig_skel *skel;
    pb_error err;
    assert_int_equal(pb_rig_skel_from_desc(d->joints, d->joint_count, &skel, &err), POSE_OK);
    pb_mapping *m = load_map("bridge/maps/hid_mannequin_bar.json");
    m->has_filter = 0;
    double worst = follow("mannequin_sit_to_stand.hid", PB_MOTION_SIT_TO_STAND, 500, m, skel, 0, NULL);
    assert_true(worst < 0.8);
    pb_chanmap *c;
    follow("mannequin_reach_1khz.hid", PB_MOTION_REACH, 1000, m, skel, 0, &c);
    pb_pose p;
    assert_int_equal(pb_pose_init(&p, skel->joint_count), 0);
    pb_chanmap_pose(c, &p);
    int j2 = pb_rig_skel_find(skel, "joint2");
    assert_true(j2 >= 0 && p.active[j2]);
    double deg[16];
    pb_mannequin_pose(PB_MOTION_REACH, 3.999, deg, NULL);
    double half = -deg[13] * 3.14159265358979323846 / 360.0; /* knee_r, inverted, about z */
    assert_float_equal(p.q[j2][2], sin(half), 0.01);
    assert_float_equal(p.q[j2][3], cos(half), 0.01);
    pb_pose_free(&p);
    pb_chanmap_free(c);
    pb_mapping_free(m);
    pb_rig_skel_free(skel);
    pose_synth_free(rig);
}

static void copy_file(const char *from, const char *to)
{
    FILE *a = fopen(from, "rb"), *b = fopen(to, "wb");
    assert_non_null(a);
    assert_non_null(b);
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, a)) > 0)
        assert_int_equal(fwrite(buf, 1, n, b), n);
    fclose(a);
    fclose(b);
}

/* Found by fuzz_calibrate: an entry that is not an object took a calibration
 * that was never written (reported as done), and text after the JSON value
 * was dropped by the rewrite. Both are errors now, the file untouched. */
static void test_calibration_refuses_what_it_cannot_write(void **state)
{
    (void)state;
    char map[1024];
    snprintf(map, sizeof map, "%s/calibrate_bad.json", getenv("POSE_TEST_TMP") ? getenv("POSE_TEST_TMP") : "/tmp");
    const double raw[2] = {0, 90}, deg[2] = {0, 90};
    pb_error err;
    static const char *const bad[][2] = {
        {"{\"channels\": [\"HIP_L.flex\"]}\n", "\"channels\" entry 0 is not an object"},
        {"{\"channels\": [{\"channel\": \"A\"}]}\n}, \"more\": 1}\n", "near byte 33 (text after the JSON value)"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        FILE *f = fopen(map, "w");
        assert_non_null(f);
        fputs(bad[i][0], f);
        fclose(f);
        assert_int_equal(pb_calibrate_write(map, NULL, 0, raw, deg, &err), POSE_ERR_FORMAT);
        if (!strstr(err.message, bad[i][1]))
            fail_msg("'%s' lacks '%s'", err.message, bad[i][1]);
    }
}

static void test_calibration_round_trip(void **state)
{
    (void)state;
    char src_map[1024], map[1024];
    repo_path(src_map, sizeof src_map, "bridge/maps/hid_mannequin_full_body.json");
    snprintf(map, sizeof map, "%s/calibrate.json", getenv("POSE_TEST_TMP") ? getenv("POSE_TEST_TMP") : "/tmp");
    copy_file(src_map, map);
    pb_error err;
    const double raw_id[2] = {0, 90}, deg_id[2] = {0, 90};
    /* Invalid first: unknown entry, equal readings, missing file. */
    assert_int_equal(pb_calibrate_write(map, "Ordinal.77", -1, raw_id, deg_id, &err), POSE_ERR_NOT_FOUND);
    assert_int_equal(pb_calibrate_write(map, NULL, 40, raw_id, deg_id, &err), POSE_ERR_NOT_FOUND);
    const double same[2] = {5, 5};
    assert_int_equal(pb_calibrate_write(map, "Ordinal.13", -1, same, deg_id, &err), POSE_ERR_INVALID_ARGUMENT);
    assert_int_equal(pb_calibrate_write("/nonexistent/m.json", "Ordinal.13", -1, raw_id, deg_id, &err), POSE_ERR_IO);
    /* Forget knee_l's calibration, then measure it again: seated (90 deg) and standing (4 deg). */
    assert_int_equal(pb_calibrate_write(map, "Ordinal.13", -1, raw_id, deg_id, &err), POSE_OK);
    char chname[64];
    uint32_t usage;
    int idx;
    assert_int_equal(pb_calibrate_entry(map, "Ordinal.13", -1, chname, sizeof chname, &usage, &idx, &err), POSE_OK);
    assert_string_equal(chname, "Ordinal.13");
    pb_source *src = replay("mannequin_sit_to_stand.hid");
    int ch = (int)pb_source_find_channel(src, chname);
    assert_int_equal(ch, 12);
    double raw[2];
    assert_int_equal(pb_source_seek(src, 500000000), 0);
    assert_int_equal(pb_calibrate_measure(src, (uint32_t)ch, 100, 1000, &raw[0], &err), POSE_OK);
    assert_int_equal(pb_source_seek(src, 6000000000LL), 0);
    assert_int_equal(pb_calibrate_measure(src, (uint32_t)ch, 100, 1000, &raw[1], &err), POSE_OK);
    const double deg[2] = {90, 4};
    assert_int_equal(pb_calibrate_write(map, "Ordinal.13", -1, raw, deg, &err), POSE_OK);
    pb_source_destroy(src);
    double g, o;
    pb_mannequin_sensor(12, &g, &o);
    assert_float_equal(raw[0], g * 90 + o, 0.05);
    assert_float_equal(raw[1], g * 4 + o, 0.05);
    /* The rewritten file still loads, other entries untouched, and maps raw readings to true angles. */
    pb_mapping *m;
    if (pb_mapping_load(map, &m, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(m->channel_count, 16);
    const pb_map_channel *knee = &m->channels[12];
    assert_string_equal(knee->channel, "Ordinal.13");
    assert_int_equal(knee->calib, PB_CALIB_TWO_POINT);
    for (double a = 0; a <= 120; a += 30)
        assert_float_equal(pb_map_channel_transform(knee, g * a + o), a, 0.1);
    pb_mannequin_sensor(13, &g, &o);
    assert_float_equal(pb_map_channel_transform(&m->channels[13], g * 45 + o), 45.0, 1e-3);
    pb_mapping_free(m);
}

/* Neutral posture for every entry at once (hid-calibrate --neutral): the
 * readings of a standing frame become 0 degrees, each entry keeping its gain. */
static void test_neutral_calibration(void **state)
{
    (void)state;
    char src_map[1024], map[1024];
    repo_path(src_map, sizeof src_map, "bridge/maps/hid_mannequin_full_body.json");
    snprintf(map, sizeof map, "%s/neutral.json", getenv("POSE_TEST_TMP") ? getenv("POSE_TEST_TMP") : "/tmp");
    copy_file(src_map, map);
    pb_error err;
    pb_mapping *before = load_map("bridge/maps/hid_mannequin_full_body.json");
    pb_source *src = replay("mannequin_sit_to_stand.hid");
    assert_int_equal(pb_source_seek(src, 7600000000LL), 0); /* quiet standing */
    double raw[16];
    assert_int_equal(pb_calibrate_measure_entries(src, before, 100, 1000, raw, &err), POSE_OK);
    /* the readings are the sensors' response to the generator's standing angles (noise averaged out) */
    double deg[PB_MANNEQUIN_AXES];
    pb_mannequin_pose(PB_MOTION_SIT_TO_STAND, 7.7, deg, NULL);
    for (int i = 0; i < 16; i++) {
        double g, o;
        pb_mannequin_sensor(i, &g, &o);
        assert_float_equal(raw[i], g * deg[i] + o, 0.3);
    }
    int written = 0;
    assert_int_equal(pb_calibrate_write_neutral(map, before, raw, &written, &err), POSE_OK);
    assert_int_equal(written, 16);
    pb_mapping *after;
    if (pb_mapping_load(map, &after, &err) != POSE_OK)
        fail_msg("%s", err.message);
    for (int i = 0; i < 16; i++) {
        const pb_map_channel *a = &after->channels[i], *b = &before->channels[i];
        assert_float_equal(pb_map_channel_transform(a, raw[i]), 0.0, 1e-9);
        double slope_a = pb_map_channel_transform(a, raw[i] + 10) - pb_map_channel_transform(a, raw[i]);
        double slope_b = pb_map_channel_transform(b, raw[i] + 10) - pb_map_channel_transform(b, raw[i]);
        assert_float_equal(slope_a, slope_b, 1e-9);
        assert_string_equal(a->joint, b->joint); /* the rest of the entry is untouched */
        assert_string_equal(a->dof, b->dof);
    }
    /* a file the source cannot bind leaves nothing written: a missing map is an I/O error */
    assert_int_equal(pb_calibrate_write_neutral("/nonexistent/m.json", before, raw, NULL, &err), POSE_ERR_IO);
    pb_mapping_free(after);
    pb_mapping_free(before);
    pb_source_destroy(src);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_invalid),
        cmocka_unit_test(test_full_body_follows),
        cmocka_unit_test(test_bar_follows),
        cmocka_unit_test(test_calibration_round_trip),
        cmocka_unit_test(test_calibration_refuses_what_it_cannot_write),
        cmocka_unit_test(test_neutral_calibration),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
