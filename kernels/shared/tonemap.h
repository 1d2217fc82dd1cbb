/* Display transform and frame accumulation, shared by kernels/tonemap.cl,
 * kernels/accumulate.cl and the host code and tests that must produce the same pixels.
 *
 * The tonemap is fixed (no parameters besides exposure):
 *   1. x = radiance * exposure per channel; a non-finite input channel (NaN, +-Inf: a broken
 *      sample, not a bright one) gives 0, and negative values clamp to 0;
 *   2. the ACES filmic curve as fitted by Narkowicz 2015 ("ACES Filmic Tone Mapping Curve"):
 *      x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped to [0, 1];
 *   3. the sRGB OETF (IEC 61966-2-1): 12.92 c below 0.0031308, else 1.055 c^(1/2.4) - 0.055;
 *   4. rounded to 8 bits: floor(255 c + 0.5). Alpha is 255.
 * Device and host agree to the last bit except where the device's exp/log (OpenCL allows
 * 3 ulp) differ from the host's and 255 c lands within that error of a rounding boundary:
 * then one channel differs by one. */
#ifndef RTPG_SHARED_TONEMAP_H
#define RTPG_SHARED_TONEMAP_H

#include "shared/compat.h"

PG_NAMESPACE_BEGIN

/* The curve reaches 1 at x = 7.24; clamping the input far above that keeps x * x finite. */
#define PG_TONEMAP_MAX_INPUT 1.0e4f

PG_FN float pg_tonemap_aces(float x) {
  x = clamp(x, 0.0f, PG_TONEMAP_MAX_INPUT);
  float y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
  return clamp(y, 0.0f, 1.0f);
}

/* Linear [0, 1] to sRGB-encoded [0, 1]. c^(1/2.4) as exp(log(c) / 2.4): OpenCL's pow may be
 * 16 ulp off, exp and log 3 ulp, so this form stays closer to the host's result. */
PG_FN float pg_srgb_encode(float c) {
  if (c <= 0.0031308f) return 12.92f * fmax(c, 0.0f);
  return 1.055f * exp(log(c) * (1.0f / 2.4f)) - 0.055f;
}

/* One channel of radiance to its 8-bit sRGB code, 0..255. */
PG_FN uint pg_tonemap_channel8(float radiance, float exposure) {
  if (!isfinite(radiance)) return 0u;
  float x = radiance * exposure; /* NaN only for a NaN exposure: the clamp below maps it to 0 */
  float c = pg_srgb_encode(pg_tonemap_aces(x));
  return (uint)(clamp(c, 0.0f, 1.0f) * 255.0f + 0.5f);
}

/* A pixel as packed RGBA8: red in the low byte, alpha (255) in the high byte, i.e. the
 * bytes R, G, B, A in memory on a little-endian machine. */
PG_FN uint pg_tonemap_to_srgb8(float4 radiance, float exposure) {
  uint r = pg_tonemap_channel8(radiance.x, exposure);
  uint g = pg_tonemap_channel8(radiance.y, exposure);
  uint b = pg_tonemap_channel8(radiance.z, exposure);
  return r | (g << 8) | (b << 16) | (255u << 24);
}

/* Running mean over frames: with weight_new = 1 / (n + 1) for the n-th frame (n from 0),
 * sum holds the mean of frames 0..n. Weight 1 (the first frame after a reset) replaces the
 * sum, whatever it held (even NaN), so a reset need not clear it. Written out rather than
 * mix() so both languages do the same two roundings (the kernels turn off FP contraction). */
PG_FN float4 pg_accumulate(float4 sum, float4 frame, float weight_new) {
  if (weight_new >= 1.0f) return frame;
  return sum + (frame - sum) * weight_new;
}

PG_NAMESPACE_END

#endif /* RTPG_SHARED_TONEMAP_H */
