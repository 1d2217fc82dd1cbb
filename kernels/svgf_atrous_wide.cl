/* svgf_atrous.cl with PG_LANES (a build option, kernels/wide/lanes.h) consecutive pixels of a
 * row per work-item in vector lanes (docs/denoising.md, "Cost"): every tap of the 5x5 kernel
 * loads each channel of the PG_LANES tap pixels as one vector from the planar images, so a CPU
 * device's compiler emits SIMD code for the 25 edge-stopping weights, which it does not for one
 * pixel per work-item. The same
 * operations in the same order as svgf_atrous.cl: a tap outside the image adds a zero weight
 * where the scalar kernel skips it, which leaves every sum the same up to the multiply-adds the
 * compiler forms in each. */
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
#include "wide/lanes.h"
#include "wide/svgf_wide.h"

/* clang-format off */
__kernel void svgf_atrous_wide(__global const float* in, __global float* out,
                               __global const float* surface, __global const float* depth_slope,
                               uint width, uint height, int step, pg_svgf_settings settings) {
  /* clang-format on */
  int w = (int)width, h = (int)height;
  int x0 = (int)get_global_id(0) * PG_LANES, y = (int)get_global_id(1);
  if (x0 >= w || y >= h) return;
  int row_start = y * w, n = w * h;
  pg_intw lane_x = x0 + pg_lane_numbers();

  pg_float3w c, n_c;
  pg_floatw variance_c, z_c;
  pg_load_planar_row(in, n, row_start, x0, w, &c, &variance_c);
  pg_load_planar_row(surface, n, row_start, x0, w, &n_c, &z_c);
  /* As svgf_atrous.cl's test (a NaN depth is filtered there too). */
  pg_intw filtered = ~(z_c <= 0.0f);

  pg_float3w sum_c = pg_make_float3w(0.0f, 0.0f, 0.0f);
  pg_floatw sum_v = 0.0f, sum_w = 0.0f;
  if (any(filtered)) {
    /* The centre's variance through a 3x3 Gaussian (taps inside the image, renormalised). */
    pg_floatw sum_g = 0.0f, sum_gv = 0.0f;
    for (int dy = -1; dy <= 1; ++dy) {
      int qy = y + dy;
      if (qy < 0 || qy >= h) continue;
      /* The row's three taps, as plain vector loads away from its ends: through the row loader,
       * a call, the sums went through memory at every tap (docs/denoising.md, "The normal
       * weight's exponent built in"). */
      __global const float* variance_row = in + 3 * n + qy * w;
      pg_floatw taps[3];
      if (x0 >= 1 && x0 + PG_LANES + 1 <= w) {
        for (int t = 0; t < 3; ++t) taps[t] = pg_vloadw(0, variance_row + x0 - 1 + t);
      } else {
        for (int t = 0; t < 3; ++t) taps[t] = pg_load_row_floats(variance_row, x0 - 1 + t, w);
      }
      for (int dx = -1; dx <= 1; ++dx) {
        pg_floatw variance_q = taps[dx + 1];
        pg_intw inside = (lane_x + dx >= 0) & (lane_x + dx < w);
        float g = pg_svgf_gauss3(dx, dy);
        sum_gv += select((pg_floatw)(0.0f), g * variance_q, inside);
        sum_g += select((pg_floatw)(0.0f), (pg_floatw)(g), inside);
      }
    }
    pg_floatw inverse_phi_l = 1.0f / (settings.phi_luminance * sqrt(fmax(sum_gv / sum_g, 0.0f)) +
                                      PG_SVGF_LUMINANCE_EPSILON);
    pg_floatw slope = pg_load_row_floats(depth_slope + row_start, x0, w);
    pg_floatw inverse_phi_z[PG_SVGF_SQUARED_DISTANCES(PG_SVGF_ATROUS_RADIUS)];
    pg_svgf_inverse_phi_depth_table_w(slope, z_c, (float)step, PG_SVGF_ATROUS_RADIUS, settings,
                                      inverse_phi_z);
    pg_floatw luminance_c = pg_luminance3w(c);
    for (int dy = -PG_SVGF_ATROUS_RADIUS; dy <= PG_SVGF_ATROUS_RADIUS; ++dy) {
      int qy = y + dy * step;
      if (qy < 0 || qy >= h) continue;
      for (int dx = -PG_SVGF_ATROUS_RADIUS; dx <= PG_SVGF_ATROUS_RADIUS; ++dx) {
        int offset = dx * step;
        pg_float3w q, n_q;
        pg_floatw variance_q, z_q;
        pg_load_planar_row(in, n, qy * w, x0 + offset, w, &q, &variance_q);
        pg_load_planar_row(surface, n, qy * w, x0 + offset, w, &n_q, &z_q);
        pg_intw inside = (lane_x + offset >= 0) & (lane_x + offset < w);
        pg_floatw weight =
            pg_svgf_atrous_weight(dx, PG_SVGF_ATROUS_RADIUS) *
            pg_svgf_atrous_weight(dy, PG_SVGF_ATROUS_RADIUS) *
            pg_svgf_edge_weight_w(n_c, z_c, luminance_c, n_q, z_q, pg_luminance3w(q),
                                  inverse_phi_z[pg_svgf_squared_distance(dx, dy)], inverse_phi_l);
        weight = select((pg_floatw)(0.0f), weight, inside);
        sum_c = pg_add3w(sum_c, pg_scale3w(q, weight));
        sum_v += weight * weight * variance_q;
        sum_w += weight;
      }
    }
  }
  /* sum_w >= 9/64 (1/4 at radius 1) where the centre has a surface: its weight is its kernel
   * weight squared times exp(0). Pixels without one keep their input. */
  pg_floatw safe_w = select((pg_floatw)(1.0f), sum_w, filtered);
  pg_float3w mean_c = pg_make_float3w(sum_c.x / safe_w, sum_c.y / safe_w, sum_c.z / safe_w);
  pg_float3w result = pg_select3w(c, mean_c, filtered);
  pg_floatw result_v = select(variance_c, sum_v / (safe_w * safe_w), filtered);

  pg_store_row_floats(out + row_start, x0, w, result.x);
  pg_store_row_floats(out + n + row_start, x0, w, result.y);
  pg_store_row_floats(out + 2 * n + row_start, x0, w, result.z);
  pg_store_row_floats(out + 3 * n + row_start, x0, w, result_v);
}
