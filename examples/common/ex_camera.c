/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_camera.h"

#include <math.h>
#include <string.h>

static const float ex_deg = 3.14159265358979f / 180.0f;

static void ex_cross(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void ex_normalize(float v[3])
{
    float n = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (n > 0.0f)
        for (int i = 0; i < 3; i++)
            v[i] /= n;
}

void ex_camera_frame(ex_camera *cam, const float bmin[3], const float bmax[3], float aspect)
{
    float ext[3];
    for (int i = 0; i < 3; i++) {
        cam->target[i] = 0.5f * (bmin[i] + bmax[i]);
        ext[i] = bmax[i] - bmin[i];
    }
    cam->radius = 0.5f * sqrtf(ext[0] * ext[0] + ext[1] * ext[1] + ext[2] * ext[2]);
    if (!(cam->radius > 0.0f))
        cam->radius = 1.0f;
    /* Look across the thin horizontal axis so the wide one faces the camera. */
    cam->azimuth_deg = (ext[0] <= ext[1] ? 0.0f : 90.0f) + 25.0f;
    cam->elevation_deg = 15.0f;
    cam->fov_deg = 35.0f;
    ex_camera_fit(cam, bmin, bmax, aspect);
}

void ex_camera_fit(ex_camera *cam, const float bmin[3], const float bmax[3], float aspect)
{
    /* The nearest distance at which all 8 corners of the box are in view,
     * corner by corner in the camera's frame (tighter than a bounding sphere). */
    float v[16], tan_y = tanf(0.5f * cam->fov_deg * ex_deg), tan_x = tan_y * (aspect > 0.0f ? aspect : 1.0f);
    float d = 0.0f;
    cam->distance = 1.0f;
    ex_camera_view(cam, v);
    for (int c = 0; c < 8; c++) {
        float p[3], q[3];
        for (int i = 0; i < 3; i++)
            p[i] = ((c >> i) & 1 ? bmax[i] : bmin[i]) - cam->target[i];
        for (int r = 0; r < 3; r++) /* rotate into camera axes: right, up, towards the camera */
            q[r] = v[r] * p[0] + v[4 + r] * p[1] + v[8 + r] * p[2];
        float need = q[2] + fmaxf(fabsf(q[0]) / tan_x, fabsf(q[1]) / tan_y);
        d = fmaxf(d, need);
    }
    cam->distance = fmaxf(d * 1.08f, cam->radius * 0.1f); /* a small margin around the model */
}

void ex_camera_eye(const ex_camera *cam, float eye[3])
{
    float az = cam->azimuth_deg * ex_deg, el = cam->elevation_deg * ex_deg;
    eye[0] = cam->target[0] + cam->distance * cosf(el) * cosf(az);
    eye[1] = cam->target[1] + cam->distance * cosf(el) * sinf(az);
    eye[2] = cam->target[2] + cam->distance * sinf(el);
}

void ex_camera_view(const ex_camera *cam, float m[16])
{
    float eye[3], f[3], s[3], u[3];
    const float up[3] = {0.0f, 0.0f, 1.0f};
    ex_camera_eye(cam, eye);
    for (int i = 0; i < 3; i++)
        f[i] = cam->target[i] - eye[i];
    ex_normalize(f);
    ex_cross(f, up, s);
    ex_normalize(s);
    ex_cross(s, f, u);
    memset(m, 0, 16 * sizeof *m);
    for (int i = 0; i < 3; i++) {
        m[4 * i + 0] = s[i];
        m[4 * i + 1] = u[i];
        m[4 * i + 2] = -f[i];
    }
    m[12] = -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    m[13] = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    m[14] = f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2];
    m[15] = 1.0f;
}

void ex_camera_projection(const ex_camera *cam, float aspect, float m[16])
{
    float n = cam->distance - 2.0f * cam->radius, fa = cam->distance + 2.0f * cam->radius;
    if (n < cam->radius * 0.01f)
        n = cam->radius * 0.01f;
    float t = 1.0f / tanf(0.5f * cam->fov_deg * ex_deg);
    memset(m, 0, 16 * sizeof *m);
    m[0] = t / aspect;
    m[5] = t;
    m[10] = (fa + n) / (n - fa);
    m[11] = -1.0f;
    m[14] = 2.0f * fa * n / (n - fa);
}

void ex_camera_pan(ex_camera *cam, float dx, float dy)
{
    float v[16];
    ex_camera_view(cam, v);
    for (int i = 0; i < 3; i++) /* rows 0 and 1 of the view matrix: right and up */
        cam->target[i] += cam->distance * (dx * v[4 * i + 0] + dy * v[4 * i + 1]);
}
