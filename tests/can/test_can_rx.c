/* SPDX-License-Identifier: Apache-2.0
 * The SocketCAN receive loop and live source, driven through a socketpair
 * that carries struct can_frame / canfd_frame bytes (no vcan module on CI):
 * bad reads, classic and FD frames, error frames (error-passive, bus-off,
 * restart, overflow), node silence, disconnection, and recording. */
#define _GNU_SOURCE 1
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <sys/time.h>
#include <time.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/errqueue.h>

#include <cmocka.h>

#include "can_rx.h"
#include "can_source.h"
#include "can_record.h"
#include "candump_log.h"
#include "pb_warn.h"

static void send_classic(int fd, canid_t id, const uint8_t *data, uint8_t len)
{
    struct can_frame f;
    memset(&f, 0, sizeof f);
    f.can_id = id;
    f.len = len;
    memcpy(f.data, data, len);
    assert_int_equal(write(fd, &f, sizeof f), (ssize_t)sizeof f);
}

static void send_error(int fd, canid_t cls, uint8_t ctrl, uint8_t tx, uint8_t rx)
{
    uint8_t d[8] = {0, ctrl, 0, 0, 0, 0, tx, rx};
    send_classic(fd, CAN_ERR_FLAG | cls, d, 8);
}

static void test_rx_loop(void **state)
{
    (void)state;
    int sv[2];
    assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
    pb_can_rx rx;
    pb_can_rx_init(&rx, sv[0]);
    pb_can_frame f;
    uint64_t drops;
    /* nothing there: timeout */
    assert_int_equal(pb_can_rx_read(&rx, &f, NULL, &drops, 0), 0);
    /* 5 bytes are no frame */
    assert_int_equal(write(sv[1], "abcde", 5), 5);
    assert_int_equal(pb_can_rx_read(&rx, &f, NULL, &drops, 100), -2);
    assert_int_equal(rx.bad, 1);
    /* classic standard, extended, remote */
    const uint8_t d[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    send_classic(sv[1], 0x123, d, 3);
    send_classic(sv[1], CAN_EFF_FLAG | 0x1ABCDEF0, d, 8);
    send_classic(sv[1], CAN_RTR_FLAG | 0x7FF, d, 2);
    const int64_t before = pb_can_mono_ns();
    assert_int_equal(pb_can_rx_read(&rx, &f, NULL, &drops, 100), 1);
    assert_int_equal(f.id, 0x123);
    assert_int_equal(f.flags, 0);
    assert_int_equal(f.len, 3);
    assert_int_equal(f.data[2], 3);
    /* no kernel stamp over a socketpair: the monotonic clock at reception */
    assert_true(f.t_ns >= before - 1000000 && f.t_ns <= pb_can_mono_ns());
    assert_int_equal(pb_can_rx_read(&rx, &f, NULL, &drops, 100), 1);
    assert_int_equal(f.flags, PB_CAN_EXT);
    assert_int_equal(f.id, 0x1ABCDEF0);
    assert_int_equal(f.len, 8);
    assert_int_equal(pb_can_rx_read(&rx, &f, NULL, &drops, 100), 1);
    assert_int_equal(f.flags, PB_CAN_RTR);
    assert_int_equal(f.len, 0);
    /* FD frame with BRS, 16 bytes */
    struct canfd_frame fd;
    memset(&fd, 0, sizeof fd);
    fd.can_id = 0x321;
    fd.len = 16;
    fd.flags = CANFD_BRS;
    for (int i = 0; i < 16; i++)
        fd.data[i] = (uint8_t)(0xA0 + i);
    assert_int_equal(write(sv[1], &fd, sizeof fd), (ssize_t)sizeof fd);
    assert_int_equal(pb_can_rx_read(&rx, &f, NULL, &drops, 100), 1);
    assert_int_equal(f.flags, PB_CAN_FD | PB_CAN_BRS);
    assert_int_equal(f.len, 16);
    assert_int_equal(f.data[15], 0xAF);
    /* error frame */
    send_error(sv[1], CAN_ERR_BUSOFF, 0, 0, 0);
    assert_int_equal(pb_can_rx_read(&rx, &f, NULL, &drops, 100), 1);
    assert_int_equal(f.flags, PB_CAN_ERR);
    assert_int_equal(f.id, PB_CAN_ERR_BUSOFF);
    assert_int_equal(rx.frames, 5);
    /* peer gone */
    close(sv[1]);
    errno = 0;
    assert_int_equal(pb_can_rx_read(&rx, &f, NULL, &drops, 100), -1);
    assert_int_equal(errno, EPIPE);
    close(sv[0]);
}

/* Ancillary data as the kernel attaches it to a raw CAN socket's frames
 * (a socketpair cannot carry these), built by hand. */
static void test_ancillary(void **state)
{
    (void)state;
    pb_can_rx rx;
    pb_can_rx_init(&rx, -1);
    union {
        char buf[CMSG_SPACE(sizeof(struct scm_timestamping)) + CMSG_SPACE(sizeof(struct timeval)) +
                 CMSG_SPACE(sizeof(uint32_t))];
        struct cmsghdr align;
    } ctrl;
    struct msghdr msg;
    const int64_t real = 1763769600LL * 1000000000;
    uint64_t drops;
    /* SO_TIMESTAMP (microseconds) and an overflow counter of 5 */
    memset(&ctrl, 0, sizeof ctrl);
    memset(&msg, 0, sizeof msg);
    msg.msg_control = ctrl.buf;
    msg.msg_controllen = CMSG_SPACE(sizeof(struct timeval)) + CMSG_SPACE(sizeof(uint32_t));
    struct cmsghdr *c = CMSG_FIRSTHDR(&msg);
    c->cmsg_level = SOL_SOCKET;
    c->cmsg_type = SO_TIMESTAMP;
    c->cmsg_len = CMSG_LEN(sizeof(struct timeval));
    struct timeval tv = {1763769599, 250000};
    memcpy(CMSG_DATA(c), &tv, sizeof tv);
    c = CMSG_NXTHDR(&msg, c);
    c->cmsg_level = SOL_SOCKET;
    c->cmsg_type = SO_RXQ_OVFL;
    c->cmsg_len = CMSG_LEN(sizeof(uint32_t));
    uint32_t ovfl = 5;
    memcpy(CMSG_DATA(c), &ovfl, sizeof ovfl);
    assert_true(pb_can_rx_ancillary(&rx, &msg, real, &drops) == 1763769599250000000LL);
    assert_int_equal(drops, 5);
    /* the counter is cumulative: 12 means 7 more; then it wraps past 2^32 */
    ovfl = 12;
    memcpy(CMSG_DATA(c), &ovfl, sizeof ovfl);
    pb_can_rx_ancillary(&rx, &msg, real, &drops);
    assert_int_equal(drops, 7);
    rx.ovfl = 0xFFFFFFFEu;
    ovfl = 3;
    memcpy(CMSG_DATA(c), &ovfl, sizeof ovfl);
    pb_can_rx_ancillary(&rx, &msg, real, &drops);
    assert_int_equal(drops, 5);
    assert_int_equal(rx.dropped, 17);
    /* SO_TIMESTAMPING: a hardware stamp on the wall clock wins, one on the adapter's own clock does not */
    memset(&ctrl, 0, sizeof ctrl);
    msg.msg_controllen = CMSG_SPACE(sizeof(struct scm_timestamping));
    c = CMSG_FIRSTHDR(&msg);
    c->cmsg_level = SOL_SOCKET;
    c->cmsg_type = SO_TIMESTAMPING;
    c->cmsg_len = CMSG_LEN(sizeof(struct scm_timestamping));
    struct scm_timestamping ts;
    memset(&ts, 0, sizeof ts);
    ts.ts[0].tv_sec = 1763769599;
    ts.ts[0].tv_nsec = 900000000;
    ts.ts[2].tv_sec = 1763769599;
    ts.ts[2].tv_nsec = 899999000;
    memcpy(CMSG_DATA(c), &ts, sizeof ts);
    assert_true(pb_can_rx_ancillary(&rx, &msg, real, &drops) == 1763769599899999000LL);
    assert_int_equal(drops, 0);
    ts.ts[2].tv_sec = 12345; /* adapter uptime */
    memcpy(CMSG_DATA(c), &ts, sizeof ts);
    assert_true(pb_can_rx_ancillary(&rx, &msg, real, &drops) == 1763769599900000000LL);
    /* nothing attached */
    msg.msg_controllen = 0;
    assert_true(pb_can_rx_ancillary(&rx, &msg, real, &drops) == 0);
}

typedef struct status_log {
    int count;
    pb_source_state states[64];
    char messages[64][256];
} status_log;

static void on_status(pb_source *src, pb_source_state st, const char *msg, void *user)
{
    (void)src;
    status_log *l = user;
    if (l->count < 64) {
        l->states[l->count] = st;
        snprintf(l->messages[l->count], sizeof l->messages[0], "%s", msg);
        l->count++;
    }
}

static pb_can_bus *rig_bus(const char *const *channels, size_t n)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/can-rig/goniometer_rig.dbc", getenv("POSE_DATA_DIR"));
    pb_can_bus *bus = NULL;
    pb_error err;
    if (pb_can_bus_create(path, &bus, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(pb_can_bus_select(bus, channels, n), POSE_OK);
    return bus;
}

/* KNEE_L flex 4|14@1- (0.02): 90 deg = raw 4500 = 0x1194 -> 40 19 01 */
static const uint8_t KNEE_90[8] = {0x40, 0x19, 0x01, 0, 0, 0, 0, 0};
/* 45 deg = raw 2250 = 0x8CA -> 0x8CA0 -> A0 8C 00 */
static const uint8_t KNEE_45[8] = {0xA0, 0x8C, 0x00, 0, 0, 0, 0, 0};

static void test_live_source(void **state)
{
    (void)state;
    int sv[2];
    assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
    const char *const want[] = {"KNEE_L.flex"};
    pb_source *src = NULL;
    pb_error err;
    const char *tmp = getenv("POSE_TEST_TMP");
    char rec[1024];
    snprintf(rec, sizeof rec, "%s/live_record.log", tmp);
    pb_can_live_options opt = {.record_path = rec};
    if (pb_can_live_open_fd(sv[0], 1, "pair", rig_bus(want, 1), &opt, &src, &err) != POSE_OK)
        fail_msg("%s", err.message);
    status_log log = {0};
    src->on_status = on_status;
    src->on_status_user = &log;
    assert_string_equal(src->ops->kind, "can");
    assert_int_equal(src->channel_count, 1);
    assert_string_equal(src->channels[0].name, "KNEE_L.flex");
    assert_string_equal(src->channels[0].unit, "deg");
    assert_int_equal(src->state, PB_SOURCE_WAITING);
    pb_can_decoder *dec = pb_can_source_decoder(src);
    assert_non_null(dec);
    size_t nf;
    const pb_can_filter *filters = pb_can_decoder_filters(dec, &nf);
    assert_int_equal(nf, 1); /* kernel filter: only KNEE_L's identifier */
    assert_int_equal(filters[0].id, 0x10B);
    assert_int_equal(filters[0].mask, 0x7FF);

    pb_update u;
    send_classic(sv[1], 0x10B, KNEE_90, 8);
    assert_int_equal(src->ops->read(src, &u, 200), 1);
    assert_int_equal(u.count, 1);
    assert_int_equal(u.channels[0], 0);
    assert_true(u.values[0] == 90.0);
    assert_int_equal(src->state, PB_SOURCE_OK);
    /* frames of other nodes are not channels: counted, not delivered */
    send_classic(sv[1], 0x10C, KNEE_90, 8);
    assert_int_equal(src->ops->read(src, &u, 20), 0);
    assert_int_equal(pb_can_decoder_stats(dec)->unknown, 1);
    /* silence beyond 3 cycles (15 ms): stale, value held by the consumer */
    assert_int_equal(src->ops->read(src, &u, 40), 0);
    assert_int_equal(src->state, PB_SOURCE_STALE);
    assert_non_null(strstr(src->message, "KNEE_L silent"));
    send_classic(sv[1], 0x10B, KNEE_45, 8);
    assert_int_equal(src->ops->read(src, &u, 200), 1);
    assert_true(u.values[0] == 45.0);
    assert_int_equal(src->state, PB_SOURCE_OK);
    /* error-passive: fault, data still flows */
    send_error(sv[1], CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE, 8, 130);
    send_classic(sv[1], 0x10B, KNEE_90, 8);
    assert_int_equal(src->ops->read(src, &u, 200), 1);
    assert_int_equal(src->state, PB_SOURCE_FAULT);
    assert_string_equal(src->message, "CAN controller error-passive (tx errors 8, rx errors 130)");
    /* bus-off */
    send_error(sv[1], CAN_ERR_BUSOFF, 0, 0, 0);
    assert_int_equal(src->ops->read(src, &u, 10), 0);
    assert_int_equal(src->state, PB_SOURCE_FAULT);
    assert_non_null(strstr(src->message, "bus-off"));
    assert_int_equal(pb_can_decoder_stats(dec)->bus, PB_CAN_BUS_OFF);
    /* restart, then data again: ok */
    send_error(sv[1], CAN_ERR_RESTARTED, 0, 0, 0);
    send_classic(sv[1], 0x10B, KNEE_45, 8);
    assert_int_equal(src->ops->read(src, &u, 200), 1);
    assert_int_equal(src->state, PB_SOURCE_OK);
    /* controller rx overflow counts as dropped frames */
    send_error(sv[1], CAN_ERR_CRTL, CAN_ERR_CRTL_RX_OVERFLOW, 0, 0);
    send_classic(sv[1], 0x10B, KNEE_45, 8);
    assert_int_equal(src->ops->read(src, &u, 200), 1);
    assert_int_equal(pb_can_decoder_stats(dec)->dropped, 1);
    assert_int_equal(pb_can_decoder_stats(dec)->error_frames, 4);
    /* a short frame: 2 bytes cannot hold bits 4..17 */
    send_classic(sv[1], 0x10B, KNEE_45, 2);
    assert_int_equal(src->ops->read(src, &u, 20), 0);
    assert_int_equal(pb_can_decoder_stats(dec)->short_frames, 1);
    /* garbage on the descriptor is skipped */
    assert_int_equal(write(sv[1], "xyz", 3), 3);
    send_classic(sv[1], 0x10B, KNEE_90, 8);
    assert_int_equal(src->ops->read(src, &u, 200), 1);
    /* the other end goes away */
    close(sv[1]);
    assert_int_equal(src->ops->read(src, &u, 200), -1);
    assert_int_equal(src->state, PB_SOURCE_DISCONNECTED);
    assert_int_equal(src->ops->read(src, &u, 0), -1); /* no interface to reopen */

    /* the states went WAITING -> OK -> STALE -> OK -> FAULT ... -> DISCONNECTED */
    assert_true(log.count >= 6);
    assert_int_equal(log.states[0], PB_SOURCE_OK);
    assert_int_equal(log.states[1], PB_SOURCE_STALE);
    assert_int_equal(log.states[2], PB_SOURCE_OK);
    assert_int_equal(log.states[3], PB_SOURCE_FAULT);
    assert_int_equal(log.states[log.count - 1], PB_SOURCE_DISCONNECTED);
    pb_source_destroy(src);

    /* everything received was recorded, readable as a candump log */
    pb_candump_reader r;
    char e[256];
    assert_int_equal(pb_candump_open(&r, rec, e, sizeof e), 0);
    pb_can_frame f;
    size_t n = 0, errors = 0;
    while (pb_candump_next(&r, &f) == 1) {
        n++;
        errors += (f.flags & PB_CAN_ERR) != 0;
    }
    assert_int_equal(r.bad_lines, 0);
    assert_int_equal(n, 12);
    assert_int_equal(errors, 4);
    pb_candump_close(&r);
}

static size_t count_log_frames(const char *path, size_t *bad)
{
    pb_candump_reader r;
    char e[256];
    if (pb_candump_open(&r, path, e, sizeof e) != 0)
        return 0;
    pb_can_frame f;
    size_t n = 0;
    while (pb_candump_next(&r, &f) == 1)
        n++;
    *bad = r.bad_lines;
    pb_candump_close(&r);
    return n;
}

/* can-record's loop, SIGKILLed while recording: every frame it received is
 * in the file as a whole line (it used to keep them in stdio's buffer: a
 * kill at 2 s lost ~70 frames and cut the last line). */
static void test_record_survives_kill(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/killed.log", getenv("POSE_TEST_TMP"));
    int sv[2];
    assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
    FILE *out = fopen(path, "w");
    assert_non_null(out);
    const pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0) {
        close(sv[1]);
        pb_can_record_result res;
        pb_error err;
        _exit(pb_can_record_run(sv[0], "can0", out, NULL, &res, &err) == 0 ? 0 : 1);
    }
    fclose(out);
    close(sv[0]);
    enum { FRAMES = 100 };
    for (int i = 0; i < FRAMES; i++)
        send_classic(sv[1], 0x10B, KNEE_90, 8);
    /* wait until the child has taken every frame off the socket */
    size_t n = 0, bad = 0;
    for (int tries = 0; tries < 500 && n < FRAMES; tries++) {
        usleep(10000);
        n = count_log_frames(path, &bad);
    }
    kill(child, SIGKILL);
    int status;
    assert_int_equal(waitpid(child, &status, 0), child);
    assert_true(WIFSIGNALED(status));
    close(sv[1]);
    n = count_log_frames(path, &bad);
    assert_int_equal(n, FRAMES);
    assert_int_equal(bad, 0);
}

/* An interface-name stand-in: the opener hands out socketpair ends, so the
 * live source's reopen path (interface gone, reopened by name every 500 ms)
 * runs without a vcan module. */
static int stand_in_fds[2] = {-1, -1}; /* our ends of the current pair; [1] sends */
static int stand_in_opens;

static int stand_in_open(const char *iface, const pb_can_filter *filters, size_t count, pb_error *err)
{
    (void)filters;
    (void)count;
    if (strcmp(iface, "vcan-test") != 0) {
        pb_fail(err, POSE_ERR_IO, "CAN: interface %s: No such device", iface);
        return -1;
    }
    int sv[2];
    if (socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv) != 0)
        return -1;
    stand_in_fds[1] = sv[1];
    stand_in_opens++;
    return sv[0];
}

static void test_reopen_by_name(void **state)
{
    (void)state;
    pb_can_set_socket_opener(stand_in_open);
    const char *const want[] = {"KNEE_L.flex"};
    pb_source *src = NULL;
    pb_error err;
    if (pb_can_live_open("vcan-test", rig_bus(want, 1), NULL, &src, &err) != POSE_OK)
        fail_msg("%s", err.message);
    status_log log = {0};
    src->on_status = on_status;
    src->on_status_user = &log;
    assert_int_equal(stand_in_opens, 1);
    pb_update u;
    send_classic(stand_in_fds[1], 0x10B, KNEE_90, 8);
    assert_int_equal(src->ops->read(src, &u, 200), 1);
    assert_true(u.values[0] == 90.0);
    /* the interface goes away: disconnected, and it says it is reopening */
    close(stand_in_fds[1]);
    assert_int_equal(src->ops->read(src, &u, 200), -1);
    assert_int_equal(src->state, PB_SOURCE_DISCONNECTED);
    assert_non_null(strstr(src->message, "vcan-test"));
    assert_non_null(strstr(src->message, "reopening"));
    /* not before 500 ms */
    assert_int_equal(src->ops->read(src, &u, 0), -1);
    assert_int_equal(stand_in_opens, 1);
    usleep(550000);
    /* reopened by name (then stale: the node has been silent), and data flows again */
    assert_int_equal(src->ops->read(src, &u, 0), 0);
    assert_int_equal(stand_in_opens, 2);
    int reopened = 0;
    for (int i = 0; i < log.count; i++)
        reopened |= log.states[i] == PB_SOURCE_WAITING && strcmp(log.messages[i], "vcan-test reopened") == 0;
    assert_true(reopened);
    send_classic(stand_in_fds[1], 0x10B, KNEE_45, 8);
    assert_int_equal(src->ops->read(src, &u, 200), 1);
    assert_true(u.values[0] == 45.0);
    assert_int_equal(src->state, PB_SOURCE_OK);
    pb_source_destroy(src);
    close(stand_in_fds[1]);
    pb_can_set_socket_opener(NULL);
    /* the real opener is back */
    assert_int_equal(pb_can_socket_open("vcan-test", NULL, 0, &err), -1);
}

/* A candump log whose stamps jump an hour ahead, then back: replayed at
 * recorded timing, it used to stall for the hour (can-monitor --log went
 * silent) and take the step back without a word. The jumps are taken out,
 * each a warning naming the line, and the replay goes on in order. */
static void test_replay_time_jumps(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/jumps.log", getenv("POSE_TEST_TMP"));
    FILE *w = fopen(path, "w");
    assert_non_null(w);
    fputs("(1.000000) can0 10B#4019010000000000\n"
          "(1.010000) can0 10B#4019010000000000\n"
          "(3601.010000) can0 10B#4019010000000000\n"
          "(3601.020000) can0 10B#4019010000000000\n"
          "(3600.000000) can0 10B#4019010000000000\n"
          "(3600.010000) can0 10B#4019010000000000\n",
          w);
    fclose(w);
    const char *const want[] = {"KNEE_L.flex"};
    pb_source *src = NULL;
    pb_error err;
    pb_warnings warnings;
    memset(&warnings, 0, sizeof warnings);
    pb_warnings *prev = pb_warnings_install(&warnings);
    if (pb_candump_replay_open(path, rig_bus(want, 1), NULL, &src, &err) != POSE_OK)
        fail_msg("%s", err.message);
    const int64_t t0 = pb_can_mono_ns();
    pb_update u;
    for (int i = 0; i < 6; i++) {
        assert_int_equal(src->ops->read(src, &u, 500), 1);
        assert_int_equal(u.t_ns, i * 10000000LL);
    }
    assert_int_equal(src->ops->read(src, &u, 100), -1);
    assert_int_equal(src->state, PB_SOURCE_ENDED);
    assert_true(pb_can_mono_ns() - t0 < 1000000000);
    pb_warnings_install(prev);
    assert_int_equal(warnings.count, 2);
    if (!strstr(warnings.text[0], "jumps.log:3: time stamp jumps ahead 3600.000 s"))
        fail_msg("%s", warnings.text[0]);
    if (!strstr(warnings.text[1], "jumps.log:5: time stamp goes back 1.020 s"))
        fail_msg("%s", warnings.text[1]);
    pb_source_destroy(src);
}

static void test_open_errors(void **state)
{
    (void)state;
    pb_source *src = (pb_source *)1;
    pb_error err;
    const char *const nope[] = {"KNEE_L.nope"};
    assert_int_equal(pb_can_live_open_fd(-1, 0, "x", rig_bus(nope, 1), NULL, &src, &err), POSE_ERR_NOT_FOUND);
    assert_null(src);
    assert_non_null(strstr(err.message, "KNEE_L.nope"));
    /* no such interface (or no CAN support at all in this kernel) */
    assert_int_equal(pb_can_live_open("nocan9", rig_bus(NULL, 0), NULL, &src, &err), POSE_ERR_IO);
    assert_null(src);
    assert_int_equal(pb_can_socket_open("an-interface-name-too-long", NULL, 0, &err), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_open_errors),
        cmocka_unit_test(test_ancillary),
        cmocka_unit_test(test_rx_loop),
        cmocka_unit_test(test_live_source),
        cmocka_unit_test(test_record_survives_kill),
        cmocka_unit_test(test_reopen_by_name),
        cmocka_unit_test(test_replay_time_jumps),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
