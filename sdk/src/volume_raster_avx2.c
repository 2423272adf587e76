/* SPDX-License-Identifier: Apache-2.0
 * The rasterizer (volume_raster_body.h) compiled with -mavx2
 * (sdk/CMakeLists.txt); called only when the CPU has AVX2. Empty on other
 * architectures. */
#include "volume_internal.h"

#ifdef POSE__HAVE_AVX2_VOLUME
#  define POSE__VR(name) name##_avx2
#  include "volume_raster_body.h"
#else
typedef int pose__no_avx2_raster; /* ISO C wants a non-empty file */
#endif
