/* SPDX-License-Identifier: Apache-2.0
 *
 * VTK XML writer for tissue surfaces. Hand-written on purpose: the format
 * is a few XML elements around arrays, and the library that writes it
 * (VTK, libvtk9-dev) is hundreds of megabytes of C++ for a C example tool.
 * DataArrays are format="binary", as VTK itself writes them: with zlib
 * (EX_VTK_ZLIB, Debian's zlib1g-dev) the values in 64 KiB blocks each
 * compressed (vtkZLibDataCompressor), a base64 header of block count and
 * sizes, then base64 of the blocks (less than half the bytes for posed
 * tissues); without, base64 of a UInt32 byte count and the values as one
 * stream. The tests read every frame back with meshio.
 */
#include "ex_vtk.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef EX_VTK_ZLIB
#include <zlib.h>
#endif

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

#ifdef EX_VTK_ZLIB
enum { BLOCK = 1 << 16 };
#define EX_VTK_COMPRESSOR " compressor=\"vtkZLibDataCompressor\""

/* The values as zlib blocks: header {blocks, block size, last block size,
 * compressed size of each}, base64 on its own, then the blocks. -1 when out of memory. */
static int put_values(FILE *f, const unsigned char *data, size_t bytes)
{
    size_t blocks = bytes ? (bytes + BLOCK - 1) / BLOCK : 0;
    uint32_t *hdr = malloc((3 + blocks) * sizeof *hdr);
    unsigned char *out = malloc(blocks * compressBound(BLOCK) + 1);
    if (!hdr || !out) {
        free(hdr);
        free(out);
        return -1;
    }
    hdr[0] = (uint32_t)blocks;
    hdr[1] = BLOCK;
    hdr[2] = (uint32_t)(blocks ? bytes - (blocks - 1) * BLOCK : 0);
    size_t used = 0;
    for (size_t b = 0; b < blocks; b++) {
        uLongf n = compressBound(BLOCK);
        size_t len = b + 1 < blocks ? BLOCK : hdr[2];
        /* level 1: nearly all of level 6's gain on float arrays, several times faster */
        if (compress2(out + used, &n, data + b * BLOCK, (uLong)len, 1) != Z_OK) {
            free(hdr);
            free(out);
            return -1;
        }
        hdr[3 + b] = (uint32_t)n;
        used += n;
    }
    put_base64(f, (const unsigned char *)hdr, (3 + blocks) * sizeof *hdr, NULL, 0);
    put_base64(f, out, used, NULL, 0);
    free(hdr);
    free(out);
    return 0;
}
#else
#define EX_VTK_COMPRESSOR ""

static int put_values(FILE *f, const unsigned char *data, size_t bytes)
{
    uint32_t hdr = (uint32_t)bytes;
    put_base64(f, (const unsigned char *)&hdr, sizeof hdr, data, bytes);
    return 0;
}
#endif

/* One DataArray of `count` values of `size` bytes each (this build targets
 * little-endian hosts). -1 when out of memory. */
static int data_array(FILE *f, const char *type, const char *name, int components, const void *data, size_t count,
                      size_t size)
{
    fprintf(f, "<DataArray type=\"%s\" Name=\"%s\"", type, name);
    if (components > 1)
        fprintf(f, " NumberOfComponents=\"%d\"", components);
    fprintf(f, " format=\"binary\">\n");
    int rc = put_values(f, data, count * size);
    fprintf(f, "\n</DataArray>\n");
    return rc;
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
               "header_type=\"UInt32\"" EX_VTK_COMPRESSOR ">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n"
               "<Points>\n",
            pose_version_string(), nv, nt);
    int oom = data_array(f, "Float32", "Points", 3, pos, 3 * nv, sizeof *pos);
    fprintf(f, "</Points>\n<Cells>\n");
    oom |= data_array(f, "Int32", "connectivity", 1, conn, 3 * nt, sizeof *conn);
    oom |= data_array(f, "Int32", "offsets", 1, offs, nt, sizeof *offs);
    oom |= data_array(f, "UInt8", "types", 1, types, nt, 1);
    fprintf(f, "</Cells>\n<PointData Normals=\"Normals\" Vectors=\"displacement\">\n");
    oom |= data_array(f, "Float32", "Normals", 3, nrm, 3 * nv, sizeof *nrm);
    oom |= data_array(f, "Float32", "displacement", 3, disp, 3 * nv, sizeof *disp);
    fprintf(f, "</PointData>\n<CellData Scalars=\"tissue\">\n");
    oom |= data_array(f, "Int32", "tissue", 1, label, nt, sizeof *label);
    fprintf(f, "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad || oom)
        snprintf(err, err_size, "%s: %s%s", path, oom ? "out of memory" : "write failed: ",
                 oom ? "" : strerror(errno ? errno : EIO));
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

/* s as XML attribute text. */
static void put_xml(FILE *f, const char *s)
{
    for (; *s; s++)
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
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
    for (size_t i = 0; i < s->frames; i++) {
        fprintf(f, "<DataSet timestep=\"%.6f\" group=\"\" part=\"0\" file=\"", s->times[i]);
        put_xml(f, s->base);
        fprintf(f, "_%05zu.vtu\"/>\n", i);
    }
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
