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

#include "shared/bit_packing.h"

PG_NAMESPACE_BEGIN

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
