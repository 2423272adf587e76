/* SPDX-License-Identifier: Apache-2.0
 * Postures of the bundled body in clinical angles, asserted on joint
 * positions: the same checks run on the bake's own numbers (test_clinical.c,
 * forward kinematics written out from pose.h's convention) and through
 * libpose on a baked rig (test_clinical_body.c). Model frame of data/anatomy:
 * Z up, facing +X, left = +Y. */
#ifndef POSE_TEST_CLINICAL_CHECKS_H
#define POSE_TEST_CLINICAL_CHECKS_H

/** A posable body. */
typedef struct posture_api {
    void *ctx;
    void (*rest)(void *ctx);    /**< every joint at rest (the T-pose) */
    void (*neutral)(void *ctx); /**< every joint at clinical 0 */
    /** One joint's clinical angles {flexion, abduction, rotation}, others unchanged. */
    void (*set)(void *ctx, const char *joint, float flex, float abd, float rot);
    /** A joint centre in model space for the current posture. */
    void (*where)(void *ctx, const char *joint, double xyz[3]);
} posture_api;

/** Angle in degrees between the segment from joint a to joint b and `dir`. */
double clinical_segment_angle(const posture_api *api, const char *a, const char *b, const double dir[3]);

/** Every posture check of the brief (cmocka assertions), printing the measured angles. */
void clinical_check_postures(const posture_api *api);

#endif /* POSE_TEST_CLINICAL_CHECKS_H */
