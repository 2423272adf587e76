/* SPDX-License-Identifier: Apache-2.0
 * The triple-buffer hand-off: single-thread semantics, then a writer and a
 * concurrent reader hammering it: every pose the reader sees must be whole
 * (all its values from one publish) and never older than the previous one.
 * Run under TSan (label `threads`). */
#include <pthread.h>
#include <stdatomic.h>

#include "bridge_test.h"
#include "handoff.h"

enum { JOINTS = 31, PUBLISHES = 200000 };

static void fill(pb_pose *p, uint64_t k)
{
    float v = (float)(k % 1000003);
    for (int j = 0; j < p->joint_count; j++)
        for (int c = 0; c < 4; c++)
            p->q[j][c] = v + (float)c;
    p->root_t[0] = p->root_t[1] = p->root_t[2] = v;
    p->frame = (long)k;
}

static int whole(const pb_pose *p)
{
    float v = (float)(p->frame % 1000003);
    for (int j = 0; j < p->joint_count; j++)
        for (int c = 0; c < 4; c++)
            if (p->q[j][c] != v + (float)c)
                return 0;
    return p->root_t[0] == v && p->root_t[2] == v;
}

static void test_single_thread(void **state)
{
    (void)state;
    pb_handoff h;
    assert_int_equal(pb_handoff_init(&h, JOINTS), 0);
    int fresh = 1;
    const pb_pose *p = pb_handoff_latest(&h, &fresh);
    assert_false(fresh);
    assert_int_equal(p->seq, 0);
    fill(pb_handoff_back(&h), 7);
    pb_handoff_publish(&h);
    fill(pb_handoff_back(&h), 8);
    pb_handoff_publish(&h);
    p = pb_handoff_latest(&h, &fresh);
    assert_true(fresh);
    assert_int_equal(p->frame, 8); /* the newest, older ones skipped */
    assert_int_equal(p->seq, 2);
    p = pb_handoff_latest(&h, &fresh);
    assert_false(fresh);
    assert_int_equal(p->frame, 8);
    /* the writer's slot is never the reader's */
    assert_ptr_not_equal(pb_handoff_back(&h), p);
    pb_handoff_free(&h);
}

typedef struct shared {
    pb_handoff h;
    atomic_int done;
} shared;

static void *writer(void *arg)
{
    shared *s = arg;
    for (uint64_t k = 1; k <= PUBLISHES; k++) {
        fill(pb_handoff_back(&s->h), k);
        pb_handoff_publish(&s->h);
    }
    atomic_store(&s->done, 1);
    return NULL;
}

static void test_concurrent_reader_never_tears(void **state)
{
    (void)state;
    shared s;
    assert_int_equal(pb_handoff_init(&s.h, JOINTS), 0);
    atomic_init(&s.done, 0);
    pthread_t t;
    assert_int_equal(pthread_create(&t, NULL, writer, &s), 0);
    uint64_t last = 0, reads = 0, fresh_reads = 0;
    for (;;) {
        int done = atomic_load(&s.done);
        int fresh;
        const pb_pose *p = pb_handoff_latest(&s.h, &fresh);
        reads++;
        if (p->seq) {
            if (!whole(p))
                fail_msg("torn pose at seq %llu", (unsigned long long)p->seq);
            if (p->seq < last)
                fail_msg("went back from seq %llu to %llu", (unsigned long long)last, (unsigned long long)p->seq);
            assert_int_equal((uint64_t)p->frame, p->seq);
            fresh_reads += fresh;
            last = p->seq;
        }
        if (done && last == PUBLISHES)
            break;
        if (done && !fresh && reads > 10 * (uint64_t)PUBLISHES)
            fail_msg("the last publish never arrived (seq %llu)", (unsigned long long)last);
    }
    pthread_join(t, NULL);
    print_message("%llu reads, %llu fresh poses of %d published\n", (unsigned long long)reads,
                  (unsigned long long)fresh_reads, PUBLISHES);
    pb_handoff_free(&s.h);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_single_thread),
        cmocka_unit_test(test_concurrent_reader_never_tears),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
