/* cos and sin for the samplers (the concentric disk, the GGX visible-normal sampler, the
 * Gaussian's Box-Muller step) without library calls: PoCL's vector sin and cos cost about a
 * quarter of the sample kernel (docs/guiding.md, "Sine and cosine by polynomials"). The
 * polynomials are Cephes' single-precision sinf and cosf kernels on [-pi/4, pi/4] (about 1 ulp
 * there); a full turn is reduced to that octant exactly, in the units of the turn. Host and
 * device run the same operations, so their samples stay equal (tests/guiding). */
#ifndef RTPG_SHARED_SINCOS_H
#define RTPG_SHARED_SINCOS_H

#include "shared/compat.h"

PG_NAMESPACE_BEGIN

/* (cos a, sin a) for |a| <= pi/4. */
PG_FN float2 pg_cos_sin_octant(float a) {
  float z = a * a;
  float s = ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f) * z * a + a;
  float c =
      ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f) * z * z -
      0.5f * z + 1.0f;
  return pg_make_float2(c, s);
}

/* (cos 2 pi u, sin 2 pi u) for u in [0, 1]: the nearest quarter turn q = floor(4u + 1/2) and
 * the rest f = 4u - q in [-1/2, 1/2] (both exact: 4u scales by a power of two), so the angle
 * left is (pi/2) f in [-pi/4, pi/4]; the quarter turns rotate it. */
PG_FN float2 pg_cos_sin_turn(float u) {
  float four_u = 4.0f * u;
  float q = floor(four_u + 0.5f);
  float2 cs = pg_cos_sin_octant((PG_PI / 2.0f) * (four_u - q));
  int quarter = (int)q & 3;
  if (quarter == 1) return pg_make_float2(-cs.y, cs.x);
  if (quarter == 2) return pg_make_float2(-cs.x, -cs.y);
  if (quarter == 3) return pg_make_float2(cs.y, -cs.x);
  return cs;
}

PG_NAMESPACE_END

#endif
