/* SPDX-License-Identifier: Apache-2.0
 * The NIfTI header checks of pv_nifti_read, on the raw bytes (either byte
 * order, NIfTI-1 348 bytes or NIfTI-2 540 bytes), before nifticlib is
 * trusted with the file. */
#include "vol_nifti.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static int fail(char *err, size_t n, const char *name, const char *field, const char *fmt, ...)
{
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(err, n, "%s: NIfTI header field '%s': %s", name, field, msg);
    return -1;
}

typedef struct rd {
    const unsigned char *p;
    int swap;
} rd;

static uint64_t raw(const rd *r, size_t off, int bytes)
{
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++) {
        int k = r->swap ? i : bytes - 1 - i;
        v = (v << 8) | r->p[off + (size_t)k];
    }
    return v;
}
static int64_t i16(const rd *r, size_t off) { return (int16_t)(uint16_t)raw(r, off, 2); }
static int64_t i32(const rd *r, size_t off) { return (int32_t)(uint32_t)raw(r, off, 4); }
static int64_t i64(const rd *r, size_t off) { return (int64_t)raw(r, off, 8); }
static double f32(const rd *r, size_t off)
{
    uint32_t u = (uint32_t)raw(r, off, 4);
    float f;
    memcpy(&f, &u, 4);
    return f;
}
static double f64(const rd *r, size_t off)
{
    uint64_t u = raw(r, off, 8);
    double d;
    memcpy(&d, &u, 8);
    return d;
}

/* bitpix of a real scalar datatype, 0 for known non-scalar ones, -1 unknown. */
static int scalar_bits(int64_t dt, const char **what)
{
    switch (dt) {
    case 2: case 256: return 8;              /* uint8, int8 */
    case 4: case 512: return 16;             /* int16, uint16 */
    case 8: case 768: case 16: return 32;    /* int32, uint32, float32 */
    case 64: case 1024: case 1280: return 64; /* float64, int64, uint64 */
    case 1: *what = "binary (1 bit)"; return 0;
    case 32: case 1792: case 2048: *what = "complex"; return 0;
    case 128: case 2304: *what = "RGB colour"; return 0;
    case 1536: *what = "float128"; return 0;
    default: return -1;
    }
}

int pv_nifti_check_header(const unsigned char *hdr, size_t len, const char *name,
                          long long file_size, char *err, size_t n)
{
    if (len < 348)
        return fail(err, n, name, "sizeof_hdr", "file has %zu bytes, a NIfTI header needs 348",
                    len);
    rd r = {hdr, 0};
    int64_t sz = i32(&r, 0);
    if (sz != 348 && sz != 540) {
        r.swap = 1;
        sz = i32(&r, 0);
    }
    if (sz != 348 && sz != 540) {
        r.swap = 0;
        return fail(err, n, name, "sizeof_hdr", "%lld (NIfTI-1 has 348, NIfTI-2 540)",
                    (long long)i32(&r, 0));
    }
    int v2 = sz == 540;
    if (v2 && len < 540)
        return fail(err, n, name, "sizeof_hdr", "540 (NIfTI-2) but the file has only %zu bytes",
                    len);
    const unsigned char *magic = hdr + (v2 ? 4 : 344);
    int single;
    if (!v2 && (memcmp(magic, "n+1\0", 4) == 0 || memcmp(magic, "ni1\0", 4) == 0))
        single = magic[1] == '+';
    else if (v2 && (memcmp(magic, "n+2\0", 4) == 0 || memcmp(magic, "ni2\0", 4) == 0))
        single = magic[1] == '+';
    else
        return fail(err, n, name, "magic", "not \"%s\" or \"%s\" (not a NIfTI-%d file)",
                    v2 ? "n+2" : "n+1", v2 ? "ni2" : "ni1", v2 ? 2 : 1);

    int64_t dim[8];
    for (int i = 0; i < 8; i++)
        dim[i] = v2 ? i64(&r, 16 + 8 * (size_t)i) : i16(&r, 40 + 2 * (size_t)i);
    if (dim[0] < 1 || dim[0] > 7)
        return fail(err, n, name, "dim[0]", "%lld (the number of dimensions is 1..7)",
                    (long long)dim[0]);
    int64_t voxels = 1;
    for (int i = 1; i <= dim[0]; i++) {
        char f[16];
        snprintf(f, sizeof f, "dim[%d]", i);
        if (dim[i] < 1)
            return fail(err, n, name, f, "%lld (sizes are >= 1)", (long long)dim[i]);
        if (i > 3 && dim[i] != 1)
            return fail(err, n, name, f,
                        "%lld: a series of %lld volumes; pose takes one 3-D volume "
                        "(split it first)",
                        (long long)dim[i], (long long)dim[i]);
        if (dim[i] > PV_MAX_VOXELS / voxels)
            return fail(err, n, name, f,
                        "%lld makes more than %lld voxels (overflow or absurd size)",
                        (long long)dim[i], (long long)PV_MAX_VOXELS);
        voxels *= dim[i];
    }
    int64_t dt = i16(&r, v2 ? 12 : 70), bitpix = i16(&r, v2 ? 14 : 72);
    const char *what = "";
    int bits = scalar_bits(dt, &what);
    if (bits < 0)
        return fail(err, n, name, "datatype", "%lld is not a NIfTI datatype", (long long)dt);
    if (bits == 0)
        return fail(err, n, name, "datatype",
                    "%lld (%s): pose reads scalar images (integers or floats)", (long long)dt,
                    what);
    if (bitpix != bits)
        return fail(err, n, name, "bitpix", "%lld but datatype %lld has %d bits per voxel",
                    (long long)bitpix, (long long)dt, bits);
    for (int i = 1; i <= 3; i++) {
        double p = v2 ? f64(&r, 104 + 8 * (size_t)i) : f32(&r, 76 + 4 * (size_t)i);
        char f[16];
        snprintf(f, sizeof f, "pixdim[%d]", i);
        /* Analyze-era files leave unused axes at 0; only the used ones must be set. */
        if (i <= dim[0] && !(isfinite(p) && p > 0.0))
            return fail(err, n, name, f, "%g (voxel sizes are finite and > 0)", p);
        if (!isfinite(p))
            return fail(err, n, name, f, "%g is not finite", p);
    }
    double vox = v2 ? (double)i64(&r, 168) : f32(&r, 108);
    if (!isfinite(vox) || vox < 0 || vox > 1e15)
        return fail(err, n, name, "vox_offset", "%g is not a byte offset", vox);
    if (single && vox < (double)sz)
        return fail(err, n, name, "vox_offset",
                    "%g lies inside the %lld-byte header (a single .nii file has its data after "
                    "the header)",
                    vox, (long long)sz);
    if (file_size >= 0) {
        double need = floor(vox) + (double)voxels * (double)(bits / 8);
        if ((double)file_size < need)
            return fail(err, n, name, "vox_offset",
                        "%g + %lld voxels x %d bytes = %.0f bytes, but the file of voxels has %lld "
                        "(truncated, or wrong dim/datatype)",
                        vox, (long long)voxels, bits / 8, need, file_size);
    }
    double slope = v2 ? f64(&r, 176) : f32(&r, 112), inter = v2 ? f64(&r, 184) : f32(&r, 116);
    if (!isfinite(slope))
        return fail(err, n, name, "scl_slope", "%g is not finite", slope);
    if (!isfinite(inter))
        return fail(err, n, name, "scl_inter", "%g is not finite", inter);
    int64_t qcode = v2 ? i32(&r, 344) : i16(&r, 252), scode = v2 ? i32(&r, 348) : i16(&r, 254);
    if (qcode < 0 || qcode > 5)
        return fail(err, n, name, "qform_code", "%lld (0..5)", (long long)qcode);
    if (scode < 0 || scode > 5)
        return fail(err, n, name, "sform_code", "%lld (0..5)", (long long)scode);
    if (scode > 0) {
        static const char *rows[3] = {"srow_x", "srow_y", "srow_z"};
        for (int rr = 0; rr < 3; rr++)
            for (int c = 0; c < 4; c++) {
                double x = v2 ? f64(&r, 400 + 32 * (size_t)rr + 8 * (size_t)c)
                              : f32(&r, 280 + 16 * (size_t)rr + 4 * (size_t)c);
                if (!isfinite(x))
                    return fail(err, n, name, rows[rr], "element %d is %g (sform_code %lld)", c,
                                x, (long long)scode);
            }
    }
    if (qcode > 0)
        for (int c = 0; c < 6; c++) {
            double x = v2 ? f64(&r, 352 + 8 * (size_t)c) : f32(&r, 256 + 4 * (size_t)c);
            if (!isfinite(x))
                return fail(err, n, name, c < 3 ? "quatern_bcd" : "qoffset_xyz",
                            "element %d is %g (qform_code %lld)", c % 3, x, (long long)qcode);
        }
    return v2 ? 2 : 1;
}
