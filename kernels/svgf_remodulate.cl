/* SVGF's last step (docs/denoising.md): colour = albedo * filtered illumination + emission.
 * Pixels without a surface keep their input colour (the sky is not filtered).
 * Per pixel (hand count, as svgf_temporal.cl): 9 flops, 64 bytes; no surface: 28 bytes. The colour
 * in and out is three floats a pixel, the renderer's image layout. */
#pragma OPENCL FP_CONTRACT OFF

#include "shared/planar.h"
#include "shared/svgf.h"

/* clang-format off */
__kernel void svgf_remodulate(__global const float* illumination, __global const float* colour,
                              __global const float4* emission,
                              __global const float4* base_color_roughness,
                              __global const uint* flags, __global float* out, uint width,
                              uint height, pg_svgf_settings settings) {
  /* clang-format on */
  uint x = get_global_id(0), y = get_global_id(1);
  if (x >= width || y >= height) return;
  uint i = y * width + x, n = width * height;
  if (!pg_svgf_has_surface(flags[i])) {
    vstore3(vload3(i, colour), i, out);
    return;
  }
  float3 albedo = pg_svgf_albedo(base_color_roughness[i], settings.albedo_floor);
  vstore3(pg_svgf_remodulate(pg_planar_get(illumination, n, i).xyz, emission[i].xyz, albedo), i,
          out);
}
