/* SPDX-License-Identifier: Apache-2.0 */
/* The dynamics' tet passes for the baseline target. */
#define POSE__KV(name) name##_generic
#include "fem_dyn_tets_body.h"
