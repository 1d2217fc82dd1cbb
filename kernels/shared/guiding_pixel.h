/* What the three guiding kernels read of one G-buffer pixel (layout: include/rtpg/
 * guiding_layout.h): the rule for which pixels guiding skips (paper, section 5: sky,
 * emitters, transmission, roughness near zero), the pixel's material, and the history test
 * of reprojection. */
#ifndef RTPG_SHARED_GUIDING_PIXEL_H
#define RTPG_SHARED_GUIDING_PIXEL_H

#include "rtpg/guiding_layout.h"
#include "shared/bsdf.h"
#include "shared/compat.h"
#include "shared/pmm.h"

PG_NAMESPACE_BEGIN

PG_FN int pg_guiding_applies(uint flags, float roughness, pg_kernel_settings p) {
  if ((flags & (PG_GBUF_SKY | PG_GBUF_EMITTER | PG_GBUF_DELTA | PG_GBUF_TRANSMISSIVE)) != 0u)
    return 0;
  return roughness > p.roughness_skip;
}

PG_FN pg_material pg_material_from_gbuffer(float4 base_color_roughness, float4 metallic_specular) {
  pg_material m;
  m.base_color = pg_float4_xyz(base_color_roughness);
  m.roughness = base_color_roughness.w;
  m.metallic = metallic_specular.x;
  m.specular = metallic_specular.y;
  return m;
}

/* Does last frame's pixel (prev_*) show the same surface as this one (paper 3.1; the tests
 * of SVGF)? Same material, a position within max_relative_distance of this pixel's depth,
 * normals at least min_normal_cos apart, and a surface at all (depth > 0) in both; no
 * absolute length anywhere, so the test does not depend on the scene's unit. Reprojection keeps
 * history only where this holds. */
PG_FN int pg_same_surface(float4 position_depth, float3 normal, uint material,
                          float4 prev_position_depth, float3 prev_normal, uint prev_material,
                          float max_relative_distance, float min_normal_cos) {
  float3 d = pg_float4_xyz(position_depth) - pg_float4_xyz(prev_position_depth);
  return position_depth.w > 0.0f && sqrt(dot(d, d)) <= max_relative_distance * position_depth.w &&
         dot(normal, prev_normal) >= min_normal_cos && prev_material == material &&
         prev_position_depth.w > 0.0f;
}

PG_NAMESPACE_END

#endif
