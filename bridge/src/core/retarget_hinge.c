/* SPDX-License-Identifier: Apache-2.0 */
#include "retarget_hinge.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pb_math.h"

enum { HINGE_MAX_SAMPLES = 2000 };
#define HINGE_MIN_RMS_RAD (3.0 / PB_RAD2DEG) /* below this a joint hardly moves: no axis to speak of */
#define HINGE_MIN_SHARE 0.9

/* Largest eigenvalue and its unit eigenvector of a symmetric 3x3 matrix
 * (cyclic Jacobi: a few sweeps reach double precision for 3x3). */
static double top_eigen(double m[3][3], double vec[3])
{
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int sweep = 0; sweep < 32; sweep++) {
        double off = fabs(m[0][1]) + fabs(m[0][2]) + fabs(m[1][2]);
        if (off < 1e-15 * (fabs(m[0][0]) + fabs(m[1][1]) + fabs(m[2][2])) + 1e-300)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (fabs(m[p][q]) < 1e-300)
                    continue;
                double th = 0.5 * atan2(2.0 * m[p][q], m[q][q] - m[p][p]);
                double c = cos(th), s = sin(th);
                for (int k = 0; k < 3; k++) { /* m = J^T m J, columns then rows */
                    double a = m[k][p], b = m[k][q];
                    m[k][p] = c * a - s * b;
                    m[k][q] = s * a + c * b;
                }
                for (int k = 0; k < 3; k++) {
                    double a = m[p][k], b = m[q][k];
                    m[p][k] = c * a - s * b;
                    m[q][k] = s * a + c * b;
                }
                for (int k = 0; k < 3; k++) {
                    double a = v[k][p], b = v[k][q];
                    v[k][p] = c * a - s * b;
                    v[k][q] = s * a + c * b;
                }
            }
    }
    int best = 0;
    for (int k = 1; k < 3; k++)
        if (m[k][k] > m[best][best])
            best = k;
    for (int k = 0; k < 3; k++)
        vec[k] = v[k][best];
    return m[best][best];
}

int pb_clip_hinge_axes(const pb_clip *clip, const double *ref_values, const double (*ref_wq)[4], double (*axis)[3],
                       int *ok)
{
    size_t n = (size_t)(clip->joint_count > 0 ? clip->joint_count : 1);
    memset(ok, 0, n * sizeof *ok);
    memset(axis, 0, n * sizeof *axis);
    double *buf = calloc(n * 11, sizeof *buf);
    if (!buf)
        return -1;
    double (*lq)[4] = (double (*)[4])buf, (*lt)[3] = (double (*)[3])(buf + 4 * n);
    double (*ref_inv)[4] = (double (*)[4])(buf + 7 * n); /* local reference rotations, inverted */
    double *acc = calloc(n * 9, sizeof *acc); /* per joint: sum of r r^T of the rotation vectors r */
    if (!acc) {
        free(buf);
        return -1;
    }
    pb_clip_local(clip, ref_values, lq, lt);
    for (size_t c = 0; c < n; c++)
        pb_quat_conj(lq[c], ref_inv[c]);
    size_t step = clip->frame_count / HINGE_MAX_SAMPLES + 1, samples = 0;
    for (size_t f = 0; f < clip->frame_count; f += step, samples++) {
        pb_clip_local(clip, pb_clip_frame(clip, f), lq, lt);
        for (int c = 0; c < clip->joint_count; c++) {
            if (clip->joints[c].parent < 0)
                continue; /* the root's turning is the body's heading, not a joint's */
            double e[4];
            pb_quat_mul(lq[c], ref_inv[c], e); /* turn since the reference, in the parent's frame */
            if (e[3] < 0)
                for (int k = 0; k < 4; k++)
                    e[k] = -e[k];
            double s = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            if (s < 1e-12)
                continue;
            double ang = 2.0 * atan2(s, e[3]), r[3] = {e[0] / s * ang, e[1] / s * ang, e[2] / s * ang};
            double *a = acc + 9 * (size_t)c;
            for (int i = 0; i < 3; i++)
                for (int k = 0; k < 3; k++)
                    a[3 * i + k] += r[i] * r[k];
        }
    }
    for (int c = 0; c < clip->joint_count && samples > 0; c++) {
        int p = clip->joints[c].parent;
        const double *a = acc + 9 * (size_t)c;
        double tr = a[0] + a[4] + a[8];
        if (p < 0 || tr / (double)samples < HINGE_MIN_RMS_RAD * HINGE_MIN_RMS_RAD)
            continue;
        double m[3][3], v[3];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                m[i][k] = a[3 * i + k];
        double top = top_eigen(m, v);
        if (top < HINGE_MIN_SHARE * tr)
            continue;
        pb_quat_rotate(ref_wq[p], v, axis[c]); /* parent frame -> clip world at the reference */
        double l = pb_vec_len(axis[c]);
        for (int k = 0; k < 3; k++)
            axis[c][k] /= l;
        ok[c] = 1;
    }
    free(acc);
    free(buf);
    return 0;
}

int pb_clip_mean_local(const pb_clip *clip, const int *want, double (*mean)[4])
{
    size_t n = (size_t)(clip->joint_count > 0 ? clip->joint_count : 1);
    double *buf = calloc(n * 7, sizeof *buf);
    if (!buf)
        return -1;
    double (*lq)[4] = (double (*)[4])buf, (*lt)[3] = (double (*)[3])(buf + 4 * n);
    memset(mean, 0, n * sizeof *mean);
    size_t step = clip->frame_count / HINGE_MAX_SAMPLES + 1;
    for (size_t f = 0; f < clip->frame_count; f += step) {
        pb_clip_local(clip, pb_clip_frame(clip, f), lq, lt);
        for (int c = 0; c < clip->joint_count; c++) {
            if (!want[c])
                continue;
            /* q and -q are one rotation: add each on the side of the sum so far */
            double s = pb_quat_dot(mean[c], lq[c]) < 0 ? -1.0 : 1.0;
            for (int k = 0; k < 4; k++)
                mean[c][k] += s * lq[c][k];
        }
    }
    for (int c = 0; c < clip->joint_count; c++)
        if (want[c])
            pb_quat_normalize(mean[c]);
    free(buf);
    return 0;
}
