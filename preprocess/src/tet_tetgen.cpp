/* SPDX-License-Identifier: Apache-2.0
 *
 * TetGen backend (AGPL-3+, compiled only with POSE_WITH_TETGEN and linked
 * only into pose-bake). The one C++ file of the project: an extern "C" shim.
 *
 * The PLC is the label boundary of the voxel image: one quad facet per
 * voxel face between two different labels (marker 1 on the body's outer boundary, 2 on
 * bone/soft and bone/bone interfaces). Why not the skin and bone meshes
 * themselves: the shared skin has 773 pairs of self-intersecting triangles
 * and the bones are open and cross each other and the skin
 * (data/anatomy/README.md), which TetGen rejects (and libtet 1.5 then
 * crashes while freeing its pools); the voxel boundary never intersects
 * itself. TetGen runs with "pzq<ratio>a<volume>", each tet takes the label
 * of the voxel at its centroid (exact, since the mesh conforms to the voxel
 * faces), and the outer boundary vertices are snapped onto the skin exactly
 * as in the lattice backend (tet_snap.c).
 */
#define TETLIBRARY
#include <tetgen.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

extern "C" {
#include "tet_cells.h"
#include "tet_snap.h"
#include "tetmesh.h"
#include "voxelize.h"
}

namespace {

struct shim_error {
    pose_status status;
    char text[400];
};

/* Label of the cell holding point p (outside beyond the grid). */
uint16_t cell_label(const pp_cells *L, const double p[3])
{
    int i[3];
    for (int k = 0; k < 3; k++)
        i[k] = (int)std::floor((p[k] - L->o[k]) / L->c);
    return pp_cells_at(L, i[0], i[1], i[2]);
}

/* Fill `in` with the label-boundary PLC of the cell grid. */
void fill_plc(const pp_cells *v, tetgenio &in)
{
    size_t cx = (size_t)v->m[0] + 1, cy = (size_t)v->m[1] + 1, cz = (size_t)v->m[2] + 1;
    std::vector<int> id(cx * cy * cz, -1);
    std::vector<int> quads;   /* 4 corner ids per facet */
    std::vector<int> markers;
    int npts = 0;
    /* For each axis, faces between voxel (i - 1) and voxel i along it. */
    for (int a = 0; a < 3; a++) {
        int u = (a + 1) % 3, w = (a + 2) % 3;
        const int *n = v->m;
        int p[3];
        for (p[a] = 0; p[a] <= n[a]; p[a]++)
            for (p[w] = 0; p[w] < n[w]; p[w]++)
                for (p[u] = 0; p[u] < n[u]; p[u]++) {
                    int q[3] = {p[0], p[1], p[2]};
                    q[a]--;
                    uint16_t l0 = pp_cells_at(v, q[0], q[1], q[2]), l1 = pp_cells_at(v, p[0], p[1], p[2]);
                    if (l0 == l1)
                        continue;
                    static const int du[4] = {0, 1, 1, 0}, dw[4] = {0, 0, 1, 1};
                    for (int k = 0; k < 4; k++) {
                        int c[3] = {p[0], p[1], p[2]};
                        c[u] += du[k];
                        c[w] += dw[k];
                        size_t g = (size_t)c[0] + cx * ((size_t)c[1] + cy * (size_t)c[2]);
                        if (id[g] < 0)
                            id[g] = npts++;
                        quads.push_back(id[g]);
                    }
                    markers.push_back(l0 == PP_VOXEL_OUTSIDE || l1 == PP_VOXEL_OUTSIDE ? 1 : 2);
                }
    }
    in.firstnumber = 0;
    in.numberofpoints = npts;
    in.pointlist = new REAL[3 * (size_t)npts];
    for (size_t z = 0; z < cz; z++)
        for (size_t y = 0; y < cy; y++)
            for (size_t x = 0; x < cx; x++) {
                int i = id[x + cx * (y + cy * z)];
                if (i < 0)
                    continue;
                in.pointlist[3 * (size_t)i] = v->o[0] + (double)x * v->c;
                in.pointlist[3 * (size_t)i + 1] = v->o[1] + (double)y * v->c;
                in.pointlist[3 * (size_t)i + 2] = v->o[2] + (double)z * v->c;
            }
    size_t nf = markers.size();
    in.numberoffacets = (int)nf;
    in.facetlist = new tetgenio::facet[nf];
    in.facetmarkerlist = new int[nf];
    for (size_t f = 0; f < nf; f++) {
        tetgenio::facet *fc = &in.facetlist[f];
        tetgenio::init(fc);
        fc->numberofpolygons = 1;
        fc->polygonlist = new tetgenio::polygon[1];
        tetgenio::polygon *pg = &fc->polygonlist[0];
        tetgenio::init(pg);
        pg->numberofvertices = 4;
        pg->vertexlist = new int[4];
        for (int k = 0; k < 4; k++)
            pg->vertexlist[k] = quads[4 * f + k];
        in.facetmarkerlist[f] = markers[f];
    }
}

pose_status run(const pp_voxels *vox, const pp_mesh *skin, const pp_tet_options *opt,
                pp_tetmesh *out, shim_error *e)
{
    size_t body = 0, nvox = (size_t)vox->nx * vox->ny * vox->nz;
    for (size_t i = 0; i < nvox; i++)
        body += vox->labels[i] != PP_VOXEL_OUTSIDE;
    if (body == 0) {
        e->status = POSE_ERR_INVALID_DATA;
        snprintf(e->text, sizeof e->text, "tetrahedralize (tetgen): the voxel image has no body voxel");
        return e->status;
    }
    double h = vox->spacing, volume = (double)body * h * h * h;
    /* Budget: only the interior size (-a, twice the mean tet volume of a
     * mesh with ~6 tets per vertex) follows the target; the PLC stays at
     * voxel resolution. Coarser cells were tried and made it worse: on the
     * shared body at 5 mm with a 150 k target, cells 1x and 1.5x the lattice
     * size gave 296 k and 437 k vertices against 250 k for voxels, because
     * -q refines hard around the short edges of coarsely resampled bones. */
    size_t target = opt->target_vertices ? opt->target_vertices : body;
    double c = h;
    double max_vol = 2.0 * volume / (6.0 * (double)target);
    double ratio = opt->max_radius_edge > 0.0 ? opt->max_radius_edge : 1.414;

    pp_cells cells = {};
    if (pp_cells_label(vox, c, &cells) != POSE_OK ||
        (skin && !opt->no_snap && pp_cells_dilate(&cells) != POSE_OK)) {
        pp_cells_free(&cells);
        e->status = POSE_ERR_OUT_OF_MEMORY;
        snprintf(e->text, sizeof e->text, "tetrahedralize (tetgen): out of memory");
        return e->status;
    }
    struct cells_guard {
        pp_cells *c;
        ~cells_guard() { pp_cells_free(c); }
    } guard = {&cells};
    tetgenio in, res;
    fill_plc(&cells, in);
    char sw[128];
    snprintf(sw, sizeof sw, "pzq%.4ga%.6e%s", ratio, max_vol, opt->verbose ? "V" : "Q");
    try {
        tetrahedralize(sw, &in, &res, NULL, NULL);
    } catch (int code) {
        e->status = code == 1 ? POSE_ERR_OUT_OF_MEMORY : POSE_ERR_INVALID_DATA;
        snprintf(e->text, sizeof e->text, "tetrahedralize (tetgen -%s): TetGen failed with code %d",
                 sw, code);
        return e->status;
    }
    if (res.numberoftetrahedra <= 0 || res.numberofpoints <= 0) {
        e->status = POSE_ERR_INVALID_DATA;
        snprintf(e->text, sizeof e->text, "tetrahedralize (tetgen): TetGen returned no tets");
        return e->status;
    }
    size_t nv = (size_t)res.numberofpoints, nt = (size_t)res.numberoftetrahedra;
    out->positions = (float *)malloc(3 * nv * sizeof(float));
    out->tets = (uint32_t *)malloc(4 * nt * sizeof(uint32_t));
    out->labels = (uint16_t *)malloc(nt * sizeof(uint16_t));
    if (!out->positions || !out->tets || !out->labels) {
        pp_tetmesh_free(out);
        e->status = POSE_ERR_OUT_OF_MEMORY;
        snprintf(e->text, sizeof e->text, "tetrahedralize (tetgen): out of memory");
        return e->status;
    }
    out->vertex_count = nv;
    out->tet_count = nt;
    for (size_t i = 0; i < 3 * nv; i++)
        out->positions[i] = (float)res.pointlist[i];
    std::vector<uint8_t> near_bone(nv, 0);
    int corners = res.numberofcorners;
    for (size_t t = 0; t < nt; t++) {
        uint32_t *tt = out->tets + 4 * t;
        for (int k = 0; k < 4; k++)
            tt[k] = (uint32_t)res.tetrahedronlist[(size_t)corners * t + k];
        const REAL *p[4];
        for (int k = 0; k < 4; k++)
            p[k] = res.pointlist + 3 * (size_t)tt[k];
        double a[3], b[3], c[3], ctr[3];
        for (int k = 0; k < 3; k++) {
            a[k] = p[1][k] - p[0][k];
            b[k] = p[2][k] - p[0][k];
            c[k] = p[3][k] - p[0][k];
            ctr[k] = 0.25 * (p[0][k] + p[1][k] + p[2][k] + p[3][k]);
        }
        double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                     a[2] * (b[0] * c[1] - b[1] * c[0]);
        if (det < 0.0) {
            uint32_t s = tt[2];
            tt[2] = tt[3];
            tt[3] = s;
        }
        uint16_t l = cell_label(&cells, ctr);
        out->labels[t] = l >= PP_VOXEL_BONE0 ? (uint16_t)(l - 1) : 0;
        if (l >= PP_VOXEL_BONE0)
            for (int k = 0; k < 4; k++)
                near_bone[tt[k]] = 1;
    }
    if (skin && !opt->no_snap) {
        /* Outer faces lie on voxel faces: the outward side is the one whose
         * voxel is outside, probed half a voxel away from the face centre. */
        std::vector<int> sum(3 * nv, 0);
        for (int f = 0; f < res.numberoftrifaces; f++) {
            if (res.trifacemarkerlist && res.trifacemarkerlist[f] != 1)
                continue;
            const int *tri = res.trifacelist + 3 * (size_t)f;
            const REAL *q0 = res.pointlist + 3 * (size_t)tri[0], *q1 = res.pointlist + 3 * (size_t)tri[1],
                       *q2 = res.pointlist + 3 * (size_t)tri[2];
            double u[3], w[3], n[3];
            for (int k = 0; k < 3; k++) {
                u[k] = q1[k] - q0[k];
                w[k] = q2[k] - q0[k];
            }
            n[0] = u[1] * w[2] - u[2] * w[1];
            n[1] = u[2] * w[0] - u[0] * w[2];
            n[2] = u[0] * w[1] - u[1] * w[0];
            int axis = 0;
            for (int k = 1; k < 3; k++)
                if (std::fabs(n[k]) > std::fabs(n[axis]))
                    axis = k;
            double probe[3];
            for (int k = 0; k < 3; k++)
                probe[k] = (q0[k] + q1[k] + q2[k]) / 3.0;
            probe[axis] += 0.5 * c;
            int sign = cell_label(&cells, probe) == PP_VOXEL_OUTSIDE ? 1 : -1;
            for (int k = 0; k < 3; k++)
                sum[3 * (size_t)tri[k] + axis] += sign;
        }
        std::vector<int8_t> dir(3 * nv, 0);
        for (size_t i = 0; i < nv; i++)
            if (!near_bone[i])
                for (int k = 0; k < 3; k++)
                    dir[3 * i + k] = (int8_t)(sum[3 * i + k] > 0 ? 1 : sum[3 * i + k] < 0 ? -1 : 0);
        size_t moved = 0;
        pose_status s = pp_tet_snap(out, skin, dir.data(), (float)(PP_SNAP_REACH * c),
                                    (float)(PP_SNAP_MARGIN * c), &moved);
        if (s != POSE_OK) {
            pp_tetmesh_free(out);
            e->status = s;
            snprintf(e->text, sizeof e->text, "tetrahedralize (tetgen): out of memory while snapping");
            return s;
        }
    }
    return POSE_OK;
}

} // namespace

extern "C" pose_status pp_tet_tetgen(const pp_voxels *vox, const pp_mesh *skin,
                                     const pp_tet_options *opt, pp_tetmesh *out, char *err,
                                     size_t errlen)
{
    if (!vox || !out)
        return POSE_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    pp_tet_options def = {};
    if (!opt)
        opt = &def;
    shim_error e = {POSE_OK, {0}};
    try {
        run(vox, skin, opt, out, &e);
    } catch (const std::bad_alloc &) {
        pp_tetmesh_free(out);
        e.status = POSE_ERR_OUT_OF_MEMORY;
        snprintf(e.text, sizeof e.text, "tetrahedralize (tetgen): out of memory");
    }
    if (e.status != POSE_OK && err && errlen)
        snprintf(err, errlen, "%s", e.text);
    return e.status;
}
