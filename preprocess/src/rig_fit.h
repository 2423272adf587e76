/* SPDX-License-Identifier: Apache-2.0
 *
 * Rigging: fit a skeleton template to the patient's bone meshes. Joint
 * centres come from the anatomy (design §2):
 *  - ball:  least-squares sphere through the articular contact region, the
 *           child bone's vertices within contact_mm of the parent bone
 *           (or the parent's, or both, per the template's "fit");
 *  - hinge: axis = the contact region's principal direction closest to the
 *           template's "axis"; centre = least-squares circle of the region
 *           projected along that axis (a cylinder fit with known axis);
 *  - spine: centroid of the contact region of both vertebra groups;
 *  - root / fixed: segment centroid / the template's "at".
 * Frames: y = the flexion axis (fitted for hinges, else the template axis),
 * z = the segment direction (towards the child joint, signed like the
 * template's "up"), x = y × z; orthonormalized.
 */
#ifndef POSE_PP_RIG_FIT_H
#define POSE_PP_RIG_FIT_H

#include "pp_types.h"
#include "template_json.h"

typedef struct pp_fit_joint {
    double centre[3];     /**< model space, metres */
    double frame[3][3];   /**< columns x, y, z (frame[row][col]) */
    float rotation[4];    /**< the frame as a quaternion {x, y, z, w} */
    double residual_mm;   /**< RMS distance of the region to the fitted sphere/circle */
    double radius_mm;     /**< fitted sphere/circle radius (0 for spine/root/fixed) */
    size_t contact_points;
} pp_fit_joint;

/**
 * Fit every joint of `t`. Bones are found by pp_mesh.name. out has
 * t->joint_count entries. Fails (naming the joint and the bone) when a
 * template bone is missing, a contact region is empty or too small for its
 * rule, or a fit degenerates.
 */
int pp_rig_fit(const pp_template *t, const pp_mesh *bones, size_t bone_count, pp_fit_joint *out,
               char *err, size_t err_size);

/* Building blocks (exposed for tests). */

/** Least-squares sphere (algebraic start, geometric Gauss-Newton refinement).
 *  Returns 0 when the points do not determine a sphere. */
int pp_fit_sphere(const double *pts, size_t n, double centre[3], double *radius, double *rms);
/** Least-squares circle of the points projected along unit `axis`; centre
 *  placed at the points' mean coordinate along the axis. Returns 0 if degenerate. */
int pp_fit_circle(const double *pts, size_t n, const double axis[3], double centre[3],
                  double *radius, double *rms);
/** Unit quaternion {x,y,z,w} of a rotation matrix m[row][col]. */
void pp_quat_from_matrix(const double m[3][3], float q[4]);

#endif /* POSE_PP_RIG_FIT_H */
