/* SPDX-License-Identifier: Apache-2.0
 *
 * Destructors of the stage structs in pp_types.h. Each accepts NULL and
 * leaves the struct zeroed so a double free is harmless.
 */
#include "pp_types.h"

#include <stdlib.h>
#include <string.h>

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
