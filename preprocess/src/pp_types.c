/* SPDX-License-Identifier: Apache-2.0
 *
 * Shared stage helpers and the destructors of the stage structs in pp_types.h. Each accepts NULL and
 * leaves the struct zeroed so a double free is harmless.
 */
#include "pp_types.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

double pp_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int pp_fail(char *err, size_t n, int status, const char *fmt, ...)
{
    if (err && n) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, n, fmt, ap);
        va_end(ap);
    }
    return status;
}

void pp_mesh_free(pp_mesh *m)
{
    if (!m)
        return;
    free(m->positions);
    free(m->triangles);
    memset(m, 0, sizeof *m);
}

void pp_voxels_free(pp_voxels *v)
{
    if (!v)
        return;
    free(v->labels);
    memset(v, 0, sizeof *v);
}

void pp_tetmesh_free(pp_tetmesh *t)
{
    if (!t)
        return;
    free(t->positions);
    free(t->tets);
    free(t->labels);
    memset(t, 0, sizeof *t);
}
