/* The first-bounce samples as they cross the bus back to the host (include/rtpg/
 * guiding_layout.h, "Packed samples"): 12 bytes a pixel instead of the 20 of direction_pdf and
 * strategy. The pack_samples kernel (kernels/pack_samples.cl) writes them, the host renderer
 * reads them (host/render/first_bounce.h, FirstBounceSamples::at).
 *
 * The direction travels as its point on the octahedron |x| + |y| + |z| = 1, the lower half folded
 * over the square's diagonals (the VPL's packed normal, kernels/shared/bit_packing.h, without
 * its 16-bit rounding), in two floats: decoded within 5e-7 rad of the sampled direction (measured
 * 3.5e-7 over 10^6 directions, tests/guiding/test_sample_packing.cpp), a few times the rounding
 * that storing it in three floats already makes. The host traces the decoded direction and
 * divides by the density of the sampled one; the two differ by that angle times the density's
 * gradient (relative 1e-4 at three standard deviations of the sharpest lobe the regularisation
 * allows), an error of either sign from pixel to pixel, not a bias the estimate collects. The
 * density travels exactly; its sign bit carries the strategy (set: the Gaussian's sample,
 * PG_STRATEGY_GUIDE); a density of 0 with the bit clear is "no sample" (PG_STRATEGY_NONE), which
 * the renderer treats as it treats a zero density of any strategy. */
#ifndef RTPG_SHARED_SAMPLE_PACKING_H
#define RTPG_SHARED_SAMPLE_PACKING_H

#include "rtpg/guiding_layout.h"
#include "shared/bit_packing.h"
#include "shared/compat.h"

PG_NAMESPACE_BEGIN

/* The direction's octahedral point (kernels/shared/bit_packing.h) as it is, and back. */
PG_FN float2 pg_pack_direction(float3 d) {
  return pg_octahedral_point(d);
}
PG_FN float3 pg_unpack_direction(float2 p) {
  return normalize(pg_octahedral_unfold(p.x, p.y));
}

/* The density with the strategy in its sign bit, and back. */
PG_FN float pg_pack_sample_density(float pdf, uint strategy) {
  uint bits = as_uint(pdf) & 0x7fffffffu;
  return as_float(strategy == PG_STRATEGY_GUIDE ? bits | 0x80000000u : bits);
}
PG_FN float pg_sample_density_of(float packed) {
  return as_float(as_uint(packed) & 0x7fffffffu);
}
PG_FN uint pg_sample_strategy_of(float packed) {
  uint bits = as_uint(packed);
  return (bits & 0x80000000u) != 0u   ? PG_STRATEGY_GUIDE
         : (bits & 0x7fffffffu) != 0u ? PG_STRATEGY_BSDF
                                      : PG_STRATEGY_NONE;
}

PG_NAMESPACE_END

#endif
