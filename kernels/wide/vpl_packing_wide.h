/* The VPLs' packed channel (kernels/shared/vpl_packing.h) unpacked for PG_LANES VPLs at once
 * (kernels/wide/lanes.h), lane by lane the same operations as the scalar functions named on
 * each. OpenCL C only. */
#ifndef RTPG_WIDE_VPL_PACKING_WIDE_H
#define RTPG_WIDE_VPL_PACKING_WIDE_H

#include "wide/lanes.h"

#define pg_as_floatw PG_PASTE(as_float, PG_LANES)

/* pg_snorm16_of per lane. */
static inline pg_floatw pg_snorm16_of_w(pg_uintw bits) {
  pg_floatw v = pg_convert_floatw(bits & 0xffffu) - pg_convert_floatw((bits & 0x8000u) << 1);
  return fmax(v * (1.0f / 32767.0f), -1.0f);
}

/* pg_unpack_unit_vector per lane. */
static inline pg_float3w pg_unpack_unit_vector_w(pg_uintw bits) {
  pg_floatw x = pg_snorm16_of_w(bits), y = pg_snorm16_of_w(bits >> 16);
  pg_floatw z = 1.0f - fabs(x) - fabs(y);
  pg_floatw t = fmax(-z, 0.0f);
  x += select(t, -t, x >= 0.0f);
  y += select(t, -t, y >= 0.0f);
  return pg_scale3w(pg_make_float3w(x, y, z), 1.0f / sqrt(x * x + y * y + z * z));
}

/* pg_vpl_radiance per lane (the channel's z and w). */
static inline pg_float3w pg_vpl_radiance_w(pg_uintw z, pg_uintw w) {
  return pg_make_float3w(pg_as_floatw(z << 16), pg_as_floatw(z & 0xffff0000u),
                         pg_as_floatw(w << 16));
}

#endif
