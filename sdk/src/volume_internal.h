/* SPDX-License-Identifier: Apache-2.0
 * The volume sampler shared by volume_sample.c (the API and the passes of
 * one call) and volume_raster.c (one posed tet into one z-slab). */
#ifndef POSE_VOLUME_INTERNAL_H
#define POSE_VOLUME_INTERNAL_H

#include <stdint.h>

#include "alloc.h"
#include "pose/volume.h"
#include "rt_pool.h"

/* Barycentric tolerance: voxel centres on a face shared by two tets (grid-
 * aligned meshes) belong to both rather than to neither. */
#define POSE__VOL_EPS 1e-4

/* The output voxel centres a posed tet's bounding box holds, per axis
 * [lo, hi] clipped to the grid; a box without any has k0 > k1 (INT32_MAX,
 * INT32_MIN: outside every slab). identity: the posed tet lies exactly
 * where it rests (the same index-space bits), so each voxel it covers is
 * its own preimage and takes the rest voxel's values as they are (most
 * of a body whose posed joints leave the rest unmoved). Set per call
 * before the slabs run. */
typedef struct pose__vol_box {
    int32_t i0, i1, j0, j1, k0, k1;
    int32_t identity;
} pose__vol_box;

/* Voxels staged for sampling (one queue per slab part, at most
 * POSE__VOL_STAGE + POSE__VOL_STAGE_SLACK): the output voxel and its
 * preimage in the rest image's index space. Rows are short (two voxels on
 * average on the bundled CT), so the rasterizer queues them and the gather
 * samples them in batches, eight at a time where the CPU has AVX2. The
 * slack lets a short run be queued with fixed-width stores. */
#define POSE__VOL_STAGE 512
#define POSE__VOL_STAGE_SLACK 8
typedef struct pose__vol_stage {
    uint32_t at[POSE__VOL_STAGE + POSE__VOL_STAGE_SLACK];
    float x[POSE__VOL_STAGE + POSE__VOL_STAGE_SLACK];
    float y[POSE__VOL_STAGE + POSE__VOL_STAGE_SLACK];
    float z[POSE__VOL_STAGE + POSE__VOL_STAGE_SLACK];
    unsigned n;
} pose__vol_stage;

struct pose_volume_sampler {
    const pose_rig *rig;
    pose_allocator allocator;
    pose_volume_desc rest;
    pose_volume_grid out;
    double out_inv[3][4];   /* model -> output index */
    int orient;             /* sign of det(rest index <- model) * det(output index <- model) */
    size_t vertex_count, tet_count;
    const uint32_t *tets;
    float *rest_index;      /* 3 * V: rest vertices in the rest image's index space */
    float *posed_index;     /* 3 * V: posed vertices in the output index space (per call) */
    uint8_t *tet_flags;     /* per tet: POSE__VOL_REST_* (set at creation) */
    pose__vol_box *boxes;   /* per tet (per call) */
    /* One bit per output voxel, set when a posed tet holds its centre (per
     * call); each row starts a new word (cover_words per row), so a row
     * belongs to one slab and one thread. Bits rather than bytes: the
     * per-call clear and the fill pass move an eighth of the memory. */
    uint64_t *covered;
    size_t cover_words;
    pose__pool *pool;
    pose__vol_stage *stages; /* one per part */
    int use_avx2;            /* the variant, chosen at creation */
    /* The rest cover (volume_rest_cover.c), when the output grid is the
     * rest grid; owner NULL otherwise. */
    uint16_t *owner;         /* per output voxel: its block at rest, or POSE__VOL_NO_OWNER */
    uint32_t *owned_words;   /* per output row: the words [first, end) holding owned voxels */
    uint8_t *block_still;    /* per block (per call): all its tets lie where they rest */
    unsigned block_shift;    /* a block is 2^block_shift consecutive tets */
    int owner_building;      /* set while creation rasterizes the rest pose into owner */
    /* the call in flight */
    const float *posed;
    float *dst_intensity;
    uint16_t *dst_labels;
};

/* The rest cover (volume_rest_cover.c). */
#define POSE__VOL_NO_OWNER 0xffffu
/** Whether the sampler keeps a rest cover: the output grid is the rest grid. */
int pose__vol_rest_cover_wanted(const pose_volume_grid *rest, const pose_volume_grid *out);
/** Bytes of the rest cover's arrays (one allocation). */
size_t pose__vol_rest_cover_bytes(const pose_volume_grid *out);
/** Takes the arrays (pose__vol_rest_cover_bytes bytes, the sampler frees
 *  them as owned_words) and clears the owners; the caller then rasterizes
 *  the rest pose with owner_building set, then calls
 *  pose__vol_rest_cover_rows. */
void pose__vol_rest_cover_init(pose_volume_sampler *s, void *arrays);
/** Each row's owned words, from the owners. */
void pose__vol_rest_cover_rows(pose_volume_sampler *s);
/** block_still of blocks [block0, block1), from the boxes' identity flags. */
void pose__vol_rest_cover_blocks(pose_volume_sampler *s, size_t block0, size_t block1);
/** Output planes [k0, k1), after the moved tets: the voxels whose owner is
 *  still and that no moved tet covered take the rest image's values; all
 *  whose owner is still are marked covered. */
void pose__vol_rest_cover_copy(const pose_volume_sampler *s, size_t k0, size_t k1);

/* What a tet's rest positions say, once per sampler: the sign of its
 * volume in the rest image's index space (the posed one must match, or
 * the tet is folded). */
#define POSE__VOL_REST_POSITIVE 1
#define POSE__VOL_REST_NEGATIVE 2

/** The POSE__VOL_REST_* flags of a tet with rest vertices r (rest index
 *  space). */
int pose__volume_rest_flags(const float *r[4]);

/* The rest image's cells as the gather reads them. */
typedef struct pose__vol_cells {
    float out[3];      /* n - 0.5: a preimage beyond (or under -0.5) is outside the image */
    float top[3];      /* n - 1: the last voxel centre, where preimages are clamped */
    int last_cell[3];  /* max(n - 2, 0): the last cell's lower corner */
    size_t step[3];    /* to the next voxel on an axis; 0 on an axis of one voxel */
    size_t row, plane; /* nx, nx ny */
} pose__vol_cells;

static inline pose__vol_cells pose__vol_cells_of(const pose_volume_grid *g)
{
    const uint32_t n[3] = {g->nx, g->ny, g->nz};
    const size_t stride[3] = {1, g->nx, (size_t)g->nx * g->ny};
    pose__vol_cells c;
    for (int a = 0; a < 3; a++) {
        c.out[a] = (float)n[a] - 0.5f;
        c.top[a] = (float)(n[a] - 1);
        c.last_cell[a] = n[a] > 1 ? (int)n[a] - 2 : 0;
        c.step[a] = n[a] > 1 ? stride[a] : 0;
    }
    c.row = stride[1], c.plane = stride[2];
    return c;
}


/** Rasterize posed tet `t` (its box `box`) into output planes k0..k1 (one
 *  slab's share of the box): its covered voxels are queued in `st` with
 *  their preimages through the tet's inverse map (the gather samples the
 *  rest image there), and get their covered bits. The values a voxel gets depend on
 *  the tet and the voxel only, never on k0/k1 or the queue, so any slab
 *  split gives the same bytes. Two variants (volume_raster_body.h), the
 *  same bytes. */
void pose__volume_raster_tet_generic(const pose_volume_sampler *s, size_t t,
                                     const pose__vol_box *box, int k0, int k1,
                                     pose__vol_stage *st);

/** Samples the queued voxels into the call's outputs and empties the queue
 *  (volume_gather.c). */
void pose__volume_gather(const pose_volume_sampler *s, pose__vol_stage *st);
void pose__volume_gather_generic(const pose_volume_desc *rest, const pose__vol_stage *st,
                                 unsigned begin, float *oi, uint16_t *ol);

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
/* Variants compiled with -mavx2, used when the CPU has it (and
 * POSE_KERNELS=generic does not say otherwise, as for the skinning
 * kernels). */
#  define POSE__HAVE_AVX2_VOLUME 1
void pose__volume_raster_tet_avx2(const pose_volume_sampler *s, size_t t,
                                  const pose__vol_box *box, int k0, int k1,
                                  pose__vol_stage *st);
/** Queue entries [0, n - n % 8) eight at a time, when both outputs are
 *  asked for; returns how many it sampled. */
unsigned pose__volume_gather_avx2(const pose_volume_desc *rest, const pose__vol_stage *st,
                                  float *oi, uint16_t *ol);
#endif

/** The covered bits of output row (j, k). */
static inline uint64_t *pose__vol_cover_row(const pose_volume_sampler *s, size_t j, size_t k)
{
    return s->covered + (k * s->out.ny + j) * s->cover_words;
}

#endif /* POSE_VOLUME_INTERNAL_H */
