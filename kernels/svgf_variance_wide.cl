/* svgf_variance.cl with PG_LANES (a build option, kernels/wide/lanes.h) consecutive pixels of a
 * row per work-item in vector lanes, as svgf_atrous_wide.cl (docs/denoising.md, "Cost"): the
 * 7x7 spatial estimate, which every pixel with fewer than min_history frames of history takes
 * (the first frames of a run, disocclusions, a moving camera), loads each channel of its
 * PG_LANES tap pixels as one vector from the planar images. The same operations in the same
 * order as svgf_variance.cl: a tap outside the image adds a zero weight where the scalar kernel
 * skips it, which leaves every sum the same up to the multiply-adds the compiler forms in each.
 * Flops and bytes per pixel: svgf_variance.cl's count (taps outside the image are computed and
 * masked here, and not counted). */
/* Multiply-adds allowed, as in the a-trous pass (docs/denoising.md, "Multiply-adds in the a-trous
 * pass"): 8-9% of the spatial estimate on PoCL's CPU device. */
#pragma OPENCL FP_CONTRACT ON

#include "shared/planar.h"
#include "shared/svgf.h"
#include "wide/lanes.h"
#include "wide/svgf_wide.h"

/* clang-format off */
__kernel void svgf_variance_wide(__global const float* integrated, __global const float* moments,
                                 __global const float* surface, __global const float* depth_slope,
                                 __global float* illumination, uint width, uint height,
                                 pg_svgf_settings settings) {
  /* clang-format on */
  int w = (int)width, h = (int)height;
  int x0 = (int)get_global_id(0) * PG_LANES, y = (int)get_global_id(1);
  if (x0 >= w || y >= h) return;
  int row_start = y * w, n = w * h;
  pg_intw lane_x = x0 + pg_lane_numbers();

  pg_float3w n_c, c, m;
  pg_floatw z_c, unused;
  pg_load_planar_row(surface, n, row_start, x0, w, &n_c, &z_c);
  pg_load_planar_row(integrated, n, row_start, x0, w, &c, &unused);
  pg_load_planar_row(moments, n, row_start, x0, w, &m, &unused);
  /* As svgf_variance.cl's tests (a NaN depth takes the history test there too). */
  pg_intw has_surface = ~(z_c <= 0.0f);
  pg_intw long_history = m.z >= settings.min_history;
  pg_intw spatial = has_surface & ~long_history;

  pg_float3w result = c;
  pg_floatw result_v = pg_svgf_variance_w(m.x, m.y, m.z, settings.min_history);
  if (any(spatial)) {
    pg_floatw slope = pg_load_row_floats(depth_slope + row_start, x0, w);
    pg_floatw inverse_phi_z[PG_SVGF_SQUARED_DISTANCES(3)];
    pg_svgf_inverse_phi_depth_table_w(slope, z_c, 1.0f, 3, settings, inverse_phi_z);
    pg_floatw luminance_c = pg_luminance3w(c);
    pg_float3w sum_c = pg_make_float3w(0.0f, 0.0f, 0.0f);
    pg_floatw sum_m1 = 0.0f, sum_m2 = 0.0f, sum_w = 0.0f;
    for (int dy = -3; dy <= 3; ++dy) {
      int qy = y + dy;
      if (qy < 0 || qy >= h) continue;
      for (int dx = -3; dx <= 3; ++dx) {
        pg_float3w iq, n_q, mq;
        pg_floatw z_q, unused_q;
        pg_load_planar_row(integrated, n, qy * w, x0 + dx, w, &iq, &unused_q);
        pg_load_planar_row(surface, n, qy * w, x0 + dx, w, &n_q, &z_q);
        pg_load_planar_row(moments, n, qy * w, x0 + dx, w, &mq, &unused_q);
        pg_intw inside = (lane_x + dx >= 0) & (lane_x + dx < w);
        pg_floatw weight = pg_svgf_edge_weight_w(
            n_c, z_c, luminance_c, n_q, z_q, pg_luminance3w(iq),
            inverse_phi_z[pg_svgf_squared_distance(dx, dy)], (pg_floatw)(0.0f));
        weight = select((pg_floatw)(0.0f), weight, inside);
        sum_c = pg_add3w(sum_c, pg_scale3w(iq, weight));
        sum_m1 += weight * mq.x;
        sum_m2 += weight * mq.y;
        sum_w += weight;
      }
    }
    /* sum_w >= 1 where the centre has a surface: its own weight is exp(0). */
    pg_floatw safe_w = select((pg_floatw)(1.0f), sum_w, spatial);
    pg_floatw spatial_v =
        pg_svgf_variance_w(sum_m1 / safe_w, sum_m2 / safe_w, m.z, settings.min_history);
    result = pg_select3w(
        result, pg_make_float3w(sum_c.x / safe_w, sum_c.y / safe_w, sum_c.z / safe_w), spatial);
    result_v = select(result_v, spatial_v, spatial);
  }
  /* No surface: zero illumination and variance. */
  pg_floatw zero = 0.0f;
  pg_store_row_floats(illumination + row_start, x0, w, select(zero, result.x, has_surface));
  pg_store_row_floats(illumination + n + row_start, x0, w, select(zero, result.y, has_surface));
  pg_store_row_floats(illumination + 2 * n + row_start, x0, w, select(zero, result.z, has_surface));
  pg_store_row_floats(illumination + 3 * n + row_start, x0, w, select(zero, result_v, has_surface));
}
