/* SPDX-License-Identifier: Apache-2.0 */
/* pose_state: creation, threads, method, pose_apply and its outputs. */
#include <stdbool.h>
#include <string.h>

#include "alloc.h"
#include "contact_push.h"
#include "error.h"
#include "rig_outside.h"
#include "rt_fk.h"
#include "rt_thread.h"
#include "rt_transfer.h"
#include "state_internal.h"

static size_t align64(size_t n)
{
    return (n + 63u) & ~(size_t)63u;
}

static unsigned resolve_threads(int threads)
{
    if (threads > 0)
        return threads > POSE__MAX_THREADS ? POSE__MAX_THREADS : (unsigned)threads;
    unsigned n = pose__cpu_count();
    return n > POSE__MAX_THREADS ? POSE__MAX_THREADS : n;
}

static pose_status start_pool(pose_state *st, unsigned threads)
{
    pose__pool *pool = pose__alloc(&st->allocator, pose__pool_size(threads), POSE__ALIGN);
    if (!pool)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a pool of %u threads",
                          threads);
    if (pose__pool_init(pool, threads) != 0) {
        pose__free(&st->allocator, pool);
        return pose__fail(POSE_ERR_THREAD, "could not start %u worker threads", threads - 1);
    }
    if (st->pool) {
        pose__pool_destroy(st->pool);
        pose__free(&st->allocator, st->pool);
    }
    st->pool = pool;
    return POSE_OK;
}

static size_t st_blocks(const pose_rig *rig)
{
    return rig->rt->transfer.block_count;
}

static pose_status check_method(const pose_rig *rig, pose_method method)
{
    if ((int)method < POSE_LBS || (int)method > POSE_FEM)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "unknown skinning method %d", (int)method);
    if (method == POSE_FEM && !pose_rig_has_fem(rig))
        return pose__fail(POSE_ERR_UNSUPPORTED,
                          "POSE_FEM needs the rig's fem section (soft tissue material), and "
                          "this rig has none");
    if (method == POSE_COR && !rig->cor)
        return pose__fail(POSE_ERR_UNSUPPORTED,
                          "POSE_COR needs centres of rotation, and this rig has none");
    return POSE_OK;
}

static void set_rest_outputs(pose_state *st)
{
    const pose_rig *rig = st->rig;
    const struct pose__rig_runtime *rt = st->rt;
    memcpy(st->tet_positions, rig->tet_positions, 3 * rig->tet_vertex_count * sizeof(float));
    for (size_t t = 0; t < rig->tissue_count; t++)
        memcpy(st->tissue_positions + 3 * rt->tissue_offset[t], rig->tissues[t].positions,
               3 * rig->tissues[t].vertex_count * sizeof(float));
    memcpy(st->tissue_normals, rt->rest_normals,
           3 * rt->transfer.vertex_count * sizeof(float));
    for (size_t j = 0; j < rig->joint_count; j++) {
        pose__xform_identity(&st->skin[j]);
        st->world[j] = rt->rest_model[j];
    }
}

pose_status pose_state_create(const pose_rig *rig, pose_state **out)
{
    return pose_state_create_ex(rig, NULL, out);
}

pose_status pose_state_create_ex(const pose_rig *rig, const pose_state_options *options,
                                 pose_state **out)
{
    pose__clear_error();
    if (out)
        *out = NULL;
    if (!rig || !out)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_state_create: rig and out are required");
    if (!rig->rt)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_state_create: rig is not prepared");
    pose_state_options opt = {0};
    if (options)
        opt = *options;
    if (!pose__allocator_valid(&opt.allocator))
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_state_create: allocator needs both alloc and free");
    if (opt.size != 0 && opt.size < POSE_STATE_OPTIONS_SIZE_0_2) /* 0: the 0.1 fields (pose.h) */
        return pose__fail(POSE_ERR_INVALID_ARGUMENT,
                          "pose_state_create: options.size %zu is below the 0.2 layout (%zu)", opt.size,
                          (size_t)POSE_STATE_OPTIONS_SIZE_0_2);
    if (opt.threads < 0)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_state_create: threads = %d",
                          opt.threads);
    pose_status st_method = check_method(rig, opt.method);
    if (st_method < 0)
        return st_method;

    const size_t nj = rig->joint_count, nv = rig->tet_vertex_count;
    const size_t nt = rig->rt->transfer.vertex_count;
    size_t off_local = align64(sizeof(pose_state));
    size_t off_clinical = off_local + align64(nj * sizeof(float[4]));
    size_t off_ranges = off_clinical + align64(nj * sizeof(float[3]));
    size_t off_skin = off_ranges + align64(nj * sizeof(pose__clinical_range));
    size_t off_world = off_skin + align64(nj * sizeof(pose__xform));
    size_t off_palette = off_world + align64(nj * sizeof(pose__xform));
    size_t off_tet = off_palette + align64(nj * sizeof(pose__skin_joint));
    size_t off_pos = off_tet + align64(3 * nv * sizeof(float) + 16); /* slack: rt_transfer.h */
    size_t off_nrm = off_pos + align64(3 * nt * sizeof(float));
    size_t off_flagged = off_nrm + align64(3 * nt * sizeof(float));
    const size_t nt_padded = st_blocks(rig) * POSE__BLOCK;
    size_t off_counts = off_flagged + align64(nt_padded * sizeof(uint32_t));
    size_t size = off_counts + align64(POSE__MAX_THREADS * sizeof(size_t));

    pose_allocator alloc = pose__allocator_resolve(&opt.allocator);
    unsigned char *block = pose__alloc(&alloc, size, POSE__ALIGN);
    if (!block)
        return pose__fail(POSE_ERR_OUT_OF_MEMORY, "out of memory for a pose state (%zu bytes)",
                          size);
    pose_state *st = (pose_state *)block;
    memset(st, 0, sizeof *st);
    st->rig = rig;
    st->rt = rig->rt;
    st->allocator = alloc;
    st->method = opt.method;
    st->block = block;
    st->local = (float(*)[4])(block + off_local);
    st->clinical = (float(*)[3])(block + off_clinical);
    st->ranges = (pose__clinical_range *)(block + off_ranges);
    st->skin = (pose__xform *)(block + off_skin);
    st->world = (pose__xform *)(block + off_world);
    st->palette = (pose__skin_joint *)(block + off_palette);
    st->tet_positions = (float *)(block + off_tet);
    st->tissue_positions = (float *)(block + off_pos);
    st->tissue_normals = (float *)(block + off_nrm);
    st->flagged = (uint32_t *)(block + off_flagged);
    st->flagged_count = (size_t *)(block + off_counts);
    pose__state_fem_defaults(&st->fem_params);
    pose_dynamics_defaults(&st->dyn_options);
    for (size_t j = 0; j < nj; j++)
        pose__quat_identity(st->local[j]);
    pose__state_rig_ranges(st);
    pose__state_rest_clinical(st);
    pose__xform_identity(&st->root);
    set_rest_outputs(st);

    pose_status s = start_pool(st, resolve_threads(opt.threads));
    if (s < 0) {
        pose__free(&alloc, block);
        return s;
    }
    s = pose__state_couplings_init(st); /* state_coupling.c: the rig's couplings */
    if (s == POSE_OK)
        s = pose__state_links_init(st); /* state_links.c: and its soft-soft ones */
    if (s == POSE_OK && opt.method == POSE_FEM)
        s = pose__state_fem_work(st, "pose_state_create");
    if (s < 0) {
        pose_state_free(st);
        return s;
    }
    *out = st;
    return POSE_OK;
}

void pose_state_free(pose_state *st)
{
    if (!st)
        return;
    pose_allocator alloc = st->allocator;
    if (st->dyn_block)
        pose__free(&alloc, st->dyn_block);
    if (st->fem_block)
        pose__free(&alloc, st->fem_block);
    if (st->pool) {
        pose__pool_destroy(st->pool);
        pose__free(&alloc, st->pool);
    }
    pose__state_push_free(st);
    pose__state_couplings_free(st);
    pose__state_links_free(st);
    pose__free(&alloc, st->block);
}

const pose_rig *pose_state_rig(const pose_state *st)
{
    return st ? st->rig : NULL;
}

pose_status pose_set_method(pose_state *st, pose_method method)
{
    pose__clear_error();
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_method: state is NULL");
    pose_status s = check_method(st->rig, method);
    if (s == POSE_OK && method == POSE_FEM)
        s = pose__state_fem_work(st, "pose_set_method");
    if (s < 0)
        return s;
    st->method = method;
    return POSE_OK;
}

pose_method pose_get_method(const pose_state *st)
{
    return st ? st->method : POSE_LBS;
}

pose_status pose_set_threads(pose_state *st, int threads)
{
    pose__clear_error();
    if (!st || threads < 0)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_set_threads: %s",
                          st ? "threads must be >= 0" : "state is NULL");
    unsigned n = resolve_threads(threads);
    if (n == pose__pool_threads(st->pool))
        return POSE_OK;
    return start_pool(st, n);
}

/* The two parallel passes of pose_apply, split into whole blocks of 8
 * vertices by part: every vertex is computed on its own, so results do not
 * depend on the thread count. */
void pose__state_skin_task(void *ctx, unsigned part, unsigned parts)
{
    pose_state *st = ctx;
    const pose__skin_mesh *mesh = &st->rt->skin;
    size_t b = pose__part_begin(mesh->block_count, part, parts);
    size_t e = pose__part_begin(mesh->block_count, part + 1, parts);
    pose__skin(pose__state_skin_method(st), mesh, st->palette, b, e, st->tet_positions);
}

void pose__state_transfer_task(void *ctx, unsigned part, unsigned parts)
{
    pose_state *st = ctx;
    const pose__transfer_mesh *mesh = &st->rt->transfer;
    size_t b = pose__part_begin(mesh->block_count, part, parts);
    size_t e = pose__part_begin(mesh->block_count, part + 1, parts);
    uint32_t *flagged = st->flagged + b * POSE__BLOCK;
    /* bone tissues by their joint, the others by the transfer (state_bones.c) */
    st->flagged_count[part] = pose__state_transfer_soft(st, b, e, flagged);
    pose__state_place_outside(st, b * POSE__BLOCK, e * POSE__BLOCK); /* rig_outside.c */
    pose__state_place_bones(st, b * POSE__BLOCK, e * POSE__BLOCK);
}

/* Normals of the vertices in flat or inverted tets, from their triangles:
 * needs every position, hence a pass of its own. */
void pose__state_fix_normals_task(void *ctx, unsigned part, unsigned parts)
{
    pose_state *st = ctx;
    const pose__transfer_mesh *mesh = &st->rt->transfer;
    size_t b = pose__part_begin(mesh->block_count, part, parts);
    pose__transfer_fix_normals(mesh, st->tissue_positions, st->flagged + b * POSE__BLOCK,
                               st->flagged_count[part], st->tissue_normals);
}

/* Small meshes run on the caller alone: waking workers would cost more
 * than the work (results are the same either way). */
static bool serial_frame(const pose_state *st)
{
    return st->rt->skin.block_count + st->rt->transfer.block_count < POSE__SERIAL_BLOCKS;
}

void pose__state_skin_pass(pose_state *st)
{
    const pose_rig *rig = st->rig;
    pose__fk(rig->joint_count, rig->joint_parents, st->rt->rest_model,
             (const float(*)[4])st->local, &st->root, st->skin, st->world);
    pose__skin_palette(rig->joint_count, st->skin, st->palette);
    if (serial_frame(st))
        pose__state_skin_task(st, 0, 1);
    else
        pose__pool_run(st->pool, pose__state_skin_task, st);
}

void pose__state_transfer_pass(pose_state *st)
{
    if (serial_frame(st)) {
        pose__state_transfer_task(st, 0, 1);
        if (st->flagged_count[0] > 0)
            pose__state_fix_normals_task(st, 0, 1);
        return;
    }
    pose__pool_run(st->pool, pose__state_transfer_task, st);
    size_t flagged = 0;
    for (unsigned p = 0; p < pose__pool_threads(st->pool); p++)
        flagged += st->flagged_count[p];
    if (flagged > 0)
        pose__pool_run(st->pool, pose__state_fix_normals_task, st);
}

pose_status pose_apply(pose_state *st)
{
    pose__clear_error();
    if (!st)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_apply: state is NULL");
    double t0 = st->method == POSE_FEM ? pose__seconds() : 0.0;
    pose__state_skin_pass(st);
    if (st->method == POSE_FEM) {
        double t1 = pose__seconds();
        st->fem_stats.seconds_skin = t1 - t0;
        pose__state_fem_refine(st); /* state_fem.c */
        t0 = pose__seconds();
    }
    /* Bone tissues follow their joint rigidly (state_bones.c) with every
     * method: the bake embeds part of each bone surface in soft tets (and
     * at joints a few vertices in the next bone's), which the skinning
     * bends and POSE_FEM's refinement moves (a femoral head 32 mm off its
     * femur at hip flexion 90 through the transfer); the contact response
     * pushes skin out of each bone as its joint moves it (contact_push.c). */
    pose__state_transfer_pass(st);
    if (st->method == POSE_FEM)
        st->fem_stats.seconds_transfer = pose__seconds() - t0;
    pose__state_push_cover(st); /* contact_push.c: skin over and out of bone, on the final positions */
    return POSE_OK;
}

size_t pose__state_frame_bytes(const pose_state *st)
{
    return pose__skin_bytes(pose__state_skin_method(st), &st->rt->skin) +
           pose__transfer_bytes(&st->rt->transfer, st->rig->tet_vertex_count, 1);
}

const float *pose_tissue_positions(const pose_state *st, int tissue, size_t *vertex_count)
{
    if (!st || tissue < 0 || (size_t)tissue >= st->rig->tissue_count)
        return NULL;
    if (vertex_count)
        *vertex_count = st->rig->tissues[tissue].vertex_count;
    return st->tissue_positions + 3 * st->rt->tissue_offset[tissue];
}

const float *pose_tissue_normals(const pose_state *st, int tissue, size_t *vertex_count)
{
    if (!st || tissue < 0 || (size_t)tissue >= st->rig->tissue_count)
        return NULL;
    if (vertex_count)
        *vertex_count = st->rig->tissues[tissue].vertex_count;
    return st->tissue_normals + 3 * st->rt->tissue_offset[tissue];
}

const float *pose_tet_positions(const pose_state *st, size_t *vertex_count)
{
    if (!st)
        return NULL;
    if (vertex_count)
        *vertex_count = st->rig->tet_vertex_count;
    return st->tet_positions;
}

pose_status pose_joint_world(const pose_state *st, int joint, pose_transform *out)
{
    pose__clear_error();
    if (!st || !out || joint < 0 || (size_t)joint >= st->rig->joint_count)
        return pose__fail(POSE_ERR_INVALID_ARGUMENT, "pose_joint_world: bad %s",
                          !st ? "state" : !out ? "output" : "joint index");
    memcpy(out->rotation, st->world[joint].q, sizeof out->rotation);
    memcpy(out->translation, st->world[joint].t, sizeof out->translation);
    return POSE_OK;
}
