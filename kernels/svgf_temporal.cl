/* SVGF's temporal pass (docs/denoising.md; Schied et al. 2017, 4.1). Demodulates this frame's
 * colour by the primary hit's albedo, reprojects last frame's filtered illumination and
 * luminance moments through the motion vector (2x2 bilinear taps, each kept only where
 * pg_same_surface holds: the test guiding's reprojection uses; where none holds, the 3x3
 * neighbourhood's same-surface pixels, pg_svgf_history_tap), and blends them with this
 * frame's. Also writes the surface and depth slope the later passes read, and keeps this
 * frame's position, normal and material for the next frame's history test (kept_*): the inputs
 * may be the host's G-buffer read in place, which the renderer overwrites (a copy here rather
 * than a pass of its own: the pixel's channels are in registers already).
 * Per pixel (hand count; the rules: docs/guiding.md, "The roofline"; bench/bench_svgf.cpp counts
 * with it): 41 flops without history; with it 8 per bilinear tap, 34 per tap tested for the same
 * surface and summed, 30 for the blend; where no bilinear tap holds, 4 per neighbourhood tap and
 * 34 per tap tested. Bytes: 92 read and 88 written, 68 more read where a tap of last frame is
 * tested; a pixel without a surface reads 40 and writes 88. The colour is the renderer's image as
 * it is, three floats a pixel (no copy into four). */
/* Each operation rounded on its own, as in the host reference. */
#pragma OPENCL FP_CONTRACT OFF

#include "shared/planar.h"
#include "shared/svgf.h"

/* clang-format off */
__kernel void svgf_temporal(__global const float* colour, __global const float4* emission,
                            __global const float4* position_depth,
                            __global const float4* shading_normal,
                            __global const float4* base_color_roughness,
                            __global const uint* flags, __global const uint* material,
                            __global const float2* motion,
                            __global const float4* prev_position_depth,
                            __global const float4* prev_shading_normal,
                            __global const uint* prev_material,
                            __global const float* prev_history,
                            __global const float* prev_moments,
                            __global float* surface, __global float* depth_slope,
                            __global float* integrated, __global float* moments,
                            __global float4* kept_position_depth,
                            __global float4* kept_shading_normal, __global uint* kept_material,
                            uint width, uint height, uint has_history,
                            pg_svgf_settings settings, pg_svgf_view view) {
  /* clang-format on */
  uint x = get_global_id(0), y = get_global_id(1);
  if (x >= width || y >= height) return;
  uint i = y * width + x, n = width * height;
  float4 pd = position_depth[i];
  float4 normal4 = shading_normal[i];
  uint m = material[i];
  kept_position_depth[i] = pd;
  kept_shading_normal[i] = normal4;
  kept_material[i] = m;
  if (!pg_svgf_has_surface(flags[i])) {
    pg_planar_set(surface, n, i, (float4)(0.0f, 0.0f, 1.0f, 0.0f));
    depth_slope[i] = 0.0f;
    pg_planar_set(integrated, n, i, (float4)(0.0f));
    pg_planar_set(moments, n, i, (float4)(0.0f));
    return;
  }
  float3 normal = normal4.xyz;
  pg_planar_set(surface, n, i, (float4)(normal, pd.w));
  float z_left = x > 0u ? position_depth[i - 1u].w : 0.0f;
  float z_right = x + 1u < width ? position_depth[i + 1u].w : 0.0f;
  float z_down = y > 0u ? position_depth[i - width].w : 0.0f;
  float z_up = y + 1u < height ? position_depth[i + width].w : 0.0f;
  depth_slope[i] = settings.depth_slope_from_normal
                       ? pg_svgf_plane_slope(normal, pd.xyz, pd.w, view)
                       : pg_svgf_depth_slope(pd.w, z_left, z_right, z_down, z_up);

  float3 albedo = pg_svgf_albedo(base_color_roughness[i], settings.albedo_floor);
  float3 illumination = pg_svgf_demodulate(vload3(i, colour), emission[i].xyz, albedo);
  float luminance = pg_luminance(illumination);

  float3 sum_history = (float3)(0.0f);
  float4 sum_moments = (float4)(0.0f);
  float sum_weight = 0.0f;
  if (has_history != 0u) {
    float2 position = (float2)((float)x, (float)y) + motion[i];
    for (int pass = 0; pass < 2; ++pass) {
      if (pass == 1) {
        if (sum_weight >= PG_SVGF_MIN_TAP_WEIGHT || settings.history_fallback == 0u) break;
        sum_history = (float3)(0.0f);
        sum_moments = (float4)(0.0f);
        sum_weight = 0.0f;
      }
      for (int t = 0; t < pg_svgf_history_taps(pass); ++t) {
        int px, py;
        float w = pg_svgf_history_tap(position, pass, t, &px, &py);
        if (w <= 0.0f || px < 0 || py < 0 || px >= (int)width || py >= (int)height) continue;
        uint j = (uint)py * width + (uint)px;
        if (!pg_same_surface(pd, normal, m, prev_position_depth[j], prev_shading_normal[j].xyz,
                             prev_material[j], settings.reproject_position,
                             settings.reproject_normal))
          continue;
        sum_history += w * pg_planar_get(prev_history, n, j).xyz;
        sum_moments += w * pg_planar_get(prev_moments, n, j);
        sum_weight += w;
      }
    }
  }
  float length = 1.0f;
  float3 c = illumination;
  float2 mo = (float2)(luminance, luminance * luminance);
  if (sum_weight >= PG_SVGF_MIN_TAP_WEIGHT) {
    float3 history = sum_history / sum_weight;
    float4 history_moments = sum_moments / sum_weight;
    length = fmin(history_moments.z + 1.0f, settings.max_history);
    c = pg_svgf_blend3(history, illumination, pg_svgf_blend_weight(settings.alpha_colour, length));
    float wm = pg_svgf_blend_weight(settings.alpha_moments, length);
    mo = (float2)(pg_svgf_blend(history_moments.x, mo.x, wm),
                  pg_svgf_blend(history_moments.y, mo.y, wm));
  }
  pg_planar_set(integrated, n, i, (float4)(c, 0.0f));
  pg_planar_set(moments, n, i, (float4)(mo.x, mo.y, length, 0.0f));
}
