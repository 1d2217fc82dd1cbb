/* Small encodings of floats and unit vectors that the packed buffers share (the VPLs' packed
 * channel, kernels/shared/vpl_packing.h; the G-buffer as it crosses the bus, kernels/shared/
 * gbuffer_packing.h). Each packer here has its unpacker, in integer and float arithmetic that
 * gives the same bits in OpenCL C and in C++ (tests/guiding/test_vpl_packing.cpp and
 * test_gbuffer_packing.cpp check both sides). */
#ifndef RTPG_SHARED_BIT_PACKING_H
#define RTPG_SHARED_BIT_PACKING_H

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

/* v rounded to the nearest IEEE half float, ties to even (the low 16 bits of the result), by
 * integer arithmetic on the float's bits, so host and device agree without cl_khr_fp16 or F16C.
 * Magnitudes above the largest half (65504) become it, not infinity; v must not be NaN. Below
 * 2^-14 the result is subnormal (steps of 2^-24). */
PG_FN uint pg_half_bits(float v) {
  uint sign = (as_uint(v) >> 16) & 0x8000u;
  float a = fmin(fabs(v), 65504.0f);
  if (a < 6.103515625e-05f) {
    /* Subnormal: a / 2^-24 rounded to the nearest integer, ties to even (exact in float: a is a
     * multiple of 2^-149 below 2^-14, so the product's fraction is exact). 1024 is the smallest
     * normal half's bits, correctly. */
    float scaled = a * 16777216.0f;
    float whole = floor(scaled);
    float rest = scaled - whole;
    uint m = (uint)whole;
    m += (rest > 0.5f || (rest == 0.5f && (m & 1u) != 0u)) ? 1u : 0u;
    return sign | m;
  }
  uint rebiased = as_uint(a) - ((127u - 15u) << 23);
  return sign | ((rebiased + 0xfffu + ((rebiased >> 13) & 1u)) >> 13);
}

/* The low 16 bits of `bits` as the half float's value (finite halves only: pg_half_bits never
 * makes another). */
PG_FN float pg_float_of_half(uint bits) {
  uint magnitude = bits & 0x7fffu;
  float a = magnitude < 0x0400u ? (float)magnitude * 5.9604644775390625e-08f
                                : as_float((magnitude << 13) + ((127u - 15u) << 23));
  return (bits & 0x8000u) != 0u ? -a : a;
}

/* Two floats as halves in one word, x in the low half. */
PG_FN uint pg_pack_half2(float x, float y) {
  return pg_half_bits(x) | (pg_half_bits(y) << 16);
}

PG_NAMESPACE_END

#endif
