/* pg_guiding_applies and pg_shares_model (kernels/shared/guiding_pixel.h) for PG_LANES pixels at
 * once (kernels/wide/lanes.h). OpenCL C only. */
#ifndef RTPG_WIDE_GUIDING_PIXEL_WIDE_H
#define RTPG_WIDE_GUIDING_PIXEL_WIDE_H

#include "rtpg/guiding_layout.h"
#include "shared/guiding_pixel.h"
#include "shared/kernel_args.h"
#include "wide/lanes.h"

static inline pg_intw pg_guiding_applies_w(pg_uintw flags, pg_floatw roughness,
                                           pg_kernel_settings p) {
  uint skip = PG_GBUF_SKY | PG_GBUF_EMITTER | PG_GBUF_DELTA | PG_GBUF_TRANSMISSIVE;
  return ((flags & skip) == 0u) & (roughness > p.roughness_skip);
}

/* pg_model_sharable in the lanes. */
static inline pg_intw pg_model_sharable_w(pg_uintw flags, pg_floatw roughness, pg_floatw metallic,
                                          pg_floatw specular, pg_kernel_settings p) {
  return pg_guiding_applies_w(flags, roughness, p) &
         (((metallic <= 0.0f) & (specular <= 0.0f)) | (roughness >= PG_SHARED_MODEL_MIN_ROUGHNESS));
}

/* pg_shares_model for the lanes' pixels x0 .. x0 + PG_LANES - 1 of row y, whose sharability
 * (pg_model_sharable_w) and shading normal the caller has, and the pixels above them in row
 * pg_model_row(y): none where y is that row. pg_same_surface's products written out (both wide
 * kernels decide alike). */
static inline pg_intw pg_shares_model_w(PG_ARGS_GBUFFER int x0, int y, int w, pg_intw sharable,
                                        pg_float3w normal, pg_kernel_settings p) {
  int model_y = pg_model_row(y, p);
  if (model_y == y || !any(sharable)) return (pg_intw)(0);
  int row_start = y * w, model_start = model_y * w;
  pg_float3w base_color;
  pg_floatw roughness, metallic, specular, unused;
  pg_load_row_float4_rows(base_color_roughness + model_start, x0, w, &base_color.x, &base_color.y,
                          &base_color.z, &roughness);
  pg_load_row_float4_rows(metallic_specular + model_start, x0, w, &metallic, &specular, &unused,
                          &unused);
  pg_intw shares = sharable & pg_model_sharable_w(pg_load_row_uints(flags + model_start, x0, w),
                                                  roughness, metallic, specular, p);
  if (!any(shares)) return shares;
  pg_float3w position, model_position, model_normal;
  pg_floatw depth, model_depth;
  pg_load_row_float4_rows(position_depth + row_start, x0, w, &position.x, &position.y, &position.z,
                          &depth);
  pg_load_row_float4_rows(position_depth + model_start, x0, w, &model_position.x, &model_position.y,
                          &model_position.z, &model_depth);
  pg_load_row_float4_rows(shading_normal + model_start, x0, w, &model_normal.x, &model_normal.y,
                          &model_normal.z, &unused);
  pg_float3w d = pg_sub3w(position, model_position);
  return shares & (depth > 0.0f) & (sqrt(pg_dot3w(d, d)) <= p.reproject_position * depth) &
         (pg_dot3w(normal, model_normal) >=
          fmax(p.reproject_normal, PG_SHARED_MODEL_MIN_NORMAL_COS)) &
         (pg_load_row_uints(material + row_start, x0, w) ==
          pg_load_row_uints(material + model_start, x0, w)) &
         (model_depth > 0.0f) &
         (copysign((pg_floatw)(1.0f), normal.z) == copysign((pg_floatw)(1.0f), model_normal.z));
}

#endif
