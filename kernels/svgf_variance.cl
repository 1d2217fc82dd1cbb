/* SVGF's variance estimate (docs/denoising.md; Schied et al. 2017, 4.2): the luminance variance
 * from the temporal moments where the history holds min_history frames or more, else from the
 * moments of a 7x7 neighbourhood weighted by depth and normal (the illumination is averaged the
 * same way there). Writes illumination (rgb) with its variance (w), the input of the first
 * a-trous iteration.
 * Per pixel (hand count, as svgf_temporal.cl): 5 flops and 64 bytes where the history is long
 * enough; else 15 + 10 x 5 (1 / phi_z at each squared tap distance: two multiplies, a multiply
 * and an add, a division) + (36 + P) per tap inside the image and 68 bytes, P = the normal weight's
 * power (a squaring per bit of phi_normal below the top one, a multiply per set bit after the
 * first: 7 for 128); no surface: 1 flop, 32 bytes.
 */
/* Multiply-adds allowed, as in the a-trous pass (docs/denoising.md, "Multiply-adds in the a-trous
 * pass"): 8-9% of the spatial estimate on PoCL's CPU device. */
#pragma OPENCL FP_CONTRACT ON

#include "shared/planar.h"
#include "shared/svgf.h"

/* clang-format off */
__kernel void svgf_variance(__global const float* integrated, __global const float* moments,
                            __global const float* surface, __global const float* depth_slope,
                            __global float* illumination, uint width, uint height,
                            pg_svgf_settings settings) {
  /* clang-format on */
  uint x = get_global_id(0), y = get_global_id(1);
  if (x >= width || y >= height) return;
  uint i = y * width + x, n = width * height;
  float4 sc = pg_planar_get(surface, n, i);
  if (sc.w <= 0.0f) {
    pg_planar_set(illumination, n, i, (float4)(0.0f));
    return;
  }
  float4 mc = pg_planar_get(moments, n, i);
  float4 ic = pg_planar_get(integrated, n, i);
  if (mc.z >= settings.min_history) {
    float v = pg_svgf_variance(mc.x, mc.y, mc.z, settings.min_history);
    pg_planar_set(illumination, n, i, (float4)(ic.xyz, v));
    return;
  }
  float slope = depth_slope[i];
  float inverse_phi_z[PG_SVGF_SQUARED_DISTANCES(3)];
  pg_svgf_inverse_phi_depth_table(slope, sc.w, 1.0f, 3, settings, inverse_phi_z);
  float lc = pg_luminance(ic.xyz);
  float3 sum_c = (float3)(0.0f);
  float sum_m1 = 0.0f, sum_m2 = 0.0f, sum_w = 0.0f;
  for (int dy = -3; dy <= 3; ++dy) {
    int qy = (int)y + dy;
    if (qy < 0 || qy >= (int)height) continue;
    for (int dx = -3; dx <= 3; ++dx) {
      int qx = (int)x + dx;
      if (qx < 0 || qx >= (int)width) continue;
      uint j = (uint)qy * width + (uint)qx;
      float4 iq = pg_planar_get(integrated, n, j);
      float w =
          pg_svgf_edge_weight(sc, lc, pg_planar_get(surface, n, j), pg_luminance(iq.xyz),
                              inverse_phi_z[pg_svgf_squared_distance(dx, dy)], 0.0f, settings);
      float4 mq = pg_planar_get(moments, n, j);
      sum_c += w * iq.xyz;
      sum_m1 += w * mq.x;
      sum_m2 += w * mq.y;
      sum_w += w;
    }
  }
  /* sum_w >= 1: the centre's own weight is exp(0). */
  float v = pg_svgf_variance(sum_m1 / sum_w, sum_m2 / sum_w, mc.z, settings.min_history);
  pg_planar_set(illumination, n, i, (float4)(sum_c / sum_w, v));
}
