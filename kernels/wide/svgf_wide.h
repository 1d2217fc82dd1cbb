/* SVGF in vector lanes (kernels/wide/lanes.h): PG_LANES pixels of a row read from the
 * denoiser's planar images, and the a-trous edge-stopping weight (kernels/shared/svgf.h,
 * pg_svgf_edge_weight) with the same operations in the same order, so each lane equals the
 * scalar function. OpenCL C only. */
#ifndef RTPG_WIDE_SVGF_WIDE_H
#define RTPG_WIDE_SVGF_WIDE_H

#include "shared/svgf.h"
#include "wide/lanes.h"

/* The four channels of the pixels x0 .. x0 + PG_LANES - 1 of the row starting at pixel row_start
 * of a planar image of n pixels (kernels/shared/svgf.h): rgb or xyz, and w (the row loaders'
 * rule at the row's ends: kernels/wide/lanes.h). */
static inline void pg_load_planar_row(__global const float* image, int n, int row_start, int x0,
                                      int width, pg_float3w* xyz, pg_floatw* w) {
  __global const float* p = image + row_start;
  if (x0 >= 0 && x0 + PG_LANES <= width) { /* one test for the four channels */
    xyz->x = pg_vloadw(0, p + x0);
    xyz->y = pg_vloadw(0, p + n + x0);
    xyz->z = pg_vloadw(0, p + 2 * n + x0);
    *w = pg_vloadw(0, p + 3 * n + x0);
    return;
  }
  xyz->x = pg_load_row_floats(p, x0, width);
  xyz->y = pg_load_row_floats(p + n, x0, width);
  xyz->z = pg_load_row_floats(p + 2 * n, x0, width);
  *w = pg_load_row_floats(p + 3 * n, x0, width);
}

/* pg_svgf_normal_power in the lanes. */
static inline pg_floatw pg_svgf_normal_power_w(pg_floatw x) {
  pg_floatw r = (pg_floatw)(1.0f);
  PG_SVGF_CONSTANT_POWER(r, x);
  return r;
}

/* pg_svgf_inverse_phi_depth in the lanes. */
static inline pg_floatw pg_svgf_inverse_phi_depth_w(pg_floatw slope_c, pg_floatw z_c,
                                                    float distance, pg_svgf_settings s) {
  return 1.0f / (s.phi_depth * slope_c * distance + PG_SVGF_DEPTH_EPSILON * z_c);
}

/* pg_svgf_inverse_phi_depth_table in the lanes. */
static inline void pg_svgf_inverse_phi_depth_table_w(pg_floatw slope_c, pg_floatw z_c, float step,
                                                     int radius, pg_svgf_settings s,
                                                     pg_floatw* table) {
  for (int d2 = 0; d2 < PG_SVGF_SQUARED_DISTANCES(radius); ++d2)
    table[d2] = pg_svgf_is_tap_squared_distance(d2, radius)
                    ? pg_svgf_inverse_phi_depth_w(slope_c, z_c, step * sqrt((float)d2), s)
                    : (pg_floatw)(0.0f);
}

/* pg_svgf_edge_weight in the lanes: the centre's normal n_c, depth z_c and luminance, a tap's
 * normal n_q, depth z_q and luminance, the centre's 1 / phi_z at the tap's distance and
 * inverse_phi_l. A tap without a surface gets 0. */
static inline pg_floatw pg_svgf_edge_weight_w(pg_float3w n_c, pg_floatw z_c, pg_floatw luminance_c,
                                              pg_float3w n_q, pg_floatw z_q, pg_floatw luminance_q,
                                              pg_floatw inverse_phi_z, pg_floatw inverse_phi_l) {
  pg_floatw cos_n = fmin(fmax(pg_dot3w(n_c, n_q), 0.0f), 1.0f);
  pg_floatw e = fabs(z_c - z_q) * inverse_phi_z + fabs(luminance_c - luminance_q) * inverse_phi_l;
  pg_floatw w = pg_svgf_normal_power_w(cos_n) * exp(-e);
  return select((pg_floatw)(0.0f), w, z_q > 0.0f);
}

/* pg_svgf_variance in the lanes. */
static inline pg_floatw pg_svgf_variance_w(pg_floatw m1, pg_floatw m2, pg_floatw length,
                                           float min_history) {
  pg_floatw square = m1 * m1; /* not fused: pg_svgf_variance */
  pg_floatw v = fmax(m2 - square, 0.0f);
  return select(v, v * (min_history / fmax(length, 1.0f)), length < min_history);
}

#endif
