/* SPDX-License-Identifier: Apache-2.0
 *
 * An orbit camera around a target point, Z up (the rigs' convention: pose-bake
 * writes metres, Z up, the body facing +X). Matrices are column-major float[16]
 * as glLoadMatrixf takes them.
 */
#ifndef POSE_EX_CAMERA_H
#define POSE_EX_CAMERA_H

typedef struct ex_camera {
    float target[3];
    float distance;
    float azimuth_deg;   /* 0 = camera on the +X side of the target, 90 = on +Y */
    float elevation_deg; /* above the horizontal plane through the target */
    float fov_deg;       /* vertical field of view */
    float radius;        /* radius of the framed bounds, for the near/far planes */
} ex_camera;

/**
 * Frame an axis-aligned box: look at its centre from the side where it is
 * widest (the front of a body facing +X, the side of a bar), slightly from
 * above and to the side, at the distance that fits it in view for `aspect`.
 */
void ex_camera_frame(ex_camera *cam, const float bmin[3], const float bmax[3], float aspect);

/** Keep the direction, set the distance so the box just fits in view for `aspect`. */
void ex_camera_fit(ex_camera *cam, const float bmin[3], const float bmax[3], float aspect);

/** Camera position in model space. */
void ex_camera_eye(const ex_camera *cam, float eye[3]);

void ex_camera_view(const ex_camera *cam, float m[16]);
void ex_camera_projection(const ex_camera *cam, float aspect, float m[16]);

/** Move the target in the view plane by (dx, dy) in units of the distance. */
void ex_camera_pan(ex_camera *cam, float dx, float dy);

#endif
