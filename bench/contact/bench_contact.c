/* SPDX-License-Identifier: Apache-2.0 */
/*
 * bench_contact: the cost of collision detection (pose/contact.h) per frame
 * on a baked rig, at issue 13's poses (tests/contact/contact_body.h), with
 * the detection's threads at 1 and 2: pose_contact_detect after one
 * pose_apply, repeated. Printed per frame: wall milliseconds, and CPU
 * milliseconds of the whole process divided by the threads (CPU time per
 * thread: the figure that holds on a machine shared with other work, where
 * wall time waits for the cores), and the counts.
 * Then the response (pose_set_contact_response): pose_apply with it off
 * and on, per frame, on 1 and 2 threads: the difference is what the push
 * adds, for a pose held (the frames after the first leave the clusters
 * nothing moved near as they were: contact_quiet.h) and for a pose new at
 * every frame (every cluster searched: what a moving body costs at most).
 * Usage: bench_contact RIG [--seconds S] [--response-only]
 *   (S per pose and thread count, default 1; --response-only skips the
 *   detection's timing)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_common.h"
#include "contact_body.h"
#include "contact_push.h"
#include "pose/contact.h"
#include "pose/pose.h"
#include "state_internal.h"

/* Wall and CPU seconds per pose_apply of `st`, repeated for `seconds`. */
static void time_apply(pose_state *st, double seconds, double *wall, double *cpu)
{
    int frames = 0;
    const double w0 = bench_now(), c0 = bench_cpu_seconds();
    do {
        pose_apply(st);
        frames++;
    } while (bench_now() - w0 < seconds || frames < 3);
    *wall = (bench_now() - w0) / frames;
    *cpu = (bench_cpu_seconds() - c0) / frames;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Blocks of frames with the response off and on, interleaved, so that both
 * see the same load on a shared machine; min and median per frame. */
#define BLOCKS 7

static int bench_response(pose_rig *rig, double seconds)
{
    for (int threads = 1; threads <= 2; threads++) {
        pose_state_options so = {.size = sizeof so, .threads = threads, .method = POSE_DQS};
        pose_state *st;
        if (pose_state_create_ex(rig, &so, &st) != POSE_OK) {
            fprintf(stderr, "%s\n", pose_last_error());
            return 1;
        }
        pose_contact_response on = {.size = sizeof on, .enabled = 1}, off = {.size = sizeof off};
        pose_contact_response_stats rs = {.size = sizeof rs};
        if (pose_set_contact_response(st, &on) != POSE_OK)
            return 1;
        pose_get_contact_response_stats(st, &rs);
        printf("response, DQS, %d thread%s (built in %.0f ms); CPU per thread per frame, min/median of %d "
               "interleaved blocks\n", threads, threads > 1 ? "s" : "", 1e3 * rs.build_seconds, BLOCKS);
        for (size_t p = 0; p < CONTACT_POSE_COUNT; p++) {
            double w_off[BLOCKS], c_off[BLOCKS], w_on[BLOCKS], c_on[BLOCKS], add[BLOCKS], add_new[BLOCKS], unused;
            contact_pose_set(rig, st, &contact_poses[p]);
            for (int b = 0; b < BLOCKS; b++) {
                double c_new;
                pose_set_contact_response(st, &off);
                time_apply(st, seconds / BLOCKS, &w_off[b], &c_off[b]);
                pose_set_contact_response(st, &on);
                time_apply(st, seconds / BLOCKS, &w_on[b], &c_on[b]);
                st->push->quiet_off = 1;
                time_apply(st, seconds / BLOCKS, &unused, &c_new);
                st->push->quiet_off = 0;
                add[b] = c_on[b] - c_off[b];
                add_new[b] = c_new - c_off[b];
            }
            pose_get_contact_response_stats(st, &rs);
            qsort(c_off, BLOCKS, sizeof(double), cmp_double);
            qsort(c_on, BLOCKS, sizeof(double), cmp_double);
            qsort(add, BLOCKS, sizeof(double), cmp_double);
            qsort(add_new, BLOCKS, sizeof(double), cmp_double);
            qsort(w_off, BLOCKS, sizeof(double), cmp_double);
            qsort(w_on, BLOCKS, sizeof(double), cmp_double);
            const double k = 1e3 / threads;
            printf("  %-18s: pose_apply off %5.2f/%5.2f, on %5.2f/%5.2f ms; added %5.2f/%5.2f ms held, "
                   "%5.2f ms median a new pose every frame (wall median %.2f -> %.2f held); %zu skin vertices "
                   "pushed\n", contact_poses[p].label, k * c_off[0], k * c_off[BLOCKS / 2], k * c_on[0],
                   k * c_on[BLOCKS / 2], k * (c_on[0] - c_off[0]), k * add[BLOCKS / 2], k * add_new[BLOCKS / 2],
                   1e3 * w_off[BLOCKS / 2], 1e3 * w_on[BLOCKS / 2], rs.pushed);
        }
        pose_state_free(st);
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s RIG [--seconds S] [--response-only]\n", argv[0]);
        return 2;
    }
    double seconds = 1.0;
    int detection = 1;
    for (int i = 2; i < argc; i++) {
        if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc)
            seconds = atof(argv[++i]);
        else if (strcmp(argv[i], "--response-only") == 0)
            detection = 0;
        else {
            fprintf(stderr, "usage: %s RIG [--seconds S] [--response-only]\n", argv[0]);
            return 2;
        }
    }
    pose_rig *rig;
    pose_state *st;
    if (pose_rig_load(argv[1], &rig) != POSE_OK || pose_state_create(rig, &st) != POSE_OK) {
        fprintf(stderr, "%s\n", pose_last_error());
        return 1;
    }
    for (int threads = 1; threads <= 2 && detection; threads++) {
        pose_contact_options o = {.size = sizeof o, .threads = threads};
        pose_contact *c;
        const double t0 = bench_now();
        if (pose_contact_create(rig, &o, &c) != POSE_OK) {
            fprintf(stderr, "%s\n", pose_last_error());
            return 1;
        }
        printf("%d thread%s (index built in %.0f ms)\n", threads, threads > 1 ? "s" : "",
               1e3 * (bench_now() - t0));
        for (size_t p = 0; p < CONTACT_POSE_COUNT; p++) {
            if (contact_pose_set(rig, st, &contact_poses[p]) != 0 || pose_apply(st) != POSE_OK) {
                fprintf(stderr, "pose '%s': %s\n", contact_poses[p].label, pose_last_error());
                return 1;
            }
            pose_contact_counts n = {.size = sizeof n};
            int frames = 0;
            const double w0 = bench_now(), c0 = bench_cpu_seconds();
            do {
                pose_contact_detect(c, st, &n);
                frames++;
            } while (bench_now() - w0 < seconds || frames < 3);
            const double wall = (bench_now() - w0) / frames, cpu = (bench_cpu_seconds() - c0) / frames;
            printf("  %-18s: %7.2f ms wall, %7.2f ms CPU per thread per frame; %zu skin pairs, %zu skin "
                   "vertices in bone, %zu bone vertices out of skin, %zu pairs of two bones\n", contact_poses[p].label,
                   1e3 * wall, 1e3 * cpu / threads, n.skin_pairs, n.skin_in_bone, n.bone_out_of_skin, n.bone_pairs);
        }
        pose_contact_free(c);
    }
    pose_state_free(st);
    const int r = bench_response(rig, seconds);
    pose_rig_free(rig);
    return r;
}
