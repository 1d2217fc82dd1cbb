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

#include "rtpg/guiding_layout.h"
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

/* ---- The VPLs on the bus (include/rtpg/guiding_layout.h, "Packed VPLs") ------------------
 * The host sends a VPL's distance from the pixel's point x0 (+infinity for an escaped ray, 0 for
 * no VPL), its normal (pg_pack_unit_vector8) and its radiance (pg_pack_rgbe), which the path
 * tracer writes where it finds them (host/render/vpl_buffer.h, VplBuffer::packed); the
 * device puts y at that distance along the direction it sampled for the pixel (sample 0's
 * direction_pdf), and takes the densities from that sample: D, and the strategy's (the BSDF's
 * density at the direction for a BSDF sample, which the unpack kernel evaluates with its
 * G-buffer, else D), both in area measure at y by the cosine at y over the distance squared as
 * the path tracer converts them (host/render/path_tracer.cpp). The device's x0 and direction
 * are the host's to a few units in the last place (kernels/shared/gbuffer_packing.h,
 * sample_packing.h); the normal comes within PG_OCTAHEDRAL8_MAX_ANGLE, and the cosine at y that
 * converts this pixel's densities is taken with the normal the train kernel will read, so that
 * a neighbour's conversion (its cosine over this one) keeps its accuracy where the two views of
 * y are alike; the radiance rounds to 8-bit shared-exponent mantissas (within 2^-7 of the
 * brightest channel). All of it moves where the guide points, not what a pixel converges to:
 * the training alone reads VPLs. */
typedef struct {
  float4 position;
  uint4 normal_radiance;
} pg_vpl;

/* What the device rebuilds: x0 its pixel's point, direction_pdf and strategy the pixel's first
 * sample (PG_SAMPLE_CHANNELS), bsdf_pdf the BSDF's solid-angle density at that direction (read
 * only for a BSDF sample). A VPL the host did not send (distance 0), or whose densities are not
 * positive and finite here, comes back invalid: every word 0. */
PG_FN pg_vpl pg_unpack_vpl(uint distance, uint radiance, uint normal, float3 x0,
                           float4 direction_pdf, uint strategy, float bsdf_pdf) {
  pg_vpl v;
  v.position = pg_make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  v.normal_radiance = pg_make_uint4(0u, 0u, 0u, 0u);
  float d = as_float(distance);
  if (!(d > 0.0f)) return v;
  float3 w = pg_float4_xyz(direction_pdf);
  float density = direction_pdf.w;
  float strategy_pdf = strategy == PG_STRATEGY_BSDF ? bsdf_pdf : density;
  uint info = PG_VPL_VALID | (strategy << PG_VPL_STRATEGY_SHIFT);
  uint normal_bits = pg_unit_vector8_to_16(normal); /* as train reads it */
  float3 y = w;
  if (isfinite(d)) {
    float cos_y = fabs(dot(pg_unpack_unit_vector(normal_bits), w));
    float to_area = cos_y / (d * d);
    strategy_pdf *= to_area;
    density *= to_area;
    y = x0 + w * d;
  } else {
    info |= PG_VPL_DISTANT;
  }
  if (!(strategy_pdf > 0.0f && isfinite(strategy_pdf)) || !isfinite(density)) return v;
  float3 l = pg_unpack_rgbe(radiance);
  v.position = pg_make_float4(y.x, y.y, y.z, strategy_pdf);
  v.normal_radiance =
      pg_make_uint4(normal_bits, pg_pack_vpl_density(density), pg_pack_vpl_radiance_rg(l),
                    pg_pack_vpl_radiance_b_info(l, info));
  return v;
}

PG_NAMESPACE_END

#endif
