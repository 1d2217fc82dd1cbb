/* The VPL's packed channel, normal_radiance (include/rtpg/guiding_layout.h, "VPLs"): the
 * writer (the host path tracer, or a library user) packs, the train kernels and the host
 * reference unpack. 32 bytes a VPL instead of 48: every VPL crosses the bus once a frame where
 * the device has its own memory, and a GPU's VPL tile in local memory is a third smaller
 * (docs/guiding.md, "The train benchmark trained on nothing; VPLs in 32 bytes").
 *   x  the geometric normal at y, octahedral (two 16-bit signed normalised integers, x in the
 *      low half): angular error under 1e-4
 *   y  the mixture density D, the float's bits (exact)
 *   z  radiance r and g as bfloat16 (the float's top 16 bits: its 8 exponent bits hold a sun's
 *      radiance, which overflows a half float; relative error at most 2^-8), r in the low half
 *   w  radiance b as bfloat16 in the low half, the info word (PG_VPL_* bits, the strategy in
 *      bits 8..15) in the high half
 * Training only reads these (the samples' weights and their densities' Jacobian), and the
 * renderer's estimate never does, so their rounding moves where the guide points, not what a
 * pixel converges to. */
#ifndef RTPG_SHARED_VPL_PACKING_H
#define RTPG_SHARED_VPL_PACKING_H

#include "shared/compat.h"

PG_NAMESPACE_BEGIN

/* x in [-1, 1] as a 16-bit signed normalised integer (the low 16 bits of the result). */
PG_FN uint pg_snorm16_bits(float x) {
  int i = (int)floor(clamp(x, -1.0f, 1.0f) * 32767.0f + 0.5f);
  return (uint)i & 0xffffu;
}

/* The inverse: the low 16 bits of `bits` as a value in [-1, 1]. */
PG_FN float pg_snorm16_of(uint bits) {
  float v = (float)(bits & 0xffffu) - (float)((bits & 0x8000u) << 1);
  return fmax(v * (1.0f / 32767.0f), -1.0f);
}

/* The largest angle between a unit vector and its packed copy, with margin (measured 6.4e-5 rad:
 * tests/guiding/test_vpl_packing.cpp). */
#define PG_OCTAHEDRAL_MAX_ANGLE 1e-4f

/* A unit vector n on the octahedron |x| + |y| + |z| = 1, the lower half folded over the
 * square's diagonals (Cigolle et al. 2014, "A Survey of Efficient Representations for
 * Independent Unit Vectors"), as two 16-bit signed normalised integers. The zero vector (a
 * distant VPL's normal, which nobody reads) packs as the pole +z. */
PG_FN uint pg_pack_unit_vector(float3 n) {
  float l1 = fabs(n.x) + fabs(n.y) + fabs(n.z);
  float inv = l1 > 0.0f ? 1.0f / l1 : 0.0f;
  float px = n.x * inv, py = n.y * inv;
  if (n.z < 0.0f) {
    float fx = (1.0f - fabs(py)) * (px >= 0.0f ? 1.0f : -1.0f);
    float fy = (1.0f - fabs(px)) * (py >= 0.0f ? 1.0f : -1.0f);
    px = fx;
    py = fy;
  }
  return pg_snorm16_bits(px) | (pg_snorm16_bits(py) << 16);
}

PG_FN float3 pg_unpack_unit_vector(uint bits) {
  float x = pg_snorm16_of(bits), y = pg_snorm16_of(bits >> 16);
  float z = 1.0f - fabs(x) - fabs(y);
  float t = fmax(-z, 0.0f); /* the folded half: move x and y back towards the axes */
  x += x >= 0.0f ? -t : t;
  y += y >= 0.0f ? -t : t;
  return pg_make_float3(x, y, z) * (1.0f / sqrt(x * x + y * y + z * z));
}

/* v rounded to the nearest bfloat16, ties to even (the low 16 bits of the result). Finite
 * values above the largest bfloat16 (3.39e38) become it instead of rounding to infinity. */
PG_FN uint pg_bfloat16_bits(float v) {
  uint u = as_uint(clamp(v, -3.3895314e38f, 3.3895314e38f));
  return (u + 0x7fffu + ((u >> 16) & 1u)) >> 16;
}

/* The low 16 bits of `bits` as the float they round. */
PG_FN float pg_float_of_bfloat16(uint bits) {
  return as_float(bits << 16);
}

/* The channel's x and y, which the writer knows at the VPL's hit. */
PG_FN uint pg_pack_vpl_normal(float3 normal) {
  return pg_pack_unit_vector(normal);
}
PG_FN uint pg_pack_vpl_density(float mixture_density) {
  return as_uint(mixture_density);
}
/* Its z and w, known when the path from y has been traced. info fits in 16 bits. */
PG_FN uint pg_pack_vpl_radiance_rg(float3 radiance) {
  return pg_bfloat16_bits(radiance.x) | (pg_bfloat16_bits(radiance.y) << 16);
}
PG_FN uint pg_pack_vpl_radiance_b_info(float3 radiance, uint info) {
  return pg_bfloat16_bits(radiance.z) | (info << 16);
}
PG_FN uint4 pg_pack_vpl_normal_radiance(float3 normal, float mixture_density, float3 radiance,
                                        uint info) {
  return pg_make_uint4(pg_pack_vpl_normal(normal), pg_pack_vpl_density(mixture_density),
                       pg_pack_vpl_radiance_rg(radiance),
                       pg_pack_vpl_radiance_b_info(radiance, info));
}

PG_FN float3 pg_vpl_normal(uint4 packed) {
  return pg_unpack_unit_vector(packed.x);
}
PG_FN float pg_vpl_mixture_density(uint4 packed) {
  return as_float(packed.y);
}
PG_FN float3 pg_vpl_radiance(uint4 packed) {
  return pg_make_float3(pg_float_of_bfloat16(packed.z), pg_float_of_bfloat16(packed.z >> 16),
                        pg_float_of_bfloat16(packed.w));
}
PG_FN uint pg_vpl_info(uint4 packed) {
  return packed.w >> 16;
}

PG_NAMESPACE_END

#endif
