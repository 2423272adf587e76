/* SPDX-License-Identifier: Apache-2.0 */
/* The rotation extraction of the co-rotational FEM, 8 tets at once (Mueller
 * et al. 2016; fem_solve.c's extract_rotation, lane by lane). Shared by the
 * quasi-static solver and the dynamics' kernels, which compile it once per
 * instruction set (the same IEEE operations in every variant). */
#ifndef POSE_FEM_ROT8_H
#define POSE_FEM_ROT8_H

#include "rt_vec.h"

static POSE__INLINE void pose__fem_quat_to_mat8(const pose__v8f q[4], pose__v8f R[9])
{
    const pose__v8f one = V8_SPLAT(1.0f), two = V8_SPLAT(2.0f);
    const pose__v8f x = q[0], y = q[1], z = q[2], s = q[3];
    R[0] = one - two * (y * y + z * z);
    R[1] = two * (x * y - s * z);
    R[2] = two * (x * z + s * y);
    R[3] = two * (x * y + s * z);
    R[4] = one - two * (x * x + z * z);
    R[5] = two * (y * z - s * x);
    R[6] = two * (x * z - s * y);
    R[7] = two * (y * z + s * x);
    R[8] = one - two * (x * x + y * y);
}

/* At most `steps` steps from q toward the rotation maximizing tr(R^T A); a
 * lane that has converged keeps its q (and the R made from it) while the
 * others iterate. */
static inline void pose__fem_rotation8(const pose__v8f A[9], pose__v8f q[4], pose__v8f R[9],
                                       int steps)
{
    for (int it = 0; it < steps; it++) {
        pose__fem_quat_to_mat8(q, R);
        pose__v8f om[3] = {V8_SPLAT(0.0f), V8_SPLAT(0.0f), V8_SPLAT(0.0f)}, d = V8_SPLAT(0.0f);
        for (int c = 0; c < 3; c++) {
            pose__v8f r0 = R[c], r1 = R[3 + c], r2 = R[6 + c];
            pose__v8f a0 = A[c], a1 = A[3 + c], a2 = A[6 + c];
            om[0] += r1 * a2 - r2 * a1;
            om[1] += r2 * a0 - r0 * a2;
            om[2] += r0 * a1 - r1 * a0;
            d += r0 * a0 + r1 * a1 + r2 * a2;
        }
        pose__v8f absd = V8_NEG_WHERE(d, d);
        pose__v8f s = V8_SPLAT(1.0f) / (absd + V8_SPLAT(1e-9f));
        om[0] *= s;
        om[1] *= s;
        om[2] *= s;
        pose__v8f w2 = om[0] * om[0] + om[1] * om[1] + om[2] * om[2];
        pose__v8i go = (pose__v8i)(w2 >= V8_SPLAT(1e-12f));
        if (!V8_ANY(go))
            return;
        pose__v8f a[3] = {V8_SPLAT(0.5f) * om[0], V8_SPLAT(0.5f) * om[1], V8_SPLAT(0.5f) * om[2]};
        pose__v8f n[4] = {
            q[0] + a[0] * q[3] + a[1] * q[2] - a[2] * q[1],
            q[1] - a[0] * q[2] + a[1] * q[3] + a[2] * q[0],
            q[2] + a[0] * q[1] - a[1] * q[0] + a[2] * q[3],
            q[3] - a[0] * q[0] - a[1] * q[1] - a[2] * q[2],
        };
        pose__v8f len = V8_SPLAT(1.0f) / V8_SQRT(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] + n[3] * n[3]);
        for (int k = 0; k < 4; k++) {
            pose__v8f u = n[k] * len;
            q[k] = (pose__v8f)(((pose__v8i)u & go) | ((pose__v8i)q[k] & ~go));
        }
    }
    pose__fem_quat_to_mat8(q, R);
}

#endif /* POSE_FEM_ROT8_H */
