/* SPDX-License-Identifier: Apache-2.0
 * The optional `volumes` section (type 7): rest images on voxel grids.
 *
 *   header (64):  u32 N (1..16), zero
 *   N records of 128 bytes: char[64] name; u32 nx, ny, nz; u32 flags
 *     (bit 0 intensity, bit 1 labels, at least one); f32[3][4] affine
 *     (voxel index -> model space, finite, invertible)
 *   then volume by volume: intensity f32 x n (pad64) when flagged, labels
 *   u16 x n (pad64) when flagged; the section ends after the last array. */
#include <math.h>
#include <string.h>

#include "error.h"
#include "pose/volume.h"
#include "rig_format.h"
#include "rig_internal.h"
#include "rig_io.h"

#define VOL_INTENSITY 1u
#define VOL_LABELS 2u

static uint64_t voxels(uint32_t nx, uint32_t ny, uint32_t nz)
{
    return (uint64_t)nx * ny * nz;
}

static uint64_t arrays_size(uint64_t n, uint32_t flags)
{
    return ((flags & VOL_INTENSITY) ? pose__align64(4 * n) : 0) +
           ((flags & VOL_LABELS) ? pose__align64(2 * n) : 0);
}

static uint32_t flags_of(const pose_rig_volume *v)
{
    return (v->intensity ? VOL_INTENSITY : 0u) | (v->labels ? VOL_LABELS : 0u);
}

static double det3(const float a[3][4])
{
    return (double)a[0][0] * ((double)a[1][1] * a[2][2] - (double)a[1][2] * a[2][1]) -
           (double)a[0][1] * ((double)a[1][0] * a[2][2] - (double)a[1][2] * a[2][0]) +
           (double)a[0][2] * ((double)a[1][0] * a[2][1] - (double)a[1][1] * a[2][0]);
}

static const char *grid_problem(uint32_t nx, uint32_t ny, uint32_t nz, const float a[3][4])
{
    if (!nx || !ny || !nz || voxels(nx, ny, nz) > POSE__RIG_MAX_VOLUME_VOXELS)
        return "grid size (1 .. 2^31 voxels)";
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            if (!isfinite(a[r][c]))
                return "affine not finite";
    if (!(fabs(det3(a)) > 1e-30))
        return "affine singular";
    return NULL;
}

pose_status pose__volumes_check_desc(const pose_rig_desc *d)
{
    if (!d->volume_count)
        return POSE_OK;
    if (d->volume_count > POSE__RIG_MAX_VOLUMES || !d->volumes)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "rig description: section 'volumes': 1..%u volumes and an array (has %zu)",
                          POSE__RIG_MAX_VOLUMES, d->volume_count);
    for (size_t i = 0; i < d->volume_count; i++) {
        const pose_rig_volume *v = &d->volumes[i];
        size_t len = v->name ? strnlen(v->name, POSE__NAME_SIZE) : 0;
        const char *why = len == 0 || len >= POSE__NAME_SIZE ? "name must be 1..63 bytes"
                          : !flags_of(v)                      ? "neither intensities nor labels"
                              : grid_problem(v->grid.nx, v->grid.ny, v->grid.nz, v->grid.affine);
        for (size_t k = 0; !why && k < i; k++)
            if (strcmp(d->volumes[k].name, v->name) == 0)
                why = "name used twice";
        if (why)
            return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                              "rig description: section 'volumes': volume %zu: %s", i, why);
    }
    return POSE_OK;
}

uint64_t pose__volumes_size_of(const pose_rig_desc *d)
{
    if (!d->volume_count)
        return 0;
    uint64_t size = POSE__RIG_SECTION_HEADER + (uint64_t)d->volume_count * POSE__RIG_VOLUME_RECORD;
    for (size_t i = 0; i < d->volume_count; i++) {
        const pose_rig_volume *v = &d->volumes[i];
        size += arrays_size(voxels(v->grid.nx, v->grid.ny, v->grid.nz), flags_of(v));
    }
    return size;
}

void pose__volumes_write(uint8_t *s, const pose_rig_desc *d)
{
    uint32_t n = (uint32_t)d->volume_count;
    memcpy(s, &n, 4);
    uint64_t data = POSE__RIG_SECTION_HEADER + (uint64_t)n * POSE__RIG_VOLUME_RECORD;
    for (uint32_t i = 0; i < n; i++) {
        const pose_rig_volume *v = &d->volumes[i];
        uint8_t *rec = s + POSE__RIG_SECTION_HEADER + (size_t)i * POSE__RIG_VOLUME_RECORD;
        memcpy(rec, v->name, strlen(v->name));
        const uint32_t head[4] = {v->grid.nx, v->grid.ny, v->grid.nz, flags_of(v)};
        memcpy(rec + 64, head, sizeof head);
        memcpy(rec + 80, v->grid.affine, 48);
        uint64_t nv = voxels(v->grid.nx, v->grid.ny, v->grid.nz);
        if (v->intensity) {
            memcpy(s + data, v->intensity, (size_t)(4 * nv));
            data += pose__align64(4 * nv);
        }
        if (v->labels) {
            memcpy(s + data, v->labels, (size_t)(2 * nv));
            data += pose__align64(2 * nv);
        }
    }
}

pose_status pose__map_volumes(const pose__source *src, const uint8_t *p, uint64_t size,
                              pose_rig *rig)
{
    if (size < POSE__RIG_SECTION_HEADER)
        return pose__source_fail(src, POSE_ERR_FORMAT, "volumes", p,
                                 "section of %llu bytes has no header",
                                 (unsigned long long)size);
    uint32_t n;
    memcpy(&n, p, 4);
    if (n < 1 || n > POSE__RIG_MAX_VOLUMES)
        return pose__source_fail(src, POSE_ERR_FORMAT, "volumes", p,
                                 "volume count %u (1..%u)", n, POSE__RIG_MAX_VOLUMES);
    for (size_t k = 4; k < POSE__RIG_SECTION_HEADER; k++)
        if (p[k])
            return pose__source_fail(src, POSE_ERR_FORMAT, "volumes", p + k,
                                     "reserved header bytes are not zero");
    uint64_t need = POSE__RIG_SECTION_HEADER + (uint64_t)n * POSE__RIG_VOLUME_RECORD;
    if (size < need)
        return pose__source_fail(src, POSE_ERR_FORMAT, "volumes", p,
                                 "%u records need %llu bytes, the section has %llu", n,
                                 (unsigned long long)need, (unsigned long long)size);
    uint64_t data = need;
    for (uint32_t i = 0; i < n; i++) {
        const uint8_t *rec = p + POSE__RIG_SECTION_HEADER + (size_t)i * POSE__RIG_VOLUME_RECORD;
        uint32_t head[4];
        float a[3][4];
        memcpy(head, rec + 64, sizeof head);
        memcpy(a, rec + 80, sizeof a);
        size_t len = strnlen((const char *)rec, POSE__NAME_SIZE);
        if (len == 0 || len >= POSE__NAME_SIZE)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, "volumes", rec,
                                     "volume %u: name is empty or not NUL-terminated", i);
        for (uint32_t k = 0; k < i; k++)
            if (strcmp((const char *)rec, (const char *)(p + POSE__RIG_SECTION_HEADER +
                                                        (size_t)k * POSE__RIG_VOLUME_RECORD)) == 0)
                return pose__source_fail(src, POSE_ERR_INVALID_DATA, "volumes", rec,
                                         "volume %u: name '%s' used twice", i, (const char *)rec);
        if (!head[3] || (head[3] & ~(VOL_INTENSITY | VOL_LABELS)))
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, "volumes", rec + 76,
                                     "volume %u ('%s'): flags 0x%x (1 intensity, 2 labels)", i,
                                     (const char *)rec, head[3]);
        const char *why = grid_problem(head[0], head[1], head[2], a);
        if (why)
            return pose__source_fail(src, POSE_ERR_INVALID_DATA, "volumes", rec + 64,
                                     "volume %u ('%s'): %s", i, (const char *)rec, why);
        uint64_t nv = voxels(head[0], head[1], head[2]);
        uint64_t bytes = arrays_size(nv, head[3]);
        if (data + bytes > size)
            return pose__source_fail(src, POSE_ERR_FORMAT, "volumes", rec,
                                     "volume %u ('%s'): %llu voxels need bytes %llu..%llu, the "
                                     "section has %llu",
                                     i, (const char *)rec, (unsigned long long)nv,
                                     (unsigned long long)data, (unsigned long long)(data + bytes),
                                     (unsigned long long)size);
        if (head[3] & VOL_INTENSITY) {
            const float *f = (const float *)(const void *)(p + data);
            for (uint64_t v = 0; v < nv; v++)
                if (!isfinite(f[v]))
                    return pose__source_fail(src, POSE_ERR_INVALID_DATA, "volumes", f + v,
                                             "volume %u ('%s'): intensity of voxel %llu is not "
                                             "finite",
                                             i, (const char *)rec, (unsigned long long)v);
        }
        data += bytes;
    }
    if (data != size)
        return pose__source_fail(src, POSE_ERR_FORMAT, "volumes", p,
                                 "section has %llu bytes, its volumes need %llu",
                                 (unsigned long long)size, (unsigned long long)data);
    rig->volumes = p;
    rig->volume_count = n;
    return POSE_OK;
}

size_t pose_rig_volume_count(const pose_rig *rig)
{
    return rig ? rig->volume_count : 0;
}

pose_status pose_rig_get_volume(const pose_rig *rig, size_t index, pose_rig_volume *out)
{
    pose__clear_error();
    if (!rig || !out || index >= rig->volume_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_rig_get_volume: %s",
                          !rig || !out ? "rig and out are required" : "index out of range");
    const uint8_t *p = rig->volumes;
    uint64_t data = POSE__RIG_SECTION_HEADER + (uint64_t)rig->volume_count * POSE__RIG_VOLUME_RECORD;
    for (size_t i = 0;; i++) {
        const uint8_t *rec = p + POSE__RIG_SECTION_HEADER + i * POSE__RIG_VOLUME_RECORD;
        uint32_t head[4];
        memcpy(head, rec + 64, sizeof head);
        uint64_t nv = voxels(head[0], head[1], head[2]);
        if (i == index) {
            memset(out, 0, sizeof *out);
            out->name = (const char *)rec;
            out->grid.nx = head[0], out->grid.ny = head[1], out->grid.nz = head[2];
            memcpy(out->grid.affine, rec + 80, 48);
            if (head[3] & VOL_INTENSITY) {
                out->intensity = (const float *)(const void *)(p + data);
                data += pose__align64(4 * nv);
            }
            if (head[3] & VOL_LABELS)
                out->labels = (const uint16_t *)(const void *)(p + data);
            return POSE_OK;
        }
        data += arrays_size(nv, head[3]);
    }
}
