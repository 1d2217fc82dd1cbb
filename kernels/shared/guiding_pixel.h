/* What the three guiding kernels read of one G-buffer pixel (layout: include/rtpg/
 * guiding_layout.h): the rule for which pixels guiding skips (paper, section 5: sky,
 * emitters, transmission, roughness near zero) and the pixel's material; the history test
 * of reprojection is shared/same_surface.h. */
#ifndef RTPG_SHARED_GUIDING_PIXEL_H
#define RTPG_SHARED_GUIDING_PIXEL_H

#include "rtpg/guiding_layout.h"
#include "shared/bsdf.h"
#include "shared/compat.h"
#include "shared/pmm.h"
#include "shared/same_surface.h"

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

PG_NAMESPACE_END

#endif
