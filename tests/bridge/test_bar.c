/* SPDX-License-Identifier: Apache-2.0
 * The right arm of CMU 131_01 onto the synthetic four-bone bar
 * (pose_synth_bar) through bridge/maps/cmu131_arm_to_bar.json: the bar's
 * segments point where the arm's segments point, and libpose, given the
 * bridge's joint targets, places the bar's joints where the bridge's own FK
 * does (same conventions for pose_set_joint and pose_set_root). */
#include "bridge_apply.h"
#include "bridge_test.h"
#include "mapping.h"
#include "pb_math.h"
#include "pose_synth.h"

static void test_arm_onto_bar(void **state)
{
    (void)state;
    pose_synth_bar_options bo = {.cor = POSE_SYNTH_COR_NONE};
    pose_synth_rig *bar;
    assert_int_equal(pose_synth_bar(&bo, &bar), POSE_OK);
    const pose_rig_desc *desc = pose_synth_desc(bar);
    pb_rig_skel *skel;
    pb_error err;
    if (pb_rig_skel_from_desc(desc->joints, desc->joint_count, &skel, &err) != POSE_OK)
        fail_msg("%s", err.message);
    assert_int_equal(skel->joint_count, 4);
    char p[1024];
    pb_clip *clip;
    pb_mapping *map;
    pb_retarget *rt;
    if (pb_bvh_load(BT_DATA(p, "mocap/cmu-bvh/131_01.bvh"), &clip, &err) != POSE_OK ||
        pb_mapping_load(BT_MAP(p, "cmu131_arm_to_bar.json"), &map, &err) != POSE_OK ||
        pb_retarget_create(map, clip, skel, &rt, &err) != POSE_OK)
        fail_msg("%s", err.message);
    pose_rig *rig;
    pose_state *st;
    assert_int_equal(pose_rig_create(desc, NULL, &rig), POSE_OK);
    assert_int_equal(pose_state_create(rig, &st), POSE_OK);
    static const char *ARM[4] = {"RightShoulder", "RightElbow", "rhand", "RFingers"};
    int cj[4];
    for (int i = 0; i < 4; i++)
        cj[i] = pb_clip_find_joint(clip, ARM[i]);
    size_t n = (size_t)clip->joint_count;
    double *s = malloc(n * 14 * sizeof(double));
    double (*lq)[4] = (double (*)[4])s, (*lt)[3] = (double (*)[3])(s + 4 * n);
    double (*cq)[4] = (double (*)[4])(s + 7 * n), (*cp)[3] = (double (*)[3])(s + 11 * n);
    double rq[4][4], rp[4][3];
    pb_pose pose;
    assert_int_equal(pb_pose_init(&pose, 4), 0);
    double worst_dir = 0, worst_pos = 0;
    int clamped_frames = 0, frames = 0;
    for (size_t f = 0; f < clip->frame_count; f += 50, frames++) {
        pb_clip_local(clip, pb_clip_frame(clip, f), lq, lt);
        pb_retarget_apply(rt, (const double (*)[4])lq, (const double (*)[3])lt, 0, &pose);
        pb_clip_world(clip, (const double (*)[4])lq, (const double (*)[3])lt, cq, cp);
        pb_rig_skel_fk(skel, (const float (*)[4])pose.q, NULL, NULL, rq, rp);
        for (int i = 0; i < 3; i++) {
            double vr[3] = {rp[i + 1][0] - rp[i][0], rp[i + 1][1] - rp[i][1], rp[i + 1][2] - rp[i][2]};
            /* clip axes (Y up, Z forward) -> rig axes (Z up, X forward): (x,y,z) -> (z,x,y) */
            double vc[3] = {cp[cj[i + 1]][2] - cp[cj[i]][2], cp[cj[i + 1]][0] - cp[cj[i]][0],
                            cp[cj[i + 1]][1] - cp[cj[i]][1]};
            double x[3] = {vr[1] * vc[2] - vr[2] * vc[1], vr[2] * vc[0] - vr[0] * vc[2], vr[0] * vc[1] - vr[1] * vc[0]};
            double ang = atan2(pb_vec_len(x), vr[0] * vc[0] + vr[1] * vc[1] + vr[2] * vc[2]) * PB_RAD2DEG;
            if (ang > 0.001)
                fail_msg("frame %zu: bar segment %d is %g deg off the arm's %s->%s (%g %g %g vs %g %g %g)", f, i, ang, ARM[i], ARM[i + 1], vr[0], vr[1], vr[2], vc[0], vc[1], vc[2]);
            worst_dir = ang > worst_dir ? ang : worst_dir;
        }
        /* the same targets through libpose (frames where the bar's joint
         * limits clamp a target are compared for direction only) */
        int clamped = 0;
        assert_int_equal(pb_pose_apply_to_state(&pose, st, &clamped), POSE_OK);
        assert_true(pose_apply(st) >= 0);
        if (clamped) {
            clamped_frames++;
            continue;
        }
        for (int j = 0; j < 4; j++) {
            pose_transform w;
            assert_int_equal(pose_joint_world(st, j, &w), POSE_OK);
            for (int k = 0; k < 3; k++) {
                double e = fabs(w.translation[k] - rp[j][k]);
                if (e > 1e-5)
                    fail_msg("frame %zu joint %d: libpose %g, bridge FK %g", f, j, w.translation[k], rp[j][k]);
                worst_pos = e > worst_pos ? e : worst_pos;
            }
        }
    }
    print_message("arm onto bar: worst direction %.2g deg, libpose vs bridge FK %.2g (%d of %d frames clamped)\n",
                  worst_dir, worst_pos, clamped_frames, frames);
    assert_true(clamped_frames < frames / 2);
    pb_pose_free(&pose);
    free(s);
    pose_state_free(st);
    pose_rig_free(rig);
    pb_retarget_free(rt);
    pb_mapping_free(map);
    pb_clip_free(clip);
    pb_rig_skel_free(skel);
    pose_synth_free(bar);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_arm_onto_bar),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
