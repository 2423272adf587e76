/* SPDX-License-Identifier: Apache-2.0
 *
 * Tetrahedralize the labelled body. Two backends behind one call:
 *
 *  - PP_TET_LATTICE (built in, Apache-2.0, the default): a balanced octree
 *    over the voxel image, one cell fine along skin and bone boundaries and
 *    up to 2^grading cells wide inside; regular regions are Kuhn
 *    (Freudenthal) cubes (six congruent tets around the main diagonal),
 *    transitions are fans from cell and face centres. grading < 0 gives the
 *    uniform Kuhn lattice. When snapping, the body first grows by one cell
 *    layer (tet_cells.h, pp_cells_dilate) so that the boundary starts
 *    outside the skin, and its vertices are then pulled inward to 0.15
 *    cells outside the skin (a move is backed off when an incident tet
 *    would become a sliver, so nothing inverts, and a vertex held back
 *    stays outside): the mesh encloses the skin (0.4 % of the shared
 *    body's skin vertices outside, under 2 mm, against 69 % and 6.4 mm
 *    when the voxel boundary was snapped both ways) at the price of up to
 *    about a cell of extra soft tissue where moves were refused (+20 % of
 *    volume at 10 mm). Tet labels are the cells' voxel labels. The size
 *    budget picks the cell size.
 *  - PP_TET_TETGEN (only when built with POSE_WITH_TETGEN; AGPL-3+): TetGen
 *    meshes the voxel image's label boundary (outer surface and bone
 *    interfaces) as a PLC with "pq<ratio>a<volume>"; each tet takes the voxel
 *    label at its centroid (exact, the mesh conforms to the voxel faces); the
 *    outer boundary (over the grown cells) is snapped as above. (The skin itself
 *    cannot be the PLC: the shared skin self-intersects in 773 triangle
 *    pairs and the bones are open and cross it.)
 *
 * Labels in pp_tetmesh: 0 soft tissue, j + 1 bone of joint j (voxel label
 * 2 + j). All tets are positively oriented: det[b-a, c-a, d-a] > 0.
 */
#ifndef POSE_PP_TETMESH_H
#define POSE_PP_TETMESH_H

#include "pp_types.h"

#include <pose/pose.h>

#define PP_TET_MAX_GRADING 4
#define PP_TET_DEFAULT_GRADING 3

typedef enum pp_tet_backend {
    PP_TET_DEFAULT = 0, /**< the built-in lattice */
    PP_TET_LATTICE = 1,
    PP_TET_TETGEN = 2
} pp_tet_backend;

/** Options; zero means default for every field. */
typedef struct pp_tet_options {
    pp_tet_backend backend;
    size_t target_vertices;  /**< size budget (vertices). Lattice: picks the cell size, lands
                                  within ~7 %. TetGen: sets -a only; its PLC is the voxel
                                  boundary, whose vertices it keeps, so it ends above the
                                  target (250 k for 150 k on the shared body at 5 mm).
                                  0: lattice cells = voxels, TetGen -a from one vertex per
                                  body voxel */
    double max_radius_edge;  /**< TetGen -q bound (default 1.414) */
    int grading;             /**< lattice: octree levels of coarsening away from skin and bone
                                  boundaries, leaves up to 2^grading cells wide (0: default,
                                  PP_TET_DEFAULT_GRADING; 1..PP_TET_MAX_GRADING; negative:
                                  uniform Kuhn lattice, one cell per leaf everywhere) */
    int no_snap;             /**< keep the staircase of the body cells (not grown). With
                                  grading < 0 every dihedral angle is 45-90 deg and the FEM
                                  Laplacian is an M-matrix; snapping makes obtuse tets, whose
                                  positive entries the weights stage lumps onto the diagonal
                                  (weights_matrix.h), so weights stay in [0, 1] either way */
    int verbose;             /**< TetGen: print its own log to stdout */
} pp_tet_options;

/** Name ("lattice", "tetgen") and parse; parse returns -1 for an unknown name. */
const char *pp_tet_backend_name(pp_tet_backend b);
int pp_tet_backend_parse(const char *name, pp_tet_backend *out);

/** 1 when the backend is compiled in (TetGen needs POSE_WITH_TETGEN). */
int pp_tet_backend_available(pp_tet_backend b);

/**
 * Build the labelled tet mesh of the body.
 * @param vox   labelled image from pp_voxelize
 * @param skin  the skin surface (lattice: snapping target; TetGen: the PLC);
 *              may be NULL for the lattice (no snapping)
 * @param opt   options (NULL for defaults)
 * @param out   the mesh; free with pp_tetmesh_free()
 * @param q     optional: quality figures of the result (tet_quality.h)
 * @return POSE_OK; POSE_ERR_UNSUPPORTED for TetGen in a build without it;
 *         POSE_ERR_INVALID_DATA when the image has no body voxel or TetGen
 *         rejects the surface (message says why); POSE_ERR_OUT_OF_MEMORY.
 */
pose_status pp_tetrahedralize(const pp_voxels *vox, const pp_mesh *skin,
                              const pp_tet_options *opt, pp_tetmesh *out, pp_tet_quality *q,
                              char *err, size_t errlen);

/* Backends (called by pp_tetrahedralize; same contract). */
pose_status pp_tet_lattice(const pp_voxels *vox, const pp_mesh *skin, const pp_tet_options *opt,
                           pp_tetmesh *out, char *err, size_t errlen);
pose_status pp_tet_tetgen(const pp_voxels *vox, const pp_mesh *skin, const pp_tet_options *opt,
                          pp_tetmesh *out, char *err, size_t errlen);

/** Quality figures of any tet mesh (seconds left 0). */
void pp_tet_quality_measure(const pp_tetmesh *t, pp_tet_quality *q);

/** Signed volume of tet i (positive when positively oriented). */
double pp_tet_volume(const pp_tetmesh *t, size_t i);

#endif /* POSE_PP_TETMESH_H */
