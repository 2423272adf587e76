/* SPDX-License-Identifier: Apache-2.0
 *
 * VTK XML writer for tissue surfaces. Hand-written on purpose: the format
 * is a few XML elements around arrays, and the library that writes it
 * (VTK, libvtk9-dev) is hundreds of megabytes of C++ for a C example tool.
 * DataArrays are format="binary": base64 of a UInt32 byte count followed by
 * the little-endian values, encoded as one stream, as VTK itself and meshio
 * write uncompressed data (the tests read every frame back with meshio).
 */
#include "ex_vtk.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Base64 of `n` bytes given in two parts (the header, then the values), as one stream. */
static void put_base64(FILE *f, const unsigned char *a, size_t na, const unsigned char *b, size_t nb)
{
    static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t n = na + nb;
    char out[4 * 1024 + 4];
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        unsigned v = 0;
        int got = 0;
        for (int k = 0; k < 3; k++) {
            v <<= 8;
            if (i + k < n) {
                v |= i + k < na ? a[i + k] : b[i + k - na];
                got++;
            }
        }
        out[o++] = tab[(v >> 18) & 63];
        out[o++] = tab[(v >> 12) & 63];
        out[o++] = got > 1 ? tab[(v >> 6) & 63] : '=';
        out[o++] = got > 2 ? tab[v & 63] : '=';
        if (o >= 4 * 1024) {
            fwrite(out, 1, o, f);
            o = 0;
        }
    }
    fwrite(out, 1, o, f);
}

/* One DataArray of `count` values of `size` bytes each (this build targets little-endian hosts). */
static void data_array(FILE *f, const char *type, const char *name, int components, const void *data, size_t count,
                       size_t size)
{
    uint64_t bytes = (uint64_t)count * size;
    uint32_t hdr = (uint32_t)bytes;
    fprintf(f, "<DataArray type=\"%s\" Name=\"%s\"", type, name);
    if (components > 1)
        fprintf(f, " NumberOfComponents=\"%d\"", components);
    fprintf(f, " format=\"binary\">\n");
    put_base64(f, (const unsigned char *)&hdr, sizeof hdr, data, (size_t)bytes);
    fprintf(f, "\n</DataArray>\n");
}

int ex_vtk_write_surfaces(const pose_state *st, const char *path, char *err, size_t err_size)
{
    const pose_rig *rig = pose_state_rig(st);
    size_t nv = 0, nt = 0, tissues = pose_rig_tissue_count(rig);
    for (size_t t = 0; t < tissues; t++) {
        pose_tissue_info ti;
        if (pose_rig_tissue_info(rig, (int)t, &ti) == POSE_OK) {
            nv += ti.vertex_count;
            nt += ti.triangle_count;
        }
    }
    if (3 * nv > INT32_MAX || 3 * nt > INT32_MAX || 12 * nv > UINT32_MAX) {
        snprintf(err, err_size, "%s: %zu vertices are too many for one file", path, nv);
        return -1;
    }
    float *pos = malloc(3 * nv * sizeof *pos + 1), *nrm = malloc(3 * nv * sizeof *nrm + 1),
          *disp = malloc(3 * nv * sizeof *disp + 1);
    int32_t *conn = malloc(3 * nt * sizeof *conn + 1), *offs = malloc(nt * sizeof *offs + 1),
            *label = malloc(nt * sizeof *label + 1);
    uint8_t *types = malloc(nt + 1);
    int rc = -1;
    FILE *f = NULL;
    if (!pos || !nrm || !disp || !conn || !offs || !label || !types) {
        snprintf(err, err_size, "%s: out of memory", path);
        goto done;
    }
    size_t v0 = 0, k0 = 0;
    for (size_t t = 0; t < tissues; t++) {
        pose_tissue_info ti;
        size_t n;
        if (pose_rig_tissue_info(rig, (int)t, &ti) < 0)
            continue;
        const float *p = pose_tissue_positions(st, (int)t, &n), *q = pose_tissue_normals(st, (int)t, &n);
        memcpy(pos + 3 * v0, p, 3 * n * sizeof *pos);
        memcpy(nrm + 3 * v0, q, 3 * n * sizeof *nrm);
        for (size_t i = 0; i < 3 * n; i++)
            disp[3 * v0 + i] = p[i] - ti.rest_positions[i];
        for (size_t k = 0; k < ti.triangle_count; k++) {
            for (int c = 0; c < 3; c++)
                conn[3 * (k0 + k) + c] = (int32_t)(v0 + ti.triangles[3 * k + c]);
            offs[k0 + k] = (int32_t)(3 * (k0 + k + 1));
            label[k0 + k] = (int32_t)t;
            types[k0 + k] = 5; /* VTK_TRIANGLE */
        }
        v0 += n;
        k0 += ti.triangle_count;
    }
    if (!(f = fopen(path, "wb"))) {
        snprintf(err, err_size, "%s: cannot create: %s", path, strerror(errno));
        goto done;
    }
    fprintf(f, "<?xml version=\"1.0\"?>\n<!-- posed tissue surfaces written by pose %s -->\n"
               "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
               "header_type=\"UInt32\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n"
               "<Points>\n",
            pose_version_string(), nv, nt);
    data_array(f, "Float32", "Points", 3, pos, 3 * nv, sizeof *pos);
    fprintf(f, "</Points>\n<Cells>\n");
    data_array(f, "Int32", "connectivity", 1, conn, 3 * nt, sizeof *conn);
    data_array(f, "Int32", "offsets", 1, offs, nt, sizeof *offs);
    data_array(f, "UInt8", "types", 1, types, nt, 1);
    fprintf(f, "</Cells>\n<PointData Normals=\"Normals\" Vectors=\"displacement\">\n");
    data_array(f, "Float32", "Normals", 3, nrm, 3 * nv, sizeof *nrm);
    data_array(f, "Float32", "displacement", 3, disp, 3 * nv, sizeof *disp);
    fprintf(f, "</PointData>\n<CellData Scalars=\"tissue\">\n");
    data_array(f, "Int32", "tissue", 1, label, nt, sizeof *label);
    fprintf(f, "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        snprintf(err, err_size, "%s: write failed: %s", path, strerror(errno ? errno : EIO));
    else
        rc = 0;
done:
    free(pos);
    free(nrm);
    free(disp);
    free(conn);
    free(offs);
    free(label);
    free(types);
    return rc;
}

struct ex_vtk_series {
    char pvd[4096], stem[4096];
    const char *base; /* the stem's file name, for paths relative to the .pvd */
    size_t frames, cap;
    double *times;
};

int ex_vtk_series_begin(const char *pvd_path, ex_vtk_series **out, char *err, size_t err_size)
{
    ex_vtk_series *s = *out = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    snprintf(s->pvd, sizeof s->pvd, "%s", pvd_path);
    snprintf(s->stem, sizeof s->stem, "%s", pvd_path);
    char *dot = strrchr(s->stem, '.'), *slash = strrchr(s->stem, '/');
    if (dot && (!slash || dot > slash))
        *dot = '\0';
    s->base = strrchr(s->stem, '/') ? strrchr(s->stem, '/') + 1 : s->stem;
    return 0;
}

int ex_vtk_series_add(ex_vtk_series *s, const pose_state *st, double t_s, char *err, size_t err_size)
{
    if (s->frames == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 64;
        double *t = realloc(s->times, cap * sizeof *t);
        if (!t) {
            snprintf(err, err_size, "out of memory");
            return -1;
        }
        s->times = t;
        s->cap = cap;
    }
    char path[4200];
    snprintf(path, sizeof path, "%s_%05zu.vtu", s->stem, s->frames);
    if (ex_vtk_write_surfaces(st, path, err, err_size) < 0)
        return -1;
    s->times[s->frames++] = t_s;
    return 0;
}

int ex_vtk_series_finish(ex_vtk_series *s, char *err, size_t err_size)
{
    FILE *f = fopen(s->pvd, "wb");
    if (!f) {
        snprintf(err, err_size, "%s: cannot create: %s", s->pvd, strerror(errno));
        return -1;
    }
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
               "<Collection>\n");
    for (size_t i = 0; i < s->frames; i++)
        fprintf(f, "<DataSet timestep=\"%.6f\" group=\"\" part=\"0\" file=\"%s_%05zu.vtu\"/>\n", s->times[i], s->base,
                i);
    fprintf(f, "</Collection>\n</VTKFile>\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        snprintf(err, err_size, "%s: write failed: %s", s->pvd, strerror(errno ? errno : EIO));
        return -1;
    }
    return 0;
}

void ex_vtk_series_free(ex_vtk_series *s)
{
    if (s)
        free(s->times);
    free(s);
}
