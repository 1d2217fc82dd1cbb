/* One a-trous wavelet iteration of SVGF (docs/denoising.md; Schied et al. 2017, 4.3): a 5x5
 * B3-spline kernel with taps `step` pixels apart, each weighted by the edge-stopping functions
 * of depth, normal and luminance (the luminance scaled by the prefiltered standard deviation);
 * the variance is filtered with the squared weights. Taps outside the image are skipped: on
 * PoCL's CPU device this is 2x faster than clamped reads with zero weights (docs/denoising.md,
 * "Cost"), since its work-item loops are not vectorised either way (svgf_atrous_wide.cl runs
 * several pixels per work-item in vector lanes).
 * Per pixel and iteration (hand count, as svgf_temporal.cl): 11 + 3 per tap of the 3x3
 * prefilter + 6 x 5 for 1 / phi_z at the six tap distances (two multiplies, a multiply and an
 * add, a division) + (38 + P) per tap of the 5x5 kernel inside the image + 5 flops, P the normal
 * weight's power (7 for phi_normal 128, PG_SVGF_CONSTANT_POWER): 1198 inside the image; 52 bytes.
 * No surface: 1 flop, 48 bytes. */
/* Multiply-adds allowed (OpenCL C's default): the taps' sums and edge terms fuse, 5-6% of the
 * pass on PoCL's CPU device; no term cancels, so the host reference, which rounds each
 * operation, agrees within rounding (docs/denoising.md, "Multiply-adds in the a-trous pass"). */
#pragma OPENCL FP_CONTRACT ON

#include "shared/planar.h"
#include "shared/svgf.h"

/* The kernel's radius, a build option (SvgfSettings::atrous_radius): 2, the paper's 5x5, or 1,
 * a 3x3 (pg_svgf_atrous_weight). Fixed at build time so that the tap loops stay unrolled. */
#ifndef PG_SVGF_ATROUS_RADIUS
#define PG_SVGF_ATROUS_RADIUS 2
#endif

/* clang-format off */
__kernel void svgf_atrous(__global const float* in, __global float* out,
                          __global const float* surface, __global const float* depth_slope,
                          uint width, uint height, int step, pg_svgf_settings settings) {
  /* clang-format on */
  uint x = get_global_id(0), y = get_global_id(1);
  if (x >= width || y >= height) return;
  uint i = y * width + x, n = width * height;
  float4 sc = pg_planar_get(surface, n, i);
  float4 c = pg_planar_get(in, n, i);
  if (sc.w <= 0.0f) {
    pg_planar_set(out, n, i, c);
    return;
  }
  /* The centre's variance through a 3x3 Gaussian (taps inside the image, renormalised). */
  float sum_g = 0.0f, sum_gv = 0.0f;
  for (int dy = -1; dy <= 1; ++dy) {
    int qy = (int)y + dy;
    if (qy < 0 || qy >= (int)height) continue;
    for (int dx = -1; dx <= 1; ++dx) {
      int qx = (int)x + dx;
      if (qx < 0 || qx >= (int)width) continue;
      float g = pg_svgf_gauss3(dx, dy);
      sum_gv += g * in[3u * n + (uint)qy * width + (uint)qx];
      sum_g += g;
    }
  }
  float inverse_phi_l = pg_svgf_inverse_phi_luminance(sqrt(fmax(sum_gv / sum_g, 0.0f)), settings);
  float slope = depth_slope[i];
  float inverse_phi_z[PG_SVGF_SQUARED_DISTANCES(PG_SVGF_ATROUS_RADIUS)];
  pg_svgf_inverse_phi_depth_table(slope, sc.w, (float)step, PG_SVGF_ATROUS_RADIUS, settings,
                                  inverse_phi_z);
  float lc = pg_luminance(c.xyz);
  float3 sum_c = (float3)(0.0f);
  float sum_v = 0.0f, sum_w = 0.0f;
  for (int dy = -PG_SVGF_ATROUS_RADIUS; dy <= PG_SVGF_ATROUS_RADIUS; ++dy) {
    int qy = (int)y + dy * step;
    if (qy < 0 || qy >= (int)height) continue;
    for (int dx = -PG_SVGF_ATROUS_RADIUS; dx <= PG_SVGF_ATROUS_RADIUS; ++dx) {
      int qx = (int)x + dx * step;
      if (qx < 0 || qx >= (int)width) continue;
      uint j = (uint)qy * width + (uint)qx;
      float4 q = pg_planar_get(in, n, j);
      float w = pg_svgf_atrous_weight(dx, PG_SVGF_ATROUS_RADIUS) *
                pg_svgf_atrous_weight(dy, PG_SVGF_ATROUS_RADIUS) *
                pg_svgf_edge_weight(sc, lc, pg_planar_get(surface, n, j), pg_luminance(q.xyz),
                                    inverse_phi_z[pg_svgf_squared_distance(dx, dy)], inverse_phi_l,
                                    settings);
      sum_c += w * q.xyz;
      sum_v += w * w * q.w;
      sum_w += w;
    }
  }
  /* sum_w >= 9/64 (1/4 at radius 1): the centre's weight is its kernel weight squared times
   * exp(0). */
  pg_planar_set(out, n, i, (float4)(sum_c / sum_w, sum_v / (sum_w * sum_w)));
}
