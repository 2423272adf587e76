/* SPDX-License-Identifier: Apache-2.0
 * The simulated vendor-class device: the bundled captures replay through the
 * USB source (usb_source.h) exactly as the generator made them (the capture
 * is regenerated here and compared byte for byte), and the faulty capture's
 * faults are each counted exactly and reported through the source's state
 * while the last good values hold: 3 frames lost, 2 late and 1 repeated
 * (3 reordered), a stall, babble, a wire error, a short transfer, 2 bad
 * checksums, and an unplug mid-transfer after which the device, back at
 * another address with its counter restarted, is reopened. Also: recorded
 * timing, seeking, source strings, the live opener without a device, and
 * the source's hotplug path on a scripted transport: after the device
 * leaves, no open is tried until the transport reports its arrival. */
#include <errno.h>
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

#include "usb_gonio.h"
#include "usb_hid.h"
#include "usb_source.h"
#include "usbmon.h"
#include "pb_warn.h"
#include "clock.h"

static const char *data_path(char *buf, size_t n, const char *rel)
{
    const char *d = getenv("POSE_DATA_DIR");
    snprintf(buf, n, "%s/%s", d ? d : ".", rel);
    return buf;
}

static pb_usb_layout *box(void)
{
    static pb_usb_layout l;
    char p[1024];
    pb_error err;
    if (pb_usb_layout_load(data_path(p, sizeof p, "../bridge/maps/usb_gonio_full_body.json"), &l, &err) != POSE_OK)
        fail_msg("%s", err.message);
    return &l;
}

/* The faults of pose-usb-gonio-gen's faulty capture (bridge/devices/usb_gonio_gen.c). */
static const uint32_t lost[] = {500, 501, 1700}, late[] = {800, 2300}, repeated[] = {1200}, stall[] = {1000},
                      babble[] = {1500}, wire[] = {2000}, short_xfer[] = {2500}, bad_crc[] = {2600, 2601};
static const pb_gonio_faults FAULTS = {1, lost, 3, late, 2, repeated, 1, stall, babble, wire, short_xfer, bad_crc,
                                       1, 1, 1, 1, 2, 3000, 200};

/* Regenerate a bundled capture in memory; it must equal the file; returns frames sent. */
static long regenerate(const char *file, pb_mannequin_motion m, double hz, double s, uint32_t seed,
                       const pb_gonio_faults *fl, const char *header)
{
    char *buf = NULL, p[1024];
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    fputs(header, f);
    long sent = pb_gonio_write_capture(f, m, hz, s, seed, fl);
    fclose(f);
    assert_true(sent > 0);
    FILE *in = fopen(data_path(p, sizeof p, file), "rb");
    assert_non_null(in);
    char *disk = malloc(len + 2);
    size_t got = fread(disk, 1, len + 1, in);
    fclose(in);
    if (got != len || memcmp(disk, buf, len) != 0)
        fail_msg("%s differs from what pose-usb-gonio-gen makes now (%zu vs %zu bytes): run it again", file, got, len);
    free(disk);
    free(buf);
    return sent;
}

typedef struct watch {
    int faults, disconnected, reopened, ok_after_reopen, ended;
    char seen[8192];        /* the fault messages, concatenated */
    int64_t held_raw[32];   /* raw values after the last delivered update */
    int have_held;
    int held_checked;
    const pb_source *src;
} watch;

static void on_status(pb_source *src, pb_source_state st, const char *msg, void *user)
{
    watch *w = user;
    (void)src;
    if (st == PB_SOURCE_FAULT) {
        w->faults++;
        size_t used = strlen(w->seen);
        snprintf(w->seen + used, sizeof w->seen - used, "%s|", msg);
        if (w->have_held) { /* the decoder's values did not move */
            assert_memory_equal(pb_usb_source_raw(w->src), w->held_raw, PB_MANNEQUIN_AXES * sizeof(int64_t));
            w->held_checked++;
        }
    } else if (st == PB_SOURCE_DISCONNECTED) {
        w->disconnected++;
        if (!strstr(msg, "unplugged mid-transfer"))
            fail_msg("disconnected: %s", msg);
    } else if (st == PB_SOURCE_WAITING && strstr(msg, "reopened")) {
        w->reopened++;
    } else if (st == PB_SOURCE_OK && w->reopened) {
        w->ok_after_reopen++;
    } else if (st == PB_SOURCE_ENDED) {
        w->ended++;
    }
}

static void test_faults_counted_exactly(void **state)
{
    (void)state;
    long sent = regenerate("usb/gonio_reach_faults.usbmon", PB_MOTION_REACH, 1000.0, 4.0, 333, &FAULTS,
                           "# pose reference USB goniometer box (bridge/devices/README.md), simulated; usbmon text, "
                           "u format\n# motion reach, 1000 Hz, 4.0 s, noise seed 333, with injected faults; made by "
                           "pose-usb-gonio-gen\n");
    char p[1024];
    pb_source *src;
    pb_error err;
    pb_usb_replay_options o = {.as_fast_as_possible = 1, .source = {.hold_channel = "hold"}};
    assert_int_equal(pb_usb_replay_open(data_path(p, sizeof p, "usb/gonio_reach_faults.usbmon"), box(), &o, &src, &err),
                     POSE_OK);
    assert_string_equal(src->ops->kind, "usbmon-replay");
    assert_int_equal(src->channel_count, PB_MANNEQUIN_AXES + 1);
    watch w = {0};
    w.src = src;
    src->on_status = on_status;
    src->on_status_user = &w;
    long updates = 0;
    int64_t last_t = -1;
    for (;;) {
        pb_update u;
        int r = pb_source_read(src, &u, 1000);
        if (r < 0)
            break;
        if (r == 0)
            continue;
        updates++;
        assert_true(u.t_ns > last_t); /* the late frames are not delivered: time only goes forward */
        last_t = u.t_ns;
        memcpy(w.held_raw, pb_usb_source_raw(src), PB_MANNEQUIN_AXES * sizeof(int64_t));
        w.have_held = 1;
    }
    const pb_usb_frame_stats *s = pb_usb_source_stats(src);
    print_message("faulty capture: %ld frames sent, %ld delivered; lost %llu, reordered %llu, short %llu, bad "
                  "checksums %llu, stalls %llu, babble %llu, wire %llu, disconnects %llu; faults reported %d: %s\n",
                  sent, updates, (unsigned long long)s->lost, (unsigned long long)s->reordered,
                  (unsigned long long)s->short_frames, (unsigned long long)s->bad_checksums,
                  (unsigned long long)s->stalls, (unsigned long long)s->overflows, (unsigned long long)s->wire_errors,
                  (unsigned long long)s->disconnects, w.faults, w.seen);
    assert_int_equal(s->lost, 3);
    assert_int_equal(s->reordered, 3);
    assert_int_equal(s->short_frames, 1);
    assert_int_equal(s->long_frames, 0);
    assert_int_equal(s->bad_checksums, 2);
    assert_int_equal(s->stalls, 1);
    assert_int_equal(s->overflows, 1);
    assert_int_equal(s->wire_errors, 1);
    assert_int_equal(s->disconnects, 1);
    assert_int_equal(updates, sent - 3);
    assert_int_equal((long)s->frames, updates);
    assert_int_equal(pb_usb_source_drops(src), 3 + 3 + 1 + 2 + 1 + 1 + 1);
    /* each episode reported once: late x2, repeated, stall, babble, wire, short, and two bad checksums (a good frame
     * between them) */
    assert_int_equal(w.faults, 9);
    assert_int_equal(w.held_checked, 9);
    assert_non_null(strstr(w.seen, "stall (endpoint halted)"));
    assert_non_null(strstr(w.seen, "babble"));
    assert_non_null(strstr(w.seen, "transfer error on the wire"));
    assert_non_null(strstr(w.seen, "short transfer (16 bytes, frame 32)"));
    assert_non_null(strstr(w.seen, "checksum mismatch"));
    assert_non_null(strstr(w.seen, "sequence counter went back"));
    assert_int_equal(w.disconnected, 1);
    assert_int_equal(w.reopened, 1);
    assert_int_equal(w.ok_after_reopen, 1);
    assert_int_equal(w.ended, 1);
    assert_int_equal(pb_usb_source_reopens(src), 1);
    pb_source_destroy(src);
}

/* The clean captures are the generator's, and replay every frame. */
static void test_clean_captures(void **state)
{
    (void)state;
    static const struct {
        const char *file, *motion;
        pb_mannequin_motion m;
        double hz, s;
        uint32_t seed;
    } caps[] = {{"usb/gonio_sit_to_stand.usbmon", "sit-to-stand", PB_MOTION_SIT_TO_STAND, 500, 8, 111},
                {"usb/gonio_arm_raise.usbmon", "arm-raise", PB_MOTION_ARM_RAISE, 250, 10, 222}};
    for (int i = 0; i < 2; i++) {
        char header[512], p[1024];
        snprintf(header, sizeof header,
                 "# pose reference USB goniometer box (bridge/devices/README.md), simulated; usbmon text, u format\n"
                 "# motion %s, %.0f Hz, %.1f s, noise seed %u; made by pose-usb-gonio-gen\n",
                 caps[i].motion, caps[i].hz, caps[i].s, caps[i].seed);
        long sent = regenerate(caps[i].file, caps[i].m, caps[i].hz, caps[i].s, caps[i].seed, NULL, header);
        assert_int_equal(sent, (long)(caps[i].hz * caps[i].s));
        pb_source *src;
        pb_error err;
        pb_usb_replay_options o = {.as_fast_as_possible = 1};
        assert_int_equal(pb_usb_replay_open(data_path(p, sizeof p, caps[i].file), box(), &o, &src, &err), POSE_OK);
        long n = 0;
        pb_update u;
        int r;
        while ((r = pb_source_read(src, &u, 100)) >= 0)
            n += r;
        assert_int_equal(n, sent);
        assert_int_equal(pb_usb_source_drops(src), 0);
        assert_int_equal(src->state, PB_SOURCE_ENDED);
        pb_source_destroy(src);
    }
}

/* Recorded timing: 0.2 s of the 500 Hz capture takes 0.2 s, seek jumps. */
static void test_timing_and_seek(void **state)
{
    (void)state;
    char p[1024];
    pb_source *src;
    pb_error err;
    pb_usb_replay_options o = {.speed = 1.0};
    assert_int_equal(pb_usb_replay_open(data_path(p, sizeof p, "usb/gonio_sit_to_stand.usbmon"), box(), &o, &src, &err),
                     POSE_OK);
    int64_t start = pb_now_ns(), t0 = -1, t = 0;
    pb_update u;
    while (t - t0 < 200000000 || t0 < 0) {
        if (pb_source_read(src, &u, 100) != 1)
            continue;
        if (t0 < 0) {
            t0 = u.t_ns;
            start = pb_now_ns();
        }
        t = u.t_ns;
    }
    double wall = (double)(pb_now_ns() - start) * 1e-9;
    print_message("0.2 s of capture replayed in %.4f s\n", wall);
    assert_true(wall > 0.19 && wall < 0.3);
    assert_int_equal(pb_source_seek(src, 6000000000LL), 0);
    assert_int_equal(pb_source_read(src, &u, 100), 1);
    assert_true(u.t_ns >= 6000000000LL && u.t_ns < 6003000000LL);
    pb_source_destroy(src);
}

static void test_specs_and_live(void **state)
{
    (void)state;
    pb_usb_layout *l = box();
    pb_usb_layout c = *l;
    pb_error err;
    assert_int_equal(pb_usb_parse_spec("usb:16c0:05dc:GON-7/1/82", &c, &err), POSE_OK);
    assert_int_equal(c.vid, 0x16c0);
    assert_int_equal(c.pid, 0x05dc);
    assert_string_equal(c.serial, "GON-7");
    assert_int_equal(c.interface, 1);
    assert_int_equal(c.endpoint, 0x82);
    c = *l;
    assert_int_equal(pb_usb_parse_spec("usb:1209:0002", &c, &err), POSE_OK);
    assert_int_equal(c.endpoint, 0x81);
    assert_string_equal(c.serial, "");
    static const char *const bad[] = {"usb:1209", "usb:12345:1", "usb:1209:0002/0/01", "usb:1209:0002/x/81",
                                      "usb:1209:0002:", "usb:zz:0002"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(pb_usb_parse_spec(bad[i], &c, &err), POSE_ERR_INVALID_ARGUMENT);
        assert_non_null(strstr(err.message, "expected usb:VID:PID"));
    }
    /* a device that is not plugged in: the source waits for it (or the build/host has no USB at all) */
    pb_source *src = NULL;
    pose_status s = pb_usb_live_open("usb:1209:00fe", l, NULL, &src, &err);
    if (s == POSE_OK) {
        print_message("live: %s (%s)\n", pb_source_state_name(src->state), src->message);
        assert_int_equal(src->state, PB_SOURCE_DISCONNECTED);
        pb_update u;
        assert_int_equal(pb_source_read(src, &u, 50), 0);
        pb_source_destroy(src);
    } else {
        print_message("live: %s\n", err.message);
        assert_true(s == POSE_ERR_UNSUPPORTED || s == POSE_ERR_IO);
    }
    /* HID over hidapi's libusb backend (loaded with dlmopen): a device that is not there is named */
    s = pb_usb_hid_open("hidusb:1209:00fe", NULL, &src, &err);
    print_message("hidusb: %s\n", err.message);
    assert_null(src);
    assert_true(s == POSE_ERR_NOT_FOUND || s == POSE_ERR_UNSUPPORTED || s == POSE_ERR_IO);
    if (s == POSE_ERR_NOT_FOUND)
        assert_non_null(strstr(err.message, "hidusb 1209:00fe: no such device plugged in"));
    static const char *const bad_hid[] = {"hidusb:1209", "hidusb:1209:0002:x", "hidusb:12345:1", "hidusb:1209:0002:300"};
    for (size_t i = 0; i < sizeof bad_hid / sizeof bad_hid[0]; i++) {
        assert_int_equal(pb_usb_hid_open(bad_hid[i], NULL, &src, &err), POSE_ERR_INVALID_ARGUMENT);
        assert_non_null(strstr(err.message, "expected hidusb:VID:PID[:INTERFACE]"));
    }
}

/* A capture whose transfers the kernel cut at 32 bytes of a 40-byte frame: short, with a warning. */
static void test_cut_capture(void **state)
{
    (void)state;
    static pb_usb_layout l;
    pb_error err;
    const char *map = "{\"usb\": {\"frame_bytes\": 40, \"channels\": [{\"name\": \"a\", \"byte\": 36, \"size\": 4}]}}";
    assert_int_equal(pb_usb_layout_parse(map, strlen(map), "m", &l, &err), POSE_OK);
    const char *text = "t 1000 C Ii:1:002:1 0:1 40 = 00000000 00000000 00000000 00000000 00000000 00000000 00000000 "
                       "00000000\n";
    pb_usbmon_capture *cap;
    assert_int_equal(pb_usbmon_parse(text, strlen(text), "cut", &cap, &err), POSE_OK);
    pb_source *src;
    pb_usb_replay_options o = {.as_fast_as_possible = 1};
    assert_int_equal(pb_usb_replay_create(cap, "cut", &l, &o, &src, &err), POSE_OK);
    pb_update u;
    assert_int_equal(pb_source_read(src, &u, 0), 0);
    assert_int_equal(src->state, PB_SOURCE_FAULT);
    assert_non_null(strstr(src->message, "short transfer (32 bytes, frame 40)"));
    assert_int_equal(pb_usb_source_stats(src)->short_frames, 1);
    pb_source_destroy(src);
    /* a capture without the endpoint says so */
    assert_int_equal(pb_usbmon_parse(text, strlen(text), "cut", &cap, &err), POSE_OK);
    l.endpoint = 0x82;
    assert_int_equal(pb_usb_replay_create(cap, "cut", &l, &o, &src, &err), POSE_ERR_NOT_FOUND);
    assert_non_null(strstr(err.message, "no completed interrupt IN transfer on endpoint 0x82"));
}


/* A scripted live transport: frames while plugged, gone at frame 5, arrival reported after 3 waits. */
typedef struct fake {
    pb_usb_transport base;
    int plugged, opens, waits, reads, closes;
    int deny; /* opens to refuse after the arrival (udev not done yet) */
} fake;

static pose_status fake_open(pb_usb_transport *t, pb_error *err)
{
    fake *f = (fake *)t;
    f->opens++;
    if (f->plugged && f->deny > 0 && f->waits > 0) {
        f->deny--;
        return pb_fail(err, POSE_ERR_IO, "fake: found but not usable: Access denied");
    }
    return f->plugged ? POSE_OK : pb_fail(err, POSE_ERR_NOT_FOUND, "fake: not plugged in");
}

static int fake_read(pb_usb_transport *t, uint8_t *buf, size_t cap, int timeout_ms, pb_usb_completion *c)
{
    fake *f = (fake *)t;
    (void)cap;
    (void)timeout_ms;
    if (++f->reads == 5) {
        f->plugged = 0;
        return PB_USB_READ_GONE; /* hotplug said it left */
    }
    uint8_t fr[PB_GONIO_FRAME_BYTES];
    double deg[PB_MANNEQUIN_AXES] = {0};
    deg[12] = f->reads; /* knee_l */
    pb_gonio_pack(t->layout, deg, 0, (uint16_t)(f->reads > 5 ? f->reads - 6 : f->reads), NULL, fr);
    memcpy(buf, fr, sizeof fr);
    *c = (pb_usb_completion){PB_USB_XFER_OK, sizeof fr, pb_now_ns()};
    return 1;
}

static int fake_wait(pb_usb_transport *t, int timeout_ms)
{
    fake *f = (fake *)t;
    if (++f->waits != 3) { /* nothing arrives: the wait takes its time (5 ms at most here) */
        int ms = timeout_ms < 5 ? timeout_ms : 5;
        struct timespec ts = {0, (long)ms * 1000000};
        nanosleep(&ts, NULL);
        return 0;
    }
    f->plugged = 1;
    return 1;
}

static void fake_close(pb_usb_transport *t)
{
    ((fake *)t)->closes++;
}

static void fake_destroy(pb_usb_transport *t)
{
    (void)t; /* on the test's stack */
}

static const pb_usb_transport_ops fake_ops = {"usb", fake_open, fake_read, NULL, fake_wait, fake_close, fake_destroy};

typedef struct states {
    char log[2048];
} states;

static void log_state(pb_source *src, pb_source_state st, const char *msg, void *user)
{
    states *s = user;
    (void)src;
    size_t n = strlen(s->log);
    snprintf(s->log + n, sizeof s->log - n, "%s: %s\n", pb_source_state_name(st), msg);
}

static void test_hotplug_reopen(void **state)
{
    (void)state;
    static pb_usb_layout l;
    pb_gonio_layout(&l);
    fake f = {.base = {.ops = &fake_ops, .origin = "usb:1209:0002", .hotplug = 1}, .plugged = 1};
    pb_source *src;
    pb_error err;
    assert_int_equal(pb_usb_source_create(&f.base, &l, NULL, &src, &err), POSE_OK);
    assert_string_equal(src->ops->kind, "usb");
    states st = {{0}};
    src->on_status = log_state;
    src->on_status_user = &st;
    pb_update u;
    for (int i = 0; i < 4; i++)
        assert_int_equal(pb_source_read(src, &u, 100), 1);
    /* frame 5: gone; then 2 waits without arrival (no open tried), the third reports it: reopened, frames again */
    assert_int_equal(pb_source_read(src, &u, 100), 1);
    print_message("%s", st.log);
    assert_int_equal(f.opens, 2);  /* the first open and the one after the arrival: no polling */
    assert_int_equal(f.waits, 3);
    assert_int_equal(f.closes, 1);
    assert_non_null(strstr(st.log, "disconnected: usb:1209:0002: device disconnected; waiting for it to come back (hotplug)\n"
                                   "waiting: usb:1209:0002: reopened on hotplug arrival\nok: usb:1209:0002: receiving\n"));
    const pb_usb_frame_stats *s = pb_usb_source_stats(src);
    assert_int_equal(s->disconnects, 1);
    assert_int_equal(s->lost, 0); /* the counter restarted with the device: resynchronised, not a loss */
    assert_int_equal(pb_usb_source_reopens(src), 1);
    assert_true(fabs(u.values[12] - (1.025 * 6 + 4.1)) < 0.051); /* knee_l's sensor at 6 degrees */
    pb_source_destroy(src);
    /* an arrival whose open fails (permissions not there yet) is retried every reopen_ms until it opens */
    fake h = {.base = {.ops = &fake_ops, .origin = "usb:1209:0002", .hotplug = 1}, .plugged = 1, .deny = 2};
    pb_usb_source_options o = {.reopen_ms = 20};
    assert_int_equal(pb_usb_source_create(&h.base, &l, &o, &src, &err), POSE_OK);
    memset(&st, 0, sizeof st);
    src->on_status = log_state;
    src->on_status_user = &st;
    int64_t t0 = pb_now_ns();
    for (int i = 0; i < 5; i++)
        assert_int_equal(pb_source_read(src, &u, 1000), 1);
    double took = (double)(pb_now_ns() - t0) * 1e-9;
    print_message("%sretried for %.3f s\n", st.log, took);
    assert_int_equal(h.opens, 4); /* the first, the refused one on arrival, one refused retry, the one that works */
    assert_true(took >= 0.038 && took < 0.5); /* two retries 20 ms apart */
    assert_non_null(strstr(st.log, "disconnected: fake: found but not usable: Access denied\nwaiting: usb:1209:0002: reopened\n"));
    pb_source_destroy(src);
    /* not plugged in at open: DISCONNECTED at once, no error */
    fake g = {.base = {.ops = &fake_ops, .origin = "usb:1209:0002", .hotplug = 1}, .plugged = 0};
    assert_int_equal(pb_usb_source_create(&g.base, &l, NULL, &src, &err), POSE_OK);
    assert_int_equal(src->state, PB_SOURCE_DISCONNECTED);
    assert_string_equal(src->message, "fake: not plugged in");
    pb_source_destroy(src);
}

/* The kernel's time stamps wrap at 4096 s: undone; a stamp that goes back is replayed one step later, with a warning. */
static void test_time_wrap_and_jumps(void **state)
{
    (void)state;
    static pb_usb_layout l;
    pb_error err;
    const char *map = "{\"usb\": {\"frame_bytes\": 2, \"channels\": [{\"name\": \"a\", \"byte\": 0, \"size\": 2}]}}";
    assert_int_equal(pb_usb_layout_parse(map, strlen(map), "m", &l, &err), POSE_OK);
    const char *text = "t 4095999000 C Ii:1:002:1 0:1 2 = 0100\n"
                       "t 4095999900 C Ii:1:002:1 0:1 2 = 0200\n"
                       "t 500 C Ii:1:002:1 0:1 2 = 0300\n"
                       "t 400 C Ii:1:002:1 0:1 2 = 0400\n"
                       "t 1500 C Ii:1:002:1 0:1 2 = 0500\n";
    pb_usbmon_capture *cap;
    assert_int_equal(pb_usbmon_parse(text, strlen(text), "cap", &cap, &err), POSE_OK);
    static pb_warnings w;
    memset(&w, 0, sizeof w);
    pb_warnings *old = pb_warnings_install(&w);
    pb_source *src;
    pb_usb_replay_options o = {.as_fast_as_possible = 1};
    assert_int_equal(pb_usb_replay_create(cap, "cap", &l, &o, &src, &err), POSE_OK);
    pb_warnings_install(old);
    assert_int_equal(w.count, 1);
    assert_non_null(strstr(w.text[0], "cap:4: time stamp 400 us goes back 0.000100 s"));
    static const int64_t want[5] = {0, 900000, 1500000, 2100000, 3200000};
    for (int i = 0; i < 5; i++) {
        pb_update u;
        assert_int_equal(pb_source_read(src, &u, 10), 1);
        assert_int_equal(u.t_ns, want[i]);
        assert_true(u.values[0] == (double)(i + 1));
    }
    pb_source_destroy(src);
}

typedef struct unplug_watch {
    int64_t gone_at, back_at;
    char back_msg[256];
} unplug_watch;

static void on_unplug(pb_source *src, pb_source_state st, const char *msg, void *user)
{
    unplug_watch *w = user;
    (void)src;
    if (st == PB_SOURCE_DISCONNECTED && !w->gone_at)
        w->gone_at = pb_now_ns();
    if (st == PB_SOURCE_WAITING && w->gone_at && !w->back_at) {
        w->back_at = pb_now_ns();
        snprintf(w->back_msg, sizeof w->back_msg, "%s", msg);
    }
}

/* At recorded timing the capture's unplug lasts as long as it did (200 ms): disconnected, then back on its
 * (simulated) hotplug arrival with the next transfer. */
static void test_unplug_at_recorded_timing(void **state)
{
    (void)state;
    char p[1024];
    pb_source *src;
    pb_error err;
    pb_usb_replay_options o = {.speed = 1.0};
    assert_int_equal(pb_usb_replay_open(data_path(p, sizeof p, "usb/gonio_reach_faults.usbmon"), box(), &o, &src, &err),
                     POSE_OK);
    unplug_watch w = {0, 0, ""};
    src->on_status = on_unplug;
    src->on_status_user = &w;
    assert_int_equal(pb_source_seek(src, 2950000000LL), 0);
    pb_update u;
    int64_t t = 0;
    while (t < 3250000000LL) {
        int r = pb_source_read(src, &u, 100);
        assert_true(r >= 0);
        if (r == 1)
            t = u.t_ns;
    }
    double gone_s = (double)(w.back_at - w.gone_at) * 1e-9;
    print_message("unplugged for %.3f s of wall time; back: %s\n", gone_s, w.back_msg);
    assert_true(gone_s > 0.18 && gone_s < 0.3);
    assert_non_null(strstr(w.back_msg, "reopened on hotplug arrival"));
    assert_int_equal(src->state, PB_SOURCE_OK);
    pb_source_destroy(src);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_faults_counted_exactly),
        cmocka_unit_test(test_clean_captures),
        cmocka_unit_test(test_timing_and_seek),
        cmocka_unit_test(test_specs_and_live),
        cmocka_unit_test(test_cut_capture),
        cmocka_unit_test(test_hotplug_reopen),
        cmocka_unit_test(test_time_wrap_and_jumps),
        cmocka_unit_test(test_unplug_at_recorded_timing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
