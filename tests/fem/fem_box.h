/* SPDX-License-Identifier: Apache-2.0 */
/* Test fixtures of the FEM tests: a box of tets and its simulation mesh.
 * Include after cmocka.h (the fixtures assert). */
#ifndef POSE_TEST_FEM_BOX_H
#define POSE_TEST_FEM_BOX_H

#include <stdint.h>
#include <stdlib.h>

#include "fem_mesh.h"
#include "fem_solve.h"

/* A box of nx x ny x nz cells of size d, each split into 6 tets around its
 * main diagonal (Kuhn: neighbouring cells share faces exactly). Cells with
 * i < bone_cells are labelled bone of joint 0. */
typedef struct box {
    size_t nv, nt;
    float *pos;
    uint32_t *tets;
    uint16_t *labels;
    int nx, ny, nz;
} box;

static inline uint32_t vid(const box *b, int i, int j, int k)
{
    return (uint32_t)((i * (b->ny + 1) + j) * (b->nz + 1) + k);
}

static inline box make_box(int nx, int ny, int nz, float d, int bone_cells)
{
    box b = {.nx = nx, .ny = ny, .nz = nz};
    b.nv = (size_t)(nx + 1) * (ny + 1) * (nz + 1);
    b.nt = (size_t)6 * nx * ny * nz;
    b.pos = malloc(3 * b.nv * sizeof(float));
    b.tets = malloc(4 * b.nt * sizeof(uint32_t));
    b.labels = malloc(b.nt * sizeof(uint16_t));
    assert_true(b.pos && b.tets && b.labels);
    for (int i = 0; i <= nx; i++)
        for (int j = 0; j <= ny; j++)
            for (int k = 0; k <= nz; k++) {
                float *p = b.pos + 3 * (size_t)vid(&b, i, j, k);
                p[0] = (float)i * d;
                p[1] = (float)j * d;
                p[2] = (float)k * d;
            }
    /* the 6 paths from corner 0 to corner 7 through the cube's corners */
    static const int path[6][2] = {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}};
    size_t t = 0;
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++)
            for (int k = 0; k < nz; k++) {
                uint32_t c[8];
                for (int n = 0; n < 8; n++)
                    c[n] = vid(&b, i + (n & 1), j + ((n >> 1) & 1), k + ((n >> 2) & 1));
                for (int p = 0; p < 6; p++, t++) {
                    uint32_t *tt = b.tets + 4 * t;
                    tt[0] = c[0];
                    tt[1] = c[path[p][0]];
                    tt[2] = c[path[p][1]];
                    tt[3] = c[7];
                    b.labels[t] = i < bone_cells ? 1 : 0;
                }
            }
    return b;
}

static inline void free_box(box *b)
{
    free(b->pos);
    free(b->tets);
    free(b->labels);
}

typedef struct sim {
    pose__fem_mesh mesh;
    pose__fem_work work;
    void *mesh_mem, *work_mem;
} sim;

static inline void make_sim(sim *s, const box *b, pose__fem_material m)
{
    size_t size = pose__fem_mesh_size(b->nv, b->nt, b->tets, b->labels);
    assert_true(size > 0);
    assert_int_equal(posix_memalign(&s->mesh_mem, 64, size), 0);
    assert_int_equal(pose__fem_mesh_build(b->nv, b->pos, b->nt, b->tets, b->labels, &m,
                                          s->mesh_mem, &s->mesh), 0);
    assert_int_equal(posix_memalign(&s->work_mem, 64, pose__fem_work_size(&s->mesh)), 0);
    pose__fem_work_init(&s->mesh, s->work_mem, &s->work);
}

static inline void free_sim(sim *s)
{
    free(s->mesh_mem);
    free(s->work_mem);
}

#endif /* POSE_TEST_FEM_BOX_H */
