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

/* x in [-1, 1] as an 8-bit signed normalised integer (the low 8 bits of the result), and back. */
PG_FN uint pg_snorm8_bits(float x) {
  int i = (int)floor(clamp(x, -1.0f, 1.0f) * 127.0f + 0.5f);
  return (uint)i & 0xffu;
}
PG_FN float pg_snorm8_of(uint bits) {
  float v = (float)(bits & 0xffu) - (float)((bits & 0x80u) << 1);
  return fmax(v * (1.0f / 127.0f), -1.0f);
}
/* The 8-bit value k / 127 as the nearest 16-bit one, round(k 32767 / 127), in integers: the same
 * bits on every device. (Through the float value the codes k = +-63 and +-64 land within 0.004
 * of a half, so two devices' roundings could pick different neighbours; no k / 127 is a tie.) */
PG_FN uint pg_snorm8_to_snorm16_bits(uint bits) {
  int k = (int)(bits & 0xffu) - (int)((bits & 0x80u) << 1);
  int q = (k < -127 ? -127 : k) * 32767;
  return (uint)((q >= 0 ? q + 63 : q - 63) / 127) & 0xffffu; /* halves away from zero */
}

/* The largest angle between a unit vector and its packed copy, with margin (measured 6.4e-5 rad:
 * tests/guiding/test_vpl_packing.cpp), and for the 8-bit packing (measured 1.65e-2 rad). */
#define PG_OCTAHEDRAL_MAX_ANGLE 1e-4f
#define PG_OCTAHEDRAL8_MAX_ANGLE 2e-2f

/* A unit vector n's point on the octahedron |x| + |y| + |z| = 1, the lower half folded over the
 * square's diagonals (Cigolle et al. 2014, "A Survey of Efficient Representations for
 * Independent Unit Vectors"): a point of [-1, 1]^2. The zero vector (a distant VPL's normal,
 * which nobody reads) maps to the pole +z. */
PG_FN float2 pg_octahedral_point(float3 n) {
  float l1 = fabs(n.x) + fabs(n.y) + fabs(n.z);
  float inv = l1 > 0.0f ? 1.0f / l1 : 0.0f;
  float px = n.x * inv, py = n.y * inv;
  if (n.z < 0.0f) {
    float fx = (1.0f - fabs(py)) * (px >= 0.0f ? 1.0f : -1.0f);
    float fy = (1.0f - fabs(px)) * (py >= 0.0f ? 1.0f : -1.0f);
    px = fx;
    py = fy;
  }
  return pg_make_float2(px, py);
}
/* The inverse up to length: the point on the octahedron (unnormalised). */
PG_FN float3 pg_octahedral_unfold(float x, float y) {
  float z = 1.0f - fabs(x) - fabs(y);
  float t = fmax(-z, 0.0f); /* the folded half: move x and y back towards the axes */
  x += x >= 0.0f ? -t : t;
  y += y >= 0.0f ? -t : t;
  return pg_make_float3(x, y, z);
}

/* n as two 16-bit signed normalised integers of its octahedral point. */
PG_FN uint pg_pack_unit_vector(float3 n) {
  float2 p = pg_octahedral_point(n);
  return pg_snorm16_bits(p.x) | (pg_snorm16_bits(p.y) << 16);
}
PG_FN float3 pg_unpack_unit_vector(uint bits) {
  float3 v = pg_octahedral_unfold(pg_snorm16_of(bits), pg_snorm16_of(bits >> 16));
  return v * (1.0f / sqrt(v.x * v.x + v.y * v.y + v.z * v.z));
}
/* n as two 8-bit ones (the low 16 bits of the result). */
PG_FN uint pg_pack_unit_vector8(float3 n) {
  float2 p = pg_octahedral_point(n);
  return pg_snorm8_bits(p.x) | (pg_snorm8_bits(p.y) << 8);
}
PG_FN float3 pg_unpack_unit_vector8(uint bits) {
  float3 v = pg_octahedral_unfold(pg_snorm8_of(bits), pg_snorm8_of(bits >> 8));
  return v * (1.0f / sqrt(v.x * v.x + v.y * v.y + v.z * v.z));
}
/* The 16-bit code (pg_pack_unit_vector) of the octahedral point an 8-bit code
 * (pg_pack_unit_vector8) holds: the same direction within the 16-bit rounding, without a square
 * root or a division. On the square's border, whose opposite halves fold onto the same
 * directions, it keeps the side the 8-bit code has. */
PG_FN uint pg_unit_vector8_to_16(uint bits) {
  return pg_snorm8_to_snorm16_bits(bits) | (pg_snorm8_to_snorm16_bits(bits >> 8) << 16);
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

/* An rgb radiance as one word with a shared exponent (Ward's RGBE, "Real Pixels", Graphics Gems
 * II, 1991): r, g and b as 8-bit mantissas (bits 0-7, 8-15, 16-23) of 2^(e - 8), e + 128 in bits
 * 24-31, e the exponent that puts the largest channel m in [2^(e-1), 2^e). Each channel is
 * rounded to the nearest multiple of 2^(e - 8): the largest within 2^-8 of its value, each other
 * within 2^-7 m (2^-8 m but where m rounds up to 2^e and e grows by one). Negative and NaN channels
 * count as 0; m below 2^-100 (8e-31) gives black and m at or above 2^127 saturates. Exact scalings
 * by powers of two (float bits), so the same bits in OpenCL C and C++. */
PG_FN float pg_power_of_two(int e) { /* 2^e for e in [-126, 127] */
  return as_float((uint)(e + 127) << 23);
}
PG_FN uint pg_pack_rgbe(float3 c) {
  float r = c.x > 0.0f ? c.x : 0.0f, g = c.y > 0.0f ? c.y : 0.0f, b = c.z > 0.0f ? c.z : 0.0f;
  float m = fmax(r, fmax(g, b));
  if (!(m >= 7.8886091e-31f)) return 0u;           /* 2^-100, or NaN */
  m = fmin(m, 1.7014117e38f);                      /* 2^127 - its last bit: e at most 127 */
  int e = (int)((as_uint(m) >> 23) & 0xffu) - 126; /* m in [2^(e-1), 2^e) */
  float scale = pg_power_of_two(8 - e);
  if (floor(m * scale + 0.5f) > 255.0f && e < 127) { /* rounds up to the next power */
    e += 1;
    scale = pg_power_of_two(8 - e);
  }
  uint mr = (uint)fmin(floor(fmin(r, 1.7014117e38f) * scale + 0.5f), 255.0f);
  uint mg = (uint)fmin(floor(fmin(g, 1.7014117e38f) * scale + 0.5f), 255.0f);
  uint mb = (uint)fmin(floor(fmin(b, 1.7014117e38f) * scale + 0.5f), 255.0f);
  return mr | (mg << 8) | (mb << 16) | ((uint)(e + 128) << 24);
}
PG_FN float3 pg_unpack_rgbe(uint bits) {
  if (bits == 0u) return pg_make_float3(0.0f, 0.0f, 0.0f);
  float unit = pg_power_of_two((int)(bits >> 24) - 128 - 8);
  return pg_make_float3((float)(bits & 0xffu) * unit, (float)((bits >> 8) & 0xffu) * unit,
                        (float)((bits >> 16) & 0xffu) * unit);
}

PG_NAMESPACE_END

#endif
