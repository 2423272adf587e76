/* SPDX-License-Identifier: Apache-2.0
 *
 * The tet mesh as a VTK XML unstructured grid (.vtu, ASCII) for ParaView:
 * cell data "label" (0 soft, j + 1 bone of joint j), point data
 * "dominant_joint", and one weight field per joint named after it. ASCII
 * keeps the writer tiny and the file diffable; it is an inspection aid.
 */
#include "bake_pipeline.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

int pp_write_vtu(const char *path, const pp_tetmesh *m, const pp_weights *w, const pp_template *t,
                 char *err, size_t err_size)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        snprintf(err, err_size, "%s: cannot create: %s", path, strerror(errno));
        return POSE_ERR_IO;
    }
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
               "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n"
               "<Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n",
            m->vertex_count, m->tet_count);
    fprintf(f, "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (size_t v = 0; v < m->vertex_count; v++)
        fprintf(f, "%.7g %.7g %.7g\n", m->positions[3 * v], m->positions[3 * v + 1],
                m->positions[3 * v + 2]);
    fprintf(f, "</DataArray></Points>\n<Cells>\n"
               "<DataArray type=\"UInt32\" Name=\"connectivity\" format=\"ascii\">\n");
    for (size_t c = 0; c < m->tet_count; c++)
        fprintf(f, "%u %u %u %u\n", m->tets[4 * c], m->tets[4 * c + 1], m->tets[4 * c + 2],
                m->tets[4 * c + 3]);
    fprintf(f, "</DataArray>\n<DataArray type=\"UInt64\" Name=\"offsets\" format=\"ascii\">\n");
    for (size_t c = 0; c < m->tet_count; c++)
        fprintf(f, "%zu\n", 4 * (c + 1));
    fprintf(f, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for (size_t c = 0; c < m->tet_count; c++)
        fputs("10\n", f); /* VTK_TETRA */
    fprintf(f, "</DataArray>\n</Cells>\n<CellData Scalars=\"label\">\n"
               "<DataArray type=\"UInt16\" Name=\"label\" format=\"ascii\">\n");
    for (size_t c = 0; c < m->tet_count; c++)
        fprintf(f, "%u\n", m->labels[c]);
    fprintf(f, "</DataArray>\n</CellData>\n<PointData Scalars=\"dominant_joint\">\n"
               "<DataArray type=\"UInt16\" Name=\"dominant_joint\" format=\"ascii\">\n");
    for (size_t v = 0; v < m->vertex_count; v++)
        fprintf(f, "%u\n", w->joints[v * w->influences]);
    fprintf(f, "</DataArray>\n");
    for (size_t j = 0; j < t->joint_count; j++) {
        fprintf(f, "<DataArray type=\"Float32\" Name=\"w_%s\" format=\"ascii\">\n", t->joints[j].name);
        for (size_t v = 0; v < m->vertex_count; v++)
            fprintf(f, "%.6g\n", pp_weights_get(w, v, (unsigned)j));
        fprintf(f, "</DataArray>\n");
    }
    fprintf(f, "</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    if (ferror(f) | (fclose(f) != 0)) {
        snprintf(err, err_size, "%s: write error", path);
        remove(path);
        return POSE_ERR_IO;
    }
    return POSE_OK;
}
