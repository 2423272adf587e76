/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_export.h"

#include <ctype.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

static FILE *ex_open(const char *path, char *err, size_t err_size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        snprintf(err, err_size, "%s: cannot create: %s", path, strerror(errno));
    return f;
}

/* Closes f; a failed write anywhere shows up in ferror or fclose. */
static int ex_close(FILE *f, const char *path, char *err, size_t err_size)
{
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        snprintf(err, err_size, "%s: write failed: %s", path, strerror(errno ? errno : EIO));
        return -1;
    }
    return 0;
}

void ex_export_file_name(const char *name, char *out, size_t out_size)
{
    size_t i = 0;
    for (; name[i] && i + 1 < out_size; i++) {
        unsigned char c = (unsigned char)name[i];
        out[i] = (char)(isalnum(c) || c == '-' || c == '_' || c == '.' ? c : '_');
    }
    out[i] = '\0';
    if (i == 0 || out[0] == '.')
        snprintf(out, out_size, "tissue");
}

int ex_export_obj(const pose_state *st, const char *path, char *err, size_t err_size)
{
    const pose_rig *rig = pose_state_rig(st);
    FILE *f = ex_open(path, err, err_size);
    if (!f)
        return -1;
    fprintf(f, "# posed tissues written by pose %s\n", pose_version_string());
    size_t base = 1; /* OBJ indices are 1-based and global to the file */
    for (size_t t = 0; t < pose_rig_tissue_count(rig); t++) {
        pose_tissue_info ti;
        size_t n;
        if (pose_rig_tissue_info(rig, (int)t, &ti) < 0)
            continue;
        const float *p = pose_tissue_positions(st, (int)t, &n);
        const float *nr = pose_tissue_normals(st, (int)t, &n);
        fprintf(f, "o %s\n", ti.name);
        for (size_t v = 0; v < n; v++)
            fprintf(f, "v %.6g %.6g %.6g\n", p[3 * v], p[3 * v + 1], p[3 * v + 2]);
        for (size_t v = 0; v < n; v++)
            fprintf(f, "vn %.5g %.5g %.5g\n", nr[3 * v], nr[3 * v + 1], nr[3 * v + 2]);
        for (size_t k = 0; k < ti.triangle_count; k++) {
            size_t a = ti.triangles[3 * k] + base, b = ti.triangles[3 * k + 1] + base,
                   c = ti.triangles[3 * k + 2] + base;
            fprintf(f, "f %zu//%zu %zu//%zu %zu//%zu\n", a, a, b, b, c, c);
        }
        base += n;
    }
    return ex_close(f, path, err, err_size);
}

static int ex_write_ply(const pose_state *st, int t, const pose_tissue_info *ti, const char *path, char *err,
                        size_t err_size)
{
    size_t n;
    const float *p = pose_tissue_positions(st, t, &n);
    const float *nr = pose_tissue_normals(st, t, &n);
    FILE *f = ex_open(path, err, err_size);
    if (!f)
        return -1;
    fprintf(f,
            "ply\nformat binary_little_endian 1.0\ncomment pose %s tissue %s\n"
            "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
            "property float nx\nproperty float ny\nproperty float nz\n"
            "element face %zu\nproperty list uchar uint vertex_indices\nend_header\n",
            pose_version_string(), ti->name, n, ti->triangle_count);
    /* Binary PLY is little-endian by declaration; this build targets little-endian hosts. */
    for (size_t v = 0; v < n; v++) {
        float rec[6] = {p[3 * v], p[3 * v + 1], p[3 * v + 2], nr[3 * v], nr[3 * v + 1], nr[3 * v + 2]};
        fwrite(rec, sizeof rec, 1, f);
    }
    for (size_t k = 0; k < ti->triangle_count; k++) {
        unsigned char three = 3;
        fwrite(&three, 1, 1, f);
        fwrite(ti->triangles + 3 * k, sizeof(uint32_t), 3, f);
    }
    return ex_close(f, path, err, err_size);
}

int ex_export_ply(const pose_state *st, const char *dir, char *err, size_t err_size)
{
    const pose_rig *rig = pose_state_rig(st);
    for (size_t t = 0; t < pose_rig_tissue_count(rig); t++) {
        pose_tissue_info ti;
        char name[128], path[4096];
        if (pose_rig_tissue_info(rig, (int)t, &ti) < 0)
            continue;
        ex_export_file_name(ti.name, name, sizeof name);
        snprintf(path, sizeof path, "%s/%s.ply", dir, name);
        if (ex_write_ply(st, (int)t, &ti, path, err, err_size) < 0)
            return -1;
    }
    return 0;
}

int ex_export_vtu(const pose_state *st, const char *path, int weight_joint, char *err, size_t err_size)
{
    const pose_rig *rig = pose_state_rig(st);
    pose_tet_info tet;
    size_t n;
    if (pose_rig_tet_info(rig, &tet) < 0) {
        snprintf(err, err_size, "%s: the rig has no tet mesh: %s", path, pose_last_error());
        return -1;
    }
    const float *p = pose_tet_positions(st, &n);
    FILE *f = ex_open(path, err, err_size);
    if (!f)
        return -1;
    fprintf(f,
            "<?xml version=\"1.0\"?>\n"
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
            "<UnstructuredGrid>\n<Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n"
            "<Points>\n<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">\n",
            tet.vertex_count, tet.tet_count);
    for (size_t v = 0; v < tet.vertex_count; v++)
        fprintf(f, "%.6g %.6g %.6g\n", p[3 * v], p[3 * v + 1], p[3 * v + 2]);
    fprintf(f, "</DataArray>\n</Points>\n<Cells>\n"
               "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for (size_t t = 0; t < tet.tet_count; t++)
        fprintf(f, "%u %u %u %u\n", tet.tets[4 * t], tet.tets[4 * t + 1], tet.tets[4 * t + 2],
                tet.tets[4 * t + 3]);
    fprintf(f, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for (size_t t = 0; t < tet.tet_count; t++)
        fprintf(f, "%zu\n", 4 * (t + 1));
    fprintf(f, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for (size_t t = 0; t < tet.tet_count; t++)
        fputs("10\n", f); /* VTK_TETRA */
    fprintf(f, "</DataArray>\n</Cells>\n<CellData Scalars=\"label\">\n"
               "<DataArray type=\"UInt16\" Name=\"label\" format=\"ascii\">\n");
    for (size_t t = 0; t < tet.tet_count; t++)
        fprintf(f, "%u\n", (unsigned)tet.labels[t]);
    fprintf(f, "</DataArray>\n</CellData>\n<PointData Vectors=\"displacement\">\n"
               "<DataArray type=\"Float32\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (size_t v = 0; v < tet.vertex_count; v++)
        fprintf(f, "%.6g %.6g %.6g\n", p[3 * v] - tet.rest_positions[3 * v],
                p[3 * v + 1] - tet.rest_positions[3 * v + 1], p[3 * v + 2] - tet.rest_positions[3 * v + 2]);
    fprintf(f, "</DataArray>\n<DataArray type=\"UInt16\" Name=\"dominant_joint\" format=\"ascii\">\n");
    for (size_t v = 0; v < tet.vertex_count; v++) {
        unsigned best = 0;
        for (unsigned k = 1; k < tet.influences; k++)
            if (tet.weights[tet.influences * v + k] > tet.weights[tet.influences * v + best])
                best = k;
        fprintf(f, "%u\n", (unsigned)tet.weight_joints[tet.influences * v + best]);
    }
    fprintf(f, "</DataArray>\n");
    if (weight_joint >= 0) {
        pose_joint_info ji;
        char name[128];
        ex_export_file_name(pose_rig_joint_info(rig, weight_joint, &ji) == POSE_OK ? ji.name : "joint", name,
                            sizeof name); /* also keeps the XML attribute well-formed */
        fprintf(f, "<DataArray type=\"Float32\" Name=\"weight_%s\" format=\"ascii\">\n", name);
        for (size_t v = 0; v < tet.vertex_count; v++) {
            float w = 0.0f;
            for (unsigned k = 0; k < tet.influences; k++)
                if (tet.weight_joints[tet.influences * v + k] == (uint16_t)weight_joint)
                    w += tet.weights[tet.influences * v + k];
            fprintf(f, "%.5g\n", w);
        }
        fprintf(f, "</DataArray>\n");
    }
    fprintf(f, "</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    return ex_close(f, path, err, err_size);
}
