/* SPDX-License-Identifier: Apache-2.0
 * NIfTI read and write through nifticlib; the header is checked first
 * (vol_nifti_header.c). */
#include "vol_nifti.h"

#include <nifti2_io.h>
#include <zlib.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int fail(char *err, size_t n, const char *fmt, const char *a, const char *b)
{
    snprintf(err, n, fmt, a, b);
    return -1;
}

/* The first 540 bytes (or fewer) of a plain or gzip file. */
static int read_head(const char *path, unsigned char *buf, size_t cap, size_t *got, char *err,
                     size_t n)
{
    gzFile g = gzopen(path, "rb");
    if (!g)
        return fail(err, n, "%s: cannot open: %s", path, strerror(errno ? errno : ENOENT));
    int k = gzread(g, buf, (unsigned)cap);
    int e = 0;
    char msg[128] = "read error";
    if (k < 0) /* copied: zlib frees its message with the stream */
        snprintf(msg, sizeof msg, "%s", gzerror(g, &e));
    gzclose(g);
    if (k < 0)
        return fail(err, n, "%s: cannot read the header: %s", path, msg);
    *got = (size_t)k;
    return 0;
}

static int is_gz(const char *path)
{
    size_t l = strlen(path);
    return l >= 3 && strcmp(path + l - 3, ".gz") == 0;
}

static double value_at(const nifti_image *nim, size_t i)
{
    const void *d = nim->data;
    switch (nim->datatype) {
    case DT_UINT8: return ((const uint8_t *)d)[i];
    case DT_INT8: return ((const int8_t *)d)[i];
    case DT_INT16: return ((const int16_t *)d)[i];
    case DT_UINT16: return ((const uint16_t *)d)[i];
    case DT_INT32: return ((const int32_t *)d)[i];
    case DT_UINT32: return ((const uint32_t *)d)[i];
    case DT_INT64: return (double)((const int64_t *)d)[i];
    case DT_UINT64: return (double)((const uint64_t *)d)[i];
    case DT_FLOAT32: return ((const float *)d)[i];
    case DT_FLOAT64: return ((const double *)d)[i];
    default: return NAN;
    }
}

int pv_nifti_read(const char *path, pv_image *out, char *err, size_t n)
{
    memset(out, 0, sizeof *out);
    unsigned char head[540];
    size_t got = 0;
    if (read_head(path, head, sizeof head, &got, err, n) < 0)
        return -1;
    /* The size of the file that holds the voxels bounds dim x datatype before
     * nifticlib allocates them: the .nii itself, or for a header/image pair
     * (magic ni1/ni2) the image file beside the header. */
    const int pair2 = got >= 8 && memcmp(head + 4, "ni2", 4) == 0;
    const int pair = pair2 || (got >= 348 && memcmp(head + 344, "ni1", 4) == 0);
    char *img = pair ? nifti_findimgname(path, pair2 ? NIFTI_FTYPE_NIFTI2_2 : NIFTI_FTYPE_NIFTI1_2) : NULL;
    if (pair && !img)
        return fail(err, n, "%s: NIfTI header field '%s': a header/image pair whose image file (.img) is missing",
                    path, "magic");
    const char *data_path = pair ? img : path;
    long long fsize = -1;
    struct stat st;
    if (!is_gz(data_path) && stat(data_path, &st) == 0 && S_ISREG(st.st_mode))
        fsize = (long long)st.st_size;
    free(img);
    int version = pv_nifti_check_header(head, got, path, fsize, err, n);
    if (version < 0)
        return -1;

    nifti_set_debug_level(0);
    nifti_image *nim = nifti_image_read(path, 1);
    if (!nim || !nim->data) {
        if (nim)
            nifti_image_free(nim);
        return fail(err, n,
                    "%s: nifticlib could not read the voxels (data shorter than the header's "
                    "dim x datatype, or a damaged %s stream)",
                    path, is_gz(path) ? "gzip" : "file");
    }
    int rc = -1;
    if (nim->nx < 1 || nim->ny < 1 || nim->nz < 1 || nim->nvox != nim->nx * nim->ny * nim->nz) {
        fail(err, n, "%s: NIfTI header field '%s': not one 3-D volume after reading", path, "dim");
        goto done;
    }
    out->nx = nim->nx;
    out->ny = nim->ny;
    out->nz = nim->nz;
    size_t nv = (size_t)nim->nvox;
    out->data = malloc(nv * sizeof *out->data);
    if (!out->data) {
        fail(err, n, "%s: out of memory for %s voxels", path, "the");
        goto done;
    }
    double slope = nim->scl_slope, inter = nim->scl_inter;
    int scaled = slope != 0.0 && !(slope == 1.0 && inter == 0.0);
    for (size_t i = 0; i < nv; i++) {
        double v = value_at(nim, i);
        out->data[i] = (float)(scaled ? v * slope + inter : v);
    }
    const nifti_dmat44 *m = NULL;
    if (nim->sform_code > 0)
        m = &nim->sto_xyz, out->affine_source = 2;
    else if (nim->qform_code > 0)
        m = &nim->qto_xyz, out->affine_source = 1;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            out->affine[r][c] = m ? m->m[r][c] : (r == c ? (&nim->dx)[r] : 0.0);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            if (!isfinite(out->affine[r][c])) {
                fail(err, n, "%s: NIfTI header field '%s': the voxel-to-world transform is not "
                             "finite",
                     path, out->affine_source == 2 ? "srow" : "quatern");
                goto done;
            }
    out->spacing[0] = nim->dx;
    out->spacing[1] = nim->dy;
    out->spacing[2] = nim->dz;
    out->sform_code = nim->sform_code;
    out->qform_code = nim->qform_code;
    out->datatype = nim->datatype;
    out->nifti_version = version; /* nifticlib's nifti_type says 1 for some NIfTI-2 files */
    out->xyz_units = nim->xyz_units;
    out->time_units = nim->time_units;
    out->intent_code = nim->intent_code;
    memcpy(out->intent_name, nim->intent_name, sizeof out->intent_name);
    out->intent_name[sizeof out->intent_name - 1] = '\0';
    memcpy(out->descrip, nim->descrip, sizeof out->descrip);
    out->descrip[sizeof out->descrip - 1] = '\0';
    rc = 0;
done:
    nifti_image_free(nim);
    if (rc < 0)
        pv_image_free(out), memset(out, 0, sizeof *out);
    return rc;
}

static void store(void *d, int dt, size_t i, double v)
{
#define CLAMP(T, lo, hi) ((T)(v < (lo) ? (lo) : v > (hi) ? (hi) : nearbyint(v)))
    switch (dt) {
    case DT_UINT8: ((uint8_t *)d)[i] = CLAMP(uint8_t, 0, 255); break;
    case DT_INT8: ((int8_t *)d)[i] = CLAMP(int8_t, -128, 127); break;
    case DT_INT16: ((int16_t *)d)[i] = CLAMP(int16_t, -32768, 32767); break;
    case DT_UINT16: ((uint16_t *)d)[i] = CLAMP(uint16_t, 0, 65535); break;
    case DT_INT32: ((int32_t *)d)[i] = CLAMP(int32_t, -2147483648.0, 2147483647.0); break;
    case DT_UINT32: ((uint32_t *)d)[i] = CLAMP(uint32_t, 0, 4294967295.0); break;
    case DT_INT64: ((int64_t *)d)[i] = CLAMP(int64_t, -9.2e18, 9.2e18); break;
    case DT_UINT64: ((uint64_t *)d)[i] = CLAMP(uint64_t, 0, 1.8e19); break;
    case DT_FLOAT32: ((float *)d)[i] = (float)v; break;
    default: ((double *)d)[i] = v; break;
    }
#undef CLAMP
}

/* nifticlib 3.0.1 builds the header (nifti_convert_nim2n*hdr); the file is
 * written here, through zlib, because its own writer loses the header of
 * a single-file NIfTI-2 and reports no errors. Layout: header, 4 zero
 * extension bytes, voxels at vox_offset (352 or 544). */
static int write_file(const char *path, const nifti_image *nim, int v2, char *err, size_t n)
{
    union {
        nifti_1_header h1;
        nifti_2_header h2;
    } h;
    memset(&h, 0, sizeof h);
    size_t hsize;
    if (v2) {
        if (nifti_convert_nim2n2hdr(nim, &h.h2) != 0)
            return fail(err, n, "%s: %s", path, "nifticlib could not build the NIfTI-2 header");
        h.h2.vox_offset = 544;
        memcpy(h.h2.magic, "n+2\0\r\n\032\n", 8);
        hsize = sizeof h.h2;
    } else {
        if (nifti_convert_nim2n1hdr(nim, &h.h1) != 0)
            return fail(err, n, "%s: %s", path, "nifticlib could not build the NIfTI-1 header");
        h.h1.vox_offset = 352.0f;
        memcpy(h.h1.magic, "n+1\0", 4);
        hsize = sizeof h.h1;
    }
    gzFile g = gzopen(path, is_gz(path) ? "wb6" : "wbT");
    if (!g)
        return fail(err, n, "%s: cannot create: %s", path, strerror(errno ? errno : EIO));
    const unsigned char ext[4] = {0, 0, 0, 0};
    size_t bytes = (size_t)nim->nvox * (size_t)nim->nbyper;
    int ok = gzwrite(g, &h, (unsigned)hsize) == (int)hsize && gzwrite(g, ext, 4) == 4;
    const unsigned char *d = nim->data;
    for (size_t off = 0; ok && off < bytes;) {
        unsigned chunk = (unsigned)(bytes - off > (1u << 30) ? (1u << 30) : bytes - off);
        ok = gzwrite(g, d + off, chunk) == (int)chunk;
        off += chunk;
    }
    int e = gzclose(g);
    if (!ok || e != Z_OK) {
        remove(path);
        return fail(err, n, "%s: writing failed: %s", path,
                    errno ? strerror(errno) : "zlib error");
    }
    return 0;
}

int pv_nifti_write(const char *path, const pv_image *img, int datatype, char *err, size_t n)
{
    if (datatype == 0)
        datatype = img->datatype ? img->datatype : DT_FLOAT32;
    const char *what = "";
    switch (datatype) {
    case DT_UINT8: case DT_INT8: case DT_INT16: case DT_UINT16: case DT_INT32: case DT_UINT32:
    case DT_INT64: case DT_UINT64: case DT_FLOAT32: case DT_FLOAT64: break;
    default: what = "not a real scalar datatype"; break;
    }
    if (*what)
        return fail(err, n, "%s: cannot write datatype %s", path, nifti_datatype_string(datatype));
    if (img->nx < 1 || img->ny < 1 || img->nz < 1 || !img->data)
        return fail(err, n, "%s: %s", path, "empty image");
    const size_t l = strlen(path);
    if (!((l > 4 && strcmp(path + l - 4, ".nii") == 0) ||
          (l > 7 && strcmp(path + l - 7, ".nii.gz") == 0)))
        return fail(err, n, "%s: %s", path, "the output name must end in .nii or .nii.gz");
    int64_t dims[8] = {3, img->nx, img->ny, img->nz, 1, 1, 1, 1};
    nifti_set_debug_level(0);
    nifti_image *nim = nifti_make_new_nim(dims, datatype, 1);
    if (!nim)
        return fail(err, n, "%s: %s", path, "out of memory");
    nim->nifti_type = img->nifti_version == 2 ? NIFTI_FTYPE_NIFTI2_1 : NIFTI_FTYPE_NIFTI1_1;
    nim->dx = nim->pixdim[1] = img->spacing[0] > 0 ? img->spacing[0] : 1.0;
    nim->dy = nim->pixdim[2] = img->spacing[1] > 0 ? img->spacing[1] : 1.0;
    nim->dz = nim->pixdim[3] = img->spacing[2] > 0 ? img->spacing[2] : 1.0;
    nifti_dmat44 a;
    memset(&a, 0, sizeof a);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            a.m[r][c] = img->affine[r][c];
    a.m[3][3] = 1.0;
    nim->sto_xyz = a;
    nim->sto_ijk = nifti_dmat44_inverse(a);
    nim->sform_code = img->sform_code > 0 ? img->sform_code : NIFTI_XFORM_SCANNER_ANAT;
    double qfac;
    nifti_dmat44_to_quatern(a, &nim->quatern_b, &nim->quatern_c, &nim->quatern_d, &nim->qoffset_x,
                            &nim->qoffset_y, &nim->qoffset_z, NULL, NULL, NULL, &qfac);
    nim->qfac = qfac;
    nim->pixdim[0] = qfac;
    nim->qto_xyz = nifti_quatern_to_dmat44(nim->quatern_b, nim->quatern_c, nim->quatern_d,
                                           nim->qoffset_x, nim->qoffset_y, nim->qoffset_z,
                                           nim->dx, nim->dy, nim->dz, qfac);
    nim->qto_ijk = nifti_dmat44_inverse(nim->qto_xyz);
    nim->qform_code = img->qform_code > 0 ? img->qform_code : NIFTI_XFORM_SCANNER_ANAT;
    nim->xyz_units = img->xyz_units ? img->xyz_units : NIFTI_UNITS_MM;
    nim->time_units = img->time_units;
    nim->intent_code = img->intent_code;
    memcpy(nim->intent_name, img->intent_name, sizeof nim->intent_name);
    nim->intent_name[sizeof nim->intent_name - 1] = '\0';
    memcpy(nim->descrip, img->descrip, sizeof nim->descrip);
    nim->descrip[sizeof nim->descrip - 1] = '\0';
    size_t nv = pv_image_voxels(img);
    for (size_t i = 0; i < nv; i++)
        store(nim->data, datatype, i, img->data[i]);
    int rc = write_file(path, nim, img->nifti_version == 2, err, n);
    nifti_image_free(nim);
    return rc;
}
